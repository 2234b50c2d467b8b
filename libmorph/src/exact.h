// Private: number types and filtered exact predicates used by every combinatorial
// decision of libmorph. A predicate is evaluated first in interval arithmetic; only
// when the interval contains zero is it evaluated again with exact rationals. No
// decision ever uses an epsilon. (The predicates on facet normals, see polytope.h, filter
// with doubles and error bounds instead of intervals.)
#pragma once

#include <CGAL/Gmpq.h>
#include <CGAL/Interval_nt.h>
#include <CGAL/Mpzf.h>

#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace morph::detail {

using Interval = CGAL::Interval_nt<false>;  // needs the rounding mode set upward (RoundingGuard)
using Exact = CGAL::Gmpq;  // rationals: positions of erosion results, planes, the LP
/// Exact dyadic floats, much faster than rationals (no gcd) for +, - and *: the facet
/// normals and every predicate on them (polynomials in double coordinates).
using ExactN = CGAL::Mpzf;

/// Sets the FPU rounding mode upward for interval arithmetic, restores it at scope exit.
/// Every thread that evaluates predicates holds one; plain double arithmetic that must
/// round to nearest (vertex positions) is done outside of it, under RoundingGuard(
/// CGAL_FE_TONEAREST). As CGAL::Protect_FPU_rounding<true>, but the control register is
/// written (and restored) only when its mode differs: reading it is cheap, writing it is
/// not, and most guards find their mode set already (nested in a chunk's guard of the same
/// mode, or round-to-nearest by default: a per-facet guard cost up to 1.7% of an erosion).
class RoundingGuard {
 public:
  explicit RoundingGuard(CGAL::FPU_CW_t mode = CGAL_FE_UPWARD)
      : backup_(CGAL::FPU_get_cw()), changed_(backup_ != mode) {
    if (changed_) CGAL::FPU_set_cw(mode);
  }
  ~RoundingGuard() {
    if (changed_) CGAL::FPU_set_cw(backup_);
  }
  RoundingGuard(const RoundingGuard&) = delete;
  RoundingGuard& operator=(const RoundingGuard&) = delete;

 private:
  CGAL::FPU_CW_t backup_;
  bool changed_;
};

template <class T>
struct V3 {
  T x, y, z;
};

template <class T>
inline V3<T> operator+(const V3<T>& a, const V3<T>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
inline V3<T> operator-(const V3<T>& a, const V3<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
inline V3<T> cross(const V3<T>& a, const V3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
inline T dot(const V3<T>& a, const V3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
inline T det(const V3<T>& a, const V3<T>& b, const V3<T>& c) {
  return dot(a, cross(b, c));
}
/// (a x b) . (c x d) = (a.c)(b.d) - (a.d)(b.c), without forming the cross products.
template <class T>
inline T cross_dot(const V3<T>& a, const V3<T>& b, const V3<T>& c, const V3<T>& d) {
  return dot(a, c) * dot(b, d) - dot(a, d) * dot(b, c);
}

/// Newell's normal of a closed polygon: twice its vector area. For a planar polygon it
/// is exactly perpendicular to the plane, for any number of vertices.
template <class T, class PointAt>
inline V3<T> newell_normal(int n, const PointAt& point_at) {
  V3<T> sum{T(0), T(0), T(0)};
  for (int i = 0; i < n; ++i) {
    const V3<T>& p = point_at(i);
    const V3<T>& q = point_at(i + 1 == n ? 0 : i + 1);
    sum.x += (p.y - q.y) * (p.z + q.z);
    sum.y += (p.z - q.z) * (p.x + q.x);
    sum.z += (p.x - q.x) * (p.y + q.y);
  }
  return sum;
}

/// Double-double arithmetic (Dekker, Knuth; as in Hida, Li and Bailey's QD library),
/// valid in round-to-nearest only. A value is hi + lo with |lo| <= ulp(hi) / 2. Each
/// operation below errs by at most 4u^2 (u = 2^-53) times the magnitude of its operands'
/// sum or product; the error bounds built on them are generous multiples of that.
struct DD {
  double hi, lo;
};
inline DD two_sum(double a, double b) {
  const double s = a + b, bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}
inline DD quick_two_sum(double a, double b) {
  const double s = a + b;
  return {s, b - (s - a)};
}
inline DD split(double a) {          // Veltkamp: a = hi + lo with 26-bit halves (|a| < 2^995)
  const double c = 134217729.0 * a;  // 2^27 + 1
  const double hi = c - (c - a);
  return {hi, a - hi};
}
/// a b = hi + lo exactly (round-to-nearest, |a|, |b| < 2^995, no underflow), by Dekker's
/// product: baseline x86-64 has no fused multiply-add.
inline DD two_prod_dekker(double a, double b) {
  const double p = a * b;
  const DD x = split(a), y = split(b);
  return {p, ((x.hi * y.hi - p) + x.hi * y.lo + x.lo * y.hi) + x.lo * y.lo};
}

#if defined(__x86_64__) && defined(__GNUC__)
/// Whether the processor (and the system) can run FMA instructions: checked once, at startup.
inline const bool kHasFma = [] {
  __builtin_cpu_init();  // the check may run before libgcc's own constructor
  return __builtin_cpu_supports("fma") != 0;
}();
/// two_prod_dekker's hi and lo with one fused multiply-subtract (a b - hi, rounded once: exact
/// where Dekker's is, so the same doubles), in inline assembly rather than through a target
/// attribute, which would keep it from being inlined into baseline code, or -ffp-contract,
/// which could fuse other expressions and change their rounding. Only where kHasFma.
inline DD two_prod_fma(double a, double b) {
  const double p = a * b;
  double lo = p;
  asm("vfmsub231sd %2, %1, %0" : "+x"(lo) : "x"(a), "x"(b));  // lo = a b - lo
  return {p, lo};
}
#else
inline constexpr bool kHasFma = false;
inline DD two_prod_fma(double a, double b) { return two_prod_dekker(a, b); }
#endif

/// a b = hi + lo exactly (see two_prod_dekker): the fused form where the processor has it
/// (measured: icosphere_320 (+) icosphere_1280's kernel 132 -> 127 us, its whole sum and the
/// erosion of uvsphere_1600 by the snub dodecahedron about 2% faster). The check is one load
/// of a flag that never changes; before it is set (code run by static constructors) Dekker's.
inline DD two_prod(double a, double b) {
  return kHasFma ? two_prod_fma(a, b) : two_prod_dekker(a, b);
}
inline DD operator+(const DD& a, const DD& b) {
  const DD s = two_sum(a.hi, b.hi);
  return quick_two_sum(s.hi, s.lo + (a.lo + b.lo));
}
inline DD operator-(const DD& a) { return {-a.hi, -a.lo}; }
inline DD operator-(const DD& a, const DD& b) { return a + -b; }
inline DD operator*(const DD& a, const DD& b) {
  const DD p = two_prod(a.hi, b.hi);
  return quick_two_sum(p.hi, p.lo + (a.hi * b.lo + a.lo * b.hi));
}
inline constexpr double kU2 = 0x1p-106;  // u^2

/// x as a double-double, in round-to-nearest, and in `error` a bound on its distance to x
/// (infinite when x is beyond the doubles). One exact subtraction: x - hi is enclosed by
/// Mpzf from its limbs (in any rounding mode) between equal or neighbouring doubles l <= h,
/// so x lies in [hi + l, hi + h].
inline DD to_dd(const ExactN& x, double& error) {
  const double hi = x.to_double();  // within an ulp of x
  if (!std::isfinite(hi)) {
    error = std::numeric_limits<double>::infinity();
    return {hi, 0};
  }
  const std::pair<double, double> rest = (x - ExactN(hi)).to_interval();
  error = rest.second - rest.first;  // exact: neighbours, or a subnormal and zero
  return quick_two_sum(hi, rest.first);
}

/// a - b exactly: the double difference when it is exact (Sterbenz: same signs and within a
/// factor 2 of each other, in any rounding mode), else the Mpzf subtraction.
inline ExactN exact_difference(double a, double b) {
  // One conversion instead of two and a subtraction: nearby vertices of a mesh (a facet's
  // edges) almost always pass. 2 |b| may overflow to infinity or DBL_MAX, where the test
  // still holds; a NaN fails it.
  const double x = std::abs(a), y = std::abs(b);
  if ((a < 0) == (b < 0) && x <= 2 * y && y <= 2 * x) return ExactN(a - b);
  return ExactN(a) - ExactN(b);
}
inline V3<ExactN> exact_difference(const V3<double>& a, const V3<double>& b) {
  return {exact_difference(a.x, b.x), exact_difference(a.y, b.y), exact_difference(a.z, b.z)};
}

/// Sign of an interval, or 2 when it straddles zero (undecided).
inline int interval_sign(const Interval& v) {
  if (v.inf() > 0) return 1;
  if (v.sup() < 0) return -1;
  if (v.inf() == 0 && v.sup() == 0) return 0;
  return 2;
}

inline V3<Interval> to_interval(const V3<double>& p) {
  return {Interval(p.x), Interval(p.y), Interval(p.z)};
}
inline V3<Exact> to_exact(const V3<double>& p) { return {Exact(p.x), Exact(p.y), Exact(p.z)}; }
inline V3<ExactN> to_exact_n(const V3<double>& p) {
  return {ExactN(p.x), ExactN(p.y), ExactN(p.z)};
}
inline V3<Exact> to_rational(const V3<ExactN>& p) { return {Exact(p.x), Exact(p.y), Exact(p.z)}; }
inline V3<Interval> to_interval(const V3<Exact>& p) {
  return {Interval(CGAL::to_interval(p.x)), Interval(CGAL::to_interval(p.y)),
          Interval(CGAL::to_interval(p.z))};
}
inline Interval to_interval_n(const ExactN& x) { return Interval(x.to_interval()); }
inline V3<Interval> to_interval_n(const V3<ExactN>& p) {
  return {to_interval_n(p.x), to_interval_n(p.y), to_interval_n(p.z)};
}

/// Rounds an exact rational to the nearest double (ties to even).
double round_to_nearest(const Exact& q);

/// X / W (W > 0) rounded to the nearest double, ties to even, as round_to_nearest(X / W)
/// but without rationals; `estimate` (any interval near X / W, not necessarily an
/// enclosure) is where the search starts.
double round_quotient(const ExactN& X, const ExactN& W, const Interval& estimate);

}  // namespace morph::detail
