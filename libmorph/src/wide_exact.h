// Private: an erosion's plane data over doubles (a facet normal (q - p) x (r - p), its offset
// <n, p - b>, the sign of <n, c - b>) in exact fixed-size integer arithmetic, made Mpzf once
// per value at the end. The doubles of one facet are scaled by a common power of two (the
// smallest unit among them) to integers below 2^116; differences, products and sums of those
// then fit in 128, 256 and 384 bits, a few machine words each, against a hundred instructions
// or more per Mpzf operation. When the doubles are too far apart in magnitude for that (their
// ratio beyond 2^63, or an infinity), the caller computes in Mpzf: the values are the same.
#pragma once

#include <gmp.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <initializer_list>

#include "exact.h"

namespace morph::detail::fixed {

using i128 = __int128;
using u128 = unsigned __int128;
static_assert(sizeof(mp_limb_t) == sizeof(std::uint64_t) && GMP_NUMB_BITS == 64);

/// An exact integer in two's complement over N 64-bit words, least significant first.
template <int N>
struct Int {
  std::uint64_t w[N];
};
using I256 = Int<4>;
using I384 = Int<6>;

/// The largest integer a Frame gives is below 2^kInputBits; below 2^kSmallBits when it is
/// `small` (usual for a mesh's nearby points: their doubles within some 2^8 of each other),
/// and differences then fit in 64 bits, products and normals in 128, offsets in 192.
constexpr int kInputBits = 116;
constexpr int kSmallBits = 61;

/// A double's significand (odd, or zero) and exponent: d = +-m 2^e.
struct Decoded {
  std::uint64_t m;
  int e;
  bool negative;
  bool finite;
};
inline Decoded decode(double d) {
  std::uint64_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  std::uint64_t m = bits & ((std::uint64_t{1} << 52) - 1);
  Decoded r{0, 0, (bits >> 63) != 0, biased != 0x7ff};
  if (!r.finite || (biased == 0 && m == 0)) return r;
  int e = -1074;
  if (biased != 0) {
    m |= std::uint64_t{1} << 52;
    e = biased - 1075;
  }
  const int tz = __builtin_ctzll(m);
  r.m = m >> tz;
  r.e = e + tz;
  return r;
}

constexpr std::uint64_t kMantissa = (std::uint64_t{1} << 52) - 1;

/// Whether simplify_quotient moves an Mpzf's exponent as set_exact expects (Mpzf(2^-64) is one
/// word 1 with exponent -1, so that the quotient kept is x 2^64 / 1): checked once, so that
/// another Mpzf layout sends every frame to the Mpzf code instead of giving wrong values.
inline bool exponent_shift_works() {
  static const bool works = [] {
    ExactN x(1.5), unit(0x1p-64);
    simplify_quotient(x, unit);
    return unit == ExactN(1) && x == ExactN(0x1.8p64);
  }();
  return works;
}

/// What a Frame needs of some doubles: the exponent of their lowest set bit (kNoBits when
/// all are zero) and the largest magnitude's bit pattern (non-negative doubles order as
/// their bit patterns; an infinity or a NaN is above every finite one). Spans combine, so a
/// point's span is found once for all the frames it is in.
struct Span {
  static constexpr int kNoBits = 1 << 20;
  int low = kNoBits;
  std::uint64_t largest = 0;
  void add(double d) {
    std::uint64_t bits;
    std::memcpy(&bits, &d, sizeof bits);
    bits &= ~(std::uint64_t{1} << 63);
    if (bits == 0) return;
    largest = std::max(largest, bits);
    const int biased = static_cast<int>(bits >> 52);
    const std::uint64_t m = biased != 0 ? (bits & kMantissa) | (kMantissa + 1) : bits;
    low = std::min(low, std::max(biased, 1) - 1075 + __builtin_ctzll(m));
  }
  void add(const V3<double>& p) {
    add(p.x);
    add(p.y);
    add(p.z);
  }
  void add(const Span& o) {
    low = std::min(low, o.low);
    largest = std::max(largest, o.largest);
  }
};

/// Doubles scaled by 2^-unit, the smallest power of two of which each is an integer
/// multiple: each then an integer below 2^kInputBits, or the frame is not ok.
class Frame {
 public:
  explicit Frame(std::initializer_list<double> values) : Frame(span_of(values)) {}
  /// The frame of the doubles whose span is `span`.
  explicit Frame(const Span& span) {
    const int low = span.low;
    const std::uint64_t largest = span.largest;
    // Not ok for an infinity or a NaN (or an Mpzf that set_exact cannot make).
    if (largest >= 0x7ff0000000000000 || !exponent_shift_works()) return;
    if (largest == 0) {  // all zero
      unit = 0;
      ok = small = true;
      scale_ = 1;
      return;
    }
    const int biased = static_cast<int>(largest >> 52);
    // 2^high > |d| for every value (largest is not zero here: clz is defined).
    const int high = biased != 0 ? biased - 1022 : -1074 + 64 - __builtin_clzll(largest);
    unit = low;
    ok = high - low <= kInputBits;
    // Small also needs 2^-unit to be a double (the scaling below): units of doubles within
    // 2^±1000, all but the subnormal ones.
    small = high - low <= kSmallBits && unit >= -1000 && unit <= 1000;
    if (small) {
      const std::uint64_t bits = static_cast<std::uint64_t>(1023 - unit) << 52;
      std::memcpy(&scale_, &bits, sizeof scale_);
    }
  }
  /// d / 2^unit, exact, for d among the frame's values.
  i128 operator()(double d) const {
    const Decoded x = decode(d);
    if (x.m == 0) return 0;
    const i128 v = static_cast<i128>(static_cast<u128>(x.m) << (x.e - unit));
    return x.negative ? -v : v;
  }
  /// The same for a small frame, in 64 bits: d 2^-unit is an integer below 2^61 (a double,
  /// so the product by the power of two is exact in any rounding mode), converted exactly.
  std::int64_t small_at(double d) const { return static_cast<std::int64_t>(d * scale_); }
  int unit = 0;
  bool ok = false;
  bool small = false;

 private:
  static Span span_of(std::initializer_list<double> values) {
    Span span;
    for (double d : values) span.add(d);
    return span;
  }
  double scale_ = 1;  // 2^-unit, for a small frame
};

template <int N>
inline Int<N> negated(Int<N> a) {
  std::uint64_t carry = 1;
  for (int i = 0; i < N; ++i) {
    const u128 t = static_cast<u128>(~a.w[i]) + carry;
    a.w[i] = static_cast<std::uint64_t>(t);
    carry = static_cast<std::uint64_t>(t >> 64);
  }
  return a;
}
template <int N>
inline bool is_negative(const Int<N>& a) {
  return (a.w[N - 1] >> 63) != 0;
}
template <int N>
inline int sign(const Int<N>& a) {
  if (is_negative(a)) return -1;
  for (int i = 0; i < N; ++i)
    if (a.w[i] != 0) return 1;
  return 0;
}
template <int N>
inline Int<N> operator+(const Int<N>& a, const Int<N>& b) {
  Int<N> r;
  std::uint64_t carry = 0;
  for (int i = 0; i < N; ++i) {
    const u128 t = static_cast<u128>(a.w[i]) + b.w[i] + carry;
    r.w[i] = static_cast<std::uint64_t>(t);
    carry = static_cast<std::uint64_t>(t >> 64);
  }
  return r;
}
template <int N>
inline Int<N> operator-(const Int<N>& a, const Int<N>& b) {
  return a + negated(b);
}

/// |a| as words, and whether a < 0.
inline u128 magnitude(i128 a, bool& negative) {
  negative = a < 0;
  return negative ? -static_cast<u128>(a) : static_cast<u128>(a);
}

/// a b exactly (|a|, |b| < 2^127: below 2^254).
inline I256 multiply(i128 a, i128 b) {
  bool na, nb;
  const u128 x = magnitude(a, na), y = magnitude(b, nb);
  const std::uint64_t x0 = static_cast<std::uint64_t>(x), x1 = static_cast<std::uint64_t>(x >> 64);
  const std::uint64_t y0 = static_cast<std::uint64_t>(y), y1 = static_cast<std::uint64_t>(y >> 64);
  const u128 p00 = static_cast<u128>(x0) * y0, p01 = static_cast<u128>(x0) * y1;
  const u128 p10 = static_cast<u128>(x1) * y0, p11 = static_cast<u128>(x1) * y1;
  I256 r;
  r.w[0] = static_cast<std::uint64_t>(p00);
  const u128 mid = (p00 >> 64) + static_cast<std::uint64_t>(p01) + static_cast<std::uint64_t>(p10);
  r.w[1] = static_cast<std::uint64_t>(mid);
  const u128 high = (mid >> 64) + (p01 >> 64) + (p10 >> 64) + static_cast<std::uint64_t>(p11);
  r.w[2] = static_cast<std::uint64_t>(high);
  r.w[3] = static_cast<std::uint64_t>((high >> 64) + (p11 >> 64));
  return na != nb ? negated(r) : r;
}

/// a b exactly (|a| < 2^255, |b| < 2^127: below 2^382).
inline I384 multiply(const I256& a, i128 b) {
  const bool na = is_negative(a);
  const I256 x = na ? negated(a) : a;
  bool nb;
  const u128 y = magnitude(b, nb);
  const std::uint64_t y0 = static_cast<std::uint64_t>(y), y1 = static_cast<std::uint64_t>(y >> 64);
  I384 r{};
  for (int i = 0; i < 4; ++i) {
    std::uint64_t carry = 0;
    for (int j = 0; j < 2; ++j) {
      const u128 t = static_cast<u128>(x.w[i]) * (j == 0 ? y0 : y1) + r.w[i + j] + carry;
      r.w[i + j] = static_cast<std::uint64_t>(t);
      carry = static_cast<std::uint64_t>(t >> 64);
    }
    r.w[i + 2] = carry;
  }
  return na != nb ? negated(r) : r;
}

/// The cross product of integer vectors (components below 2^126: below 2^253).
inline V3<I256> cross(const V3<i128>& a, const V3<i128>& b) {
  return {multiply(a.y, b.z) - multiply(a.z, b.y), multiply(a.z, b.x) - multiply(a.x, b.z),
          multiply(a.x, b.y) - multiply(a.y, b.x)};
}
/// <n, d> (components below 2^253 and 2^126: below 2^381).
inline I384 dot(const V3<I256>& n, const V3<i128>& d) {
  return multiply(n.x, d.x) + multiply(n.y, d.y) + multiply(n.z, d.z);
}

/// The small frame's products: a cross product of 64-bit vectors (components below 2^62:
/// below 2^125), and its dot product with another (below 2^189).
inline V3<i128> cross(const V3<std::int64_t>& a, const V3<std::int64_t>& b) {
  const auto product = [](std::int64_t x, std::int64_t y) { return static_cast<i128>(x) * y; };
  return {product(a.y, b.z) - product(a.z, b.y), product(a.z, b.x) - product(a.x, b.z),
          product(a.x, b.y) - product(a.y, b.x)};
}
/// x as N words (two's complement), shifted up by `words` words.
template <int N>
inline Int<N> widened(i128 x, int words) {
  Int<N> r;
  const std::uint64_t fill = x < 0 ? ~std::uint64_t{0} : 0;
  for (int i = 0; i < N; ++i) r.w[i] = fill;
  for (int i = 0; i < words; ++i) r.w[i] = 0;
  r.w[words] = static_cast<std::uint64_t>(x);
  if (words + 1 < N) r.w[words + 1] = static_cast<std::uint64_t>(static_cast<u128>(x) >> 64);
  return r;
}
inline Int<3> dot(const V3<i128>& n, const V3<std::int64_t>& d) {
  // n d = (hi 2^64 + lo) d for the signed high and unsigned low words of n (|n| < 2^126,
  // |d| < 2^62). Each lo d (below 2^126) is T 2^64 + w for T = lo d >> 64 (below 2^62) and
  // its low word w: the low words sum in 128 bits (below 3 2^64), hi d + T in one signed
  // 128-bit sum (below 2^125): a few products and additions, no carry loops.
  u128 low = 0;
  i128 high = 0;
  for (const auto& [c, e] : {std::pair{n.x, d.x}, std::pair{n.y, d.y}, std::pair{n.z, d.z}}) {
    const i128 t = static_cast<i128>(static_cast<std::uint64_t>(c)) * e;
    low += static_cast<std::uint64_t>(t);
    high += (c >> 64) * e + (t >> 64);
  }
  high += static_cast<i128>(low >> 64);
  return {{static_cast<std::uint64_t>(low), static_cast<std::uint64_t>(high),
           static_cast<std::uint64_t>(high >> 64)}};
}
/// Sets `out`, a default-constructed Mpzf (zero), to a 2^exp. Mpzf is M 2^(64 k) for an
/// integer M: |a| shifted by exp mod 64 is made an Mpzf through GMP's read-only view of its
/// words, and its exponent then moved by k words with simplify_quotient (which keeps x / y:
/// x's exponent drops by y's, for y = 2^(-64 j) an Mpzf of one word 1 and exponent -j, made
/// from its double).
template <int N>
inline void set_exact(const Int<N>& a, int exp, ExactN& out) {
  const bool negative = is_negative(a);
  const Int<N> x = negative ? negated(a) : a;
  std::uint64_t m[N + 1];
  const int r = exp & 63;  // exp mod 64, also for a negative exp
  int k = (exp - r) / 64;
  std::uint64_t low = 0;
  for (int i = 0; i < N; ++i) {
    m[i] = r == 0 ? x.w[i] : (x.w[i] << r) | low;
    low = r == 0 ? 0 : x.w[i] >> (64 - r);
  }
  m[N] = low;
  int n = N + 1;
  while (n > 0 && m[n - 1] == 0) --n;
  if (n == 0) return;
  mpz_t z;
  mpz_roinit_n(z, reinterpret_cast<const mp_limb_t*>(m), n);
  // Mpzf(Gmpz) is this call on a new Mpzf; it takes the magnitude only (CGAL 5.5): the sign
  // is set below.
  out.init_from_mpz_t(z);
  while (k != 0) {
    const int step = std::clamp(k, -15, 15);
    // 2^(-64 step), a normal double (|64 step| <= 960), from its bits.
    const std::uint64_t bits = static_cast<std::uint64_t>(1023 - 64 * step) << 52;
    double power;
    std::memcpy(&power, &bits, sizeof power);
    ExactN unit(power);
    simplify_quotient(out, unit);
    k -= step;
  }
  if (negative) out = -std::move(out);
}
inline void set_exact(i128 a, int exp, ExactN& out) { set_exact(widened<2>(a, 0), exp, out); }
inline void set_exact(const V3<i128>& v, int exp, V3<ExactN>& out) {
  set_exact(v.x, exp, out.x);
  set_exact(v.y, exp, out.y);
  set_exact(v.z, exp, out.z);
}
template <int N>
inline void set_exact(const V3<Int<N>>& v, int exp, V3<ExactN>& out) {
  set_exact(v.x, exp, out.x);
  set_exact(v.y, exp, out.y);
  set_exact(v.z, exp, out.z);
}

/// t (below 2^126) in double-double (round-to-nearest), without a library conversion of a
/// 128-bit integer: its three 42-bit pieces are exact doubles, the top two sum exactly
/// (two_sum), so does the third into that sum's hi, and the two low parts are added in one
/// rounded operation, within 2^-53 of their sum (at most an ulp of hi): within 2^-105 t. hi is
/// then the double nearest hi + lo (quick_two_sum, exact), so |lo| is at most half the gap to
/// hi's neighbour on lo's side. Every part is an integer: a non-zero lo is at least 1.
inline DD magnitude_dd(u128 t) {
  constexpr std::uint64_t kPiece = (std::uint64_t{1} << 42) - 1;
  const double d2 = static_cast<double>(static_cast<std::int64_t>(t >> 84)) * 0x1p84;
  const double d1 =
      static_cast<double>(static_cast<std::int64_t>(static_cast<std::uint64_t>(t >> 42) & kPiece)) *
      0x1p42;
  const double d0 =
      static_cast<double>(static_cast<std::int64_t>(static_cast<std::uint64_t>(t) & kPiece));
  const DD a = two_sum(d2, d1);
  const DD b = two_sum(a.hi, d0);
  return quick_two_sum(b.hi, a.lo + b.lo);
}

/// 2^exp a in double-double (round-to-nearest): the leading 126 bits of |a| (all of them
/// below 2^126) by magnitude_dd. Within 2^-103 of |hi|: magnitude_dd errs by 2^-105 of them,
/// the bits dropped below the leading 126 by under 2^-125 |a|. Both scale exactly: false when 2^exp
/// |a| could pass 2^600 or the scale fall below 2^-900 (a non-zero lo is an integer, at least that
/// scale), and `out` is then unchanged. As HalfSpace::offset_dd and normal_dd need.
template <int N>
inline bool to_dd(const Int<N>& a, int exp, DD& out) {
  const bool negative = is_negative(a);
  const Int<N> x = negative ? negated(a) : a;
  int top = N - 1;
  while (top >= 0 && x.w[top] == 0) --top;
  if (top < 0) {
    out = {0, 0};
    return true;
  }
  // |a| = T 2^shift + rest, T below 2^126 (its conversions to i128 and back exact).
  const int bits = 64 * top + 64 - __builtin_clzll(x.w[top]);
  const int shift = std::max(bits - 126, 0);
  const int e = exp + shift;
  if (e < -900 || e > 600 - 126) return false;
  const auto word = [&](int i) { return i < N ? x.w[i] : std::uint64_t{0}; };
  const int q = shift >> 6, r = shift & 63;
  const std::uint64_t low = r == 0 ? word(q) : (word(q) >> r) | (word(q + 1) << (64 - r));
  const std::uint64_t high = r == 0 ? word(q + 1) : (word(q + 1) >> r) | (word(q + 2) << (64 - r));
  const DD d = magnitude_dd((static_cast<u128>(high) << 64) | low);
  const double hi = d.hi, lo = d.lo;
  const std::uint64_t scale_bits = static_cast<std::uint64_t>(1023 + e) << 52;
  double scale;
  std::memcpy(&scale, &scale_bits, sizeof scale);
  out = negative ? DD{-hi * scale, -lo * scale} : DD{hi * scale, lo * scale};
  return true;
}

/// The normal (x1 - x0) x (y1 - y0) of doubles in a frame (frame.ok), exact, in 128 bits
/// per component for a small frame, else 256; its dot products with the frame's points.
class Normal {
 public:
  Normal(const Frame& frame, const V3<double>& x0, const V3<double>& x1, const V3<double>& y0,
         const V3<double>& y1)
      : frame_(frame) {
    if (frame.small)
      small_ = cross(small(x1) - small(x0), small(y1) - small(y0));
    else
      large_ = cross(large(x1) - large(x0), large(y1) - large(y0));
  }
  /// Sign of <n, u - v>.
  int sign_dot(const V3<double>& u, const V3<double>& v) const {
    return frame_.small ? sign(dot(small_, small(u) - small(v)))
                        : sign(dot(large_, large(u) - large(v)));
  }
  /// Sets `normal` (default-constructed: zero) to 2^doubling n.
  void set_normal(int doubling, V3<ExactN>& normal) const {
    if (frame_.small)
      set_exact(small_, 2 * frame_.unit + doubling, normal);
    else
      set_exact(large_, 2 * frame_.unit + doubling, normal);
  }
  /// 2^doubling n in double-double, each component within 2^-104 of its |hi| (magnitude_dd:
  /// hi the double nearest hi + lo), as HalfSpace::normal_dd;
  /// false for a large frame, or where the scaled words could leave 2^+-900 (then `out` is
  /// unchanged).
  bool normal_dd(int doubling, std::array<DD, 3>& out) const {
    const int e = 2 * frame_.unit + doubling;
    if (!frame_.small || e < -900 || e > 700) return false;  // |n| < 2^125
    const std::uint64_t bits = static_cast<std::uint64_t>(1023 + e) << 52;
    double scale;
    std::memcpy(&scale, &bits, sizeof scale);
    RoundingGuard nearest(CGAL_FE_TONEAREST);
    const i128 c[3] = {small_.x, small_.y, small_.z};
    for (int k = 0; k < 3; ++k) {
      // |c| below 2^126: magnitude_dd's hi and lo within 2^-105 |c| <= 2^-104 |hi|, integers,
      // so both scale exactly (non-zero ones are at least 2^e).
      bool negative;
      const DD d = magnitude_dd(magnitude(c[k], negative));
      out[k] = negative ? DD{-d.hi * scale, -d.lo * scale} : DD{d.hi * scale, d.lo * scale};
    }
    return true;
  }
  /// For a small frame: the words of n and of <n, u - v> with their exponents, the values
  /// that set_normal(doubling) and set_dot(doubling, u, &v) make Mpzf (set_exact makes them
  /// later, where needed). False for a large frame.
  bool small_words(int doubling, const V3<double>& u, const V3<double>& v, V3<i128>& normal,
                   int& normal_exp, Int<3>& dot_value, int& dot_exp) const {
    if (!frame_.small) return false;
    normal = small_;
    normal_exp = 2 * frame_.unit + doubling;
    dot_value = dot(small_, small(u) - small(v));
    dot_exp = 3 * frame_.unit + doubling;
    return true;
  }
  /// Sets `out` (default-constructed: zero) to 2^doubling <n, u - v>, or <n, u> when v is null;
  /// and `dd`, when not null, to its double-double copy from the same words (to_dd: within
  /// 2^-103 of |hi|), returning whether to_dd made one (else `dd` is unchanged).
  bool set_dot(int doubling, const V3<double>& u, const V3<double>* v, ExactN& out,
               DD* dd = nullptr) const {
    const int exp = 3 * frame_.unit + doubling;
    const auto set = [&](const auto& value) {
      set_exact(value, exp, out);
      if (!dd) return false;
      RoundingGuard nearest(CGAL_FE_TONEAREST);
      return to_dd(value, exp, *dd);
    };
    if (frame_.small) {
      const V3<std::int64_t> d = v ? small(u) - small(*v) : small(u);
      return set(dot(small_, d));
    }
    const V3<i128> d = v ? large(u) - large(*v) : large(u);
    return set(dot(large_, d));
  }

 private:
  V3<std::int64_t> small(const V3<double>& p) const {
    return {frame_.small_at(p.x), frame_.small_at(p.y), frame_.small_at(p.z)};
  }
  V3<i128> large(const V3<double>& p) const { return {frame_(p.x), frame_(p.y), frame_(p.z)}; }
  const Frame& frame_;
  V3<i128> small_;
  V3<I256> large_;
};

}  // namespace morph::detail::fixed
