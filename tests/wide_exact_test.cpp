// The fixed-point plane data of an erosion (libmorph/src/wide_exact.h): normals, offsets and
// signs of dot products must be exactly the Mpzf values, in both word sizes (a small frame and
// a large one), and a normal's double-double copy within its bound, on nearly degenerate
// triangles, points scaled by 2^+-200, shifted far from the origin, with zeros, tiny
// coordinates and subnormals; a frame it cannot hold (an infinity, doubles too far apart) must
// say so.
#include "wide_exact.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>

namespace {

using namespace morph::detail;

struct Case {
  V3<double> p, q, r, b;
};

/// A double-double copy within 2^-103 of |hi| (HalfSpace::offset_dd asks 2^-101) of the
/// exact value, |lo| at most half the gap to hi's neighbour on lo's side.
void check_dd(const DD& dd, const ExactN& exact) {
  const ExactN error = ExactN(dd.hi) + ExactN(dd.lo) - exact;
  CHECK(CGAL::abs(error) * ExactN(0x1p103) <= CGAL::abs(ExactN(dd.hi)));
  const double side = dd.lo < 0 ? -std::numeric_limits<double>::infinity()
                                : std::numeric_limits<double>::infinity();
  const double half_gap = 0.5 * std::abs(std::nextafter(dd.hi, side) - dd.hi);
  CHECK(std::abs(dd.lo) <= half_gap);
  CHECK((CGAL::sign(exact) == 0) == (dd.hi == 0));
}

/// The exact value 2^exp a of fixed-point words, from 32-bit pieces (exact doubles).
template <int N>
ExactN words_value(fixed::Int<N> a, int exp) {
  const bool negative = fixed::is_negative(a);
  if (negative) a = fixed::negated(a);
  ExactN v(0);
  for (int i = 0; i < N; ++i) {
    v = v + ExactN(std::ldexp(static_cast<double>(a.w[i] >> 32), 64 * i + 32 + exp)) +
        ExactN(std::ldexp(static_cast<double>(a.w[i] & 0xffffffff), 64 * i + exp));
  }
  return negative ? ExactN(0) - v : v;
}

/// Checks fixed::Normal against Mpzf on the triangle (p, q, r) and the point b; whether the
/// frame was small, large, or not ok (0, 1, 2).
int check(const Case& c) {
  const V3<double>&p = c.p, &q = c.q, &r = c.r, &b = c.b;
  const fixed::Frame frame{p.x, p.y, p.z, q.x, q.y, q.z, r.x, r.y, r.z, b.x, b.y, b.z};
  if (!frame.ok) return 2;
  const V3<ExactN> n = cross(exact_difference(q, p), exact_difference(r, p));
  const fixed::Normal f(frame, p, q, p, r);
  V3<ExactN> fn;
  f.set_normal(0, fn);
  CHECK(fn.x == n.x);
  CHECK(fn.y == n.y);
  CHECK(fn.z == n.z);
  V3<ExactN> doubled;
  f.set_normal(1, doubled);
  CHECK(doubled.x == n.x + n.x);
  CHECK(doubled.z == n.z + n.z);
  std::array<DD, 3> dd;
  if (f.normal_dd(1, dd)) {
    // Within 2^-104 of |hi| (HalfSpace::normal_dd asks 2^-101), |lo| at most half an ulp.
    const ExactN* exact[3] = {&doubled.x, &doubled.y, &doubled.z};
    for (int k = 0; k < 3; ++k) {
      const ExactN error = ExactN(dd[k].hi) + ExactN(dd[k].lo) - *exact[k];
      CHECK(CGAL::abs(error) * ExactN(0x1p104) <= CGAL::abs(ExactN(dd[k].hi)));
      const double half_ulp = 0.5 * std::abs(std::nextafter(dd[k].hi, 0.0) - dd[k].hi);
      CHECK(std::abs(dd[k].lo) <= half_ulp);
    }
  } else {
    const bool in_range = frame.small && std::abs(frame.unit) < 400;
    CHECK_FALSE(in_range);
  }
  const ExactN offset = dot(n, exact_difference(p, b));
  ExactN fo;
  DD odd{7, 0};
  if (f.set_dot(0, p, &b, fo, &odd)) {
    check_dd(odd, offset);
  } else {
    CHECK(odd.hi == 7);  // unchanged
    // to_dd refuses only a value from 2^474 or a scale below 2^-900.
    const bool in_range = 3 * frame.unit >= -900 && std::abs(offset.to_double()) < 0x1p470;
    CHECK_FALSE(in_range);
  }
  CHECK(fo == offset);
  CHECK(f.sign_dot(p, b) == CGAL::sign(offset));
  CHECK(f.sign_dot(b, q) == CGAL::sign(dot(n, exact_difference(b, q))));
  ExactN at_b;
  f.set_dot(1, b, nullptr, at_b);
  const ExactN expected = dot(n, to_exact_n(b));
  CHECK(at_b == expected + expected);
  return frame.small ? 0 : 1;
}

V3<double> scaled(const V3<double>& v, int e) {
  return {std::ldexp(v.x, e), std::ldexp(v.y, e), std::ldexp(v.z, e)};
}

}  // namespace

TEST_CASE("fixed-point plane data equals the Mpzf values on adversarial triangles") {
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> spread(-70, 70);
  int routes[3] = {0, 0, 0};
  const auto point = [&](int mode) {
    V3<double> v{unit(rng), unit(rng), unit(rng)};
    if (mode == 1) v = {std::ldexp(v.x, spread(rng)), std::ldexp(v.y, spread(rng)), v.z};
    if (mode == 2) v = {v.x + 1e6, v.y - 3e5, v.z};  // far from the origin
    if (rng() % 6 == 0) v.y = 0;
    if (rng() % 7 == 0) v.z = -0.0;
    return v;
  };
  for (int it = 0; it < 4000; ++it) {
    const int mode = it % 3;
    Case c{point(mode), point(mode), point(mode), point(mode)};
    if (it % 4 == 1) {
      // Nearly degenerate: q and r within a few ulps of p (a sliver, nearly zero normal).
      c.q = {std::nextafter(c.p.x, 2.0), c.p.y, std::nextafter(c.p.z, -2.0)};
      c.r = {c.p.x, std::nextafter(c.p.y, 2.0), std::nextafter(c.p.z, 2.0)};
    }
    if (it % 4 == 2) {
      // b on the plane through p, q, r (offset zero): b = p + (q - p) + (r - p) when exact.
      c.q = {c.p.x + 0.5, c.p.y, c.p.z};
      c.r = {c.p.x, c.p.y + 0.25, c.p.z};
      c.b = {c.p.x + 0.5, c.p.y + 0.25, c.p.z};
    }
    const int e = (it % 5 - 2) * 100;  // scaled by 2^-200 .. 2^200
    for (V3<double>* v : {&c.p, &c.q, &c.r, &c.b}) *v = scaled(*v, e);
    ++routes[check(c)];
  }
  // Both word sizes and the refusal were exercised.
  CHECK(routes[0] > 100);
  CHECK(routes[1] > 100);
  CHECK(routes[2] > 10);
}

TEST_CASE("fixed-point frames refuse what they cannot hold") {
  REQUIRE(fixed::exponent_shift_works());  // else every frame refuses (this CGAL's Mpzf)
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(fixed::Frame{1.0, inf}.ok);
  CHECK_FALSE(fixed::Frame{1.0, nan}.ok);
  CHECK_FALSE(fixed::Frame{1.0, 0x1p-120}.ok);  // 2^121 apart: beyond 116 bits
  const fixed::Frame wide{1.0, 0x1p-100};
  CHECK(wide.ok);
  CHECK_FALSE(wide.small);
  const fixed::Frame near{0.75, 0x1p-50, 0.0, -0.0};
  CHECK(near.small);
  CHECK(near.small_at(0.75) == std::int64_t{3} << 48);
  CHECK(near.small_at(-0.0) == 0);
  // Subnormals: exact in the large frame, never small (2^1074 is no double).
  const double tiny = std::numeric_limits<double>::denorm_min();
  const fixed::Frame sub{tiny, 3 * tiny};
  CHECK(sub.ok);
  CHECK_FALSE(sub.small);
  Case c{{tiny, 0, 0}, {0, 2 * tiny, 0}, {0, 0, 5 * tiny}, {-tiny, tiny, 0}};
  CHECK(check(c) == 1);
  // All zero: a zero normal and offset.
  Case z{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  CHECK(check(z) == 0);
}

TEST_CASE("fixed-point words to double-double: within the bound, or refused out of range") {
  // Integers of every width up to 6 words, with runs of ones and zeros (ties and carries
  // in the rounding of the leading 126 bits), either sign, scaled by 2^-1000 .. 2^600.
  std::mt19937_64 rng(1124);
  const auto word = [&] {
    switch (rng() % 5) {
      case 0:
        return std::uint64_t{0};
      case 1:
        return ~std::uint64_t{0};
      case 2:
        return std::uint64_t{1} << (rng() % 64);
      case 3:
        return (std::uint64_t{1} << 63) | 1;
      default:
        return static_cast<std::uint64_t>(rng());
    }
  };
  int converted = 0, refused = 0;
  for (int it = 0; it < 20000; ++it) {
    fixed::Int<6> a{};
    const int used = 1 + static_cast<int>(rng() % 6);
    for (int i = 0; i < used; ++i) a.w[i] = word();
    if (rng() % 2) a = fixed::negated(a);
    const int exp = static_cast<int>(rng() % 1600) - 1000;
    DD out{7, 7};
    if (fixed::to_dd(a, exp, out)) {
      ++converted;
      check_dd(out, words_value(a, exp));
    } else {
      ++refused;
      CHECK(out.hi == 7);
      CHECK(out.lo == 7);
    }
    // The same value in three words, when it fits (the small frame's offsets).
    fixed::Int<3> b{{a.w[0], a.w[1], a.w[2]}};
    if (words_value(b, 0) == words_value(a, 0) && fixed::to_dd(b, exp, out))
      check_dd(out, words_value(a, exp));
  }
  CHECK(converted > 5000);
  CHECK(refused > 1000);
  // magnitude_dd at binade boundaries (lo below a power of two: the smaller gap), at and
  // next to ties of the top 53 bits, across the 42-bit pieces.
  const fixed::u128 one = 1;
  for (int k = 0; k < 126; ++k) {
    for (const fixed::u128 t :
         {one << k, (one << k) - 1, (one << k) + 1, (one << k) | (one << (k > 53 ? k - 53 : 0)),
          ((one << k) | (one << (k > 53 ? k - 53 : 0))) + 1, (one << k) | (one << (k / 2)) | 1,
          (one << 126) - 1 - (one << k)}) {
      if (t >= (one << 126)) continue;
      const DD d = fixed::magnitude_dd(t);
      check_dd(d, words_value(fixed::Int<2>{{static_cast<std::uint64_t>(t),
                                             static_cast<std::uint64_t>(t >> 64)}},
                              0));
    }
  }
  // Exactly at a tie of the leading 126 bits, and zero.
  fixed::Int<3> tie{{0, (std::uint64_t{1} << 61) | 1, 1}};
  DD out;
  REQUIRE(fixed::to_dd(tie, -200, out));
  check_dd(out, words_value(tie, -200));
  REQUIRE(fixed::to_dd(fixed::Int<3>{{0, 0, 0}}, 0, out));
  CHECK(out.hi == 0);
  CHECK(out.lo == 0);
}
