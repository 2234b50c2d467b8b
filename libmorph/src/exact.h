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

namespace morph::detail {

using Interval = CGAL::Interval_nt<false>;  // needs the rounding mode set upward (RoundingGuard)
using Exact = CGAL::Gmpq;  // rationals: positions of erosion results, planes, the LP
/// Exact dyadic floats, much faster than rationals (no gcd) for +, - and *: the facet
/// normals and every predicate on them (polynomials in double coordinates).
using ExactN = CGAL::Mpzf;

/// Sets the FPU rounding mode upward for interval arithmetic, restores it at scope exit.
/// Every thread that evaluates predicates holds one; plain double arithmetic that must
/// round to nearest (vertex positions) is done outside of it.
using RoundingGuard = CGAL::Protect_FPU_rounding<true>;

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

/// Rounds an exact rational to the nearest double (ties to even).
double round_to_nearest(const Exact& q);

/// X / W (W > 0) rounded to the nearest double, ties to even, as round_to_nearest(X / W)
/// but without rationals; `estimate` (any interval near X / W, not necessarily an
/// enclosure) is where the search starts.
double round_quotient(const ExactN& X, const ExactN& W, const Interval& estimate);

}  // namespace morph::detail
