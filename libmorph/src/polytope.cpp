#include "polytope.h"

#include <morph/error.h>
#include <morph/validate.h>
#include <mpfr.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <unordered_map>

#include "double_pair.h"
#include "parallel.h"
#include "union_find.h"
#include "validate_detail.h"

namespace morph::detail {

double round_to_nearest(const Exact& q) {
  mpfr_t r;
  mpfr_init2(r, 53);
  mpfr_set_q(r, q.mpq(), MPFR_RNDN);
  const double d = mpfr_get_d(r, MPFR_RNDN);
  mpfr_clear(r);
  return d;
}

const V3<ExactN>& Polytope::exact_normal(int f) const {
  if (!given_normals.empty()) return given_normals[f];
  return exact_cache_->get(f, [&] {
    const int b = face_begin[f];
    std::vector<V3<ExactN>> cycle;
    cycle.reserve(degree(f));
    for (int k = 0; k < degree(f); ++k) cycle.push_back(to_exact_n(points[corner_vertex[b + k]]));
    return newell_normal<ExactN>(degree(f), [&](int i) -> const V3<ExactN>& { return cycle[i]; });
  });
}

namespace {

/// Whether component i of a triangle's Newell normal, (q - p) x (r - p), is exactly zero by a
/// cheap sufficient test: two corners coincide in projection onto the other two axes (the
/// projected triangle is degenerate). A facet symmetric under the mirror x_i -> -x_i is such a
/// triangle (the mirror fixes one corner and swaps the other two, which then differ only in
/// x_i). False when the test does not show it.
bool projection_degenerate(const V3<double>& p, const V3<double>& q, const V3<double>& r, int i) {
  const double pp[3] = {p.x, p.y, p.z}, qq[3] = {q.x, q.y, q.z}, rr[3] = {r.x, r.y, r.z};
  const int j = (i + 1) % 3, l = (i + 2) % 3;
  return (pp[j] == qq[j] && pp[l] == qq[l]) || (qq[j] == rr[j] && qq[l] == rr[l]) ||
         (rr[j] == pp[j] && rr[l] == pp[l]);
}

/// The precise normal of a facet with double points: the points scaled by a power of
/// two (exactly) so the largest coordinate is about 1, Newell's sum in double-double. A
/// component that might be zero is decided exactly (mirror-symmetric facets have exactly
/// zero components, and predicates on them are then decided without exact arithmetic).
PreciseNormal precise_newell(const std::vector<V3<double>>& points, const int* corners, int d) {
  PreciseNormal n{};
  double largest = 0;
  for (int k = 0; k < d; ++k) {
    const auto& p = points[corners[k]];
    largest = std::max({largest, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  }
  if (!(largest > 0) || !std::isfinite(largest)) return n;
  const int shift = -std::ilogb(largest);
  const double scale = std::ldexp(1.0, shift), unscale = std::ldexp(1.0, -shift);
  bool exact = true;
  auto scaled = [&](double x) {
    const double y = x * scale;  // exact unless it underflows
    exact = exact && y * unscale == x;
    return y;
  };
  DD sum[3] = {{0, 0}, {0, 0}, {0, 0}};
  double magnitude[3] = {0, 0, 0};  // sum of |term|: bounds every partial sum
  int operations = 0;               // dd operations along each component's sum
  if (d == 3) {
    // A triangle's Newell normal is the cross product of two edges (fewer operations).
    const auto &p0 = points[corners[0]], &q0 = points[corners[1]], &r0 = points[corners[2]];
    const double p[3] = {scaled(p0.x), scaled(p0.y), scaled(p0.z)};
    const double q[3] = {scaled(q0.x), scaled(q0.y), scaled(q0.z)};
    const double r[3] = {scaled(r0.x), scaled(r0.y), scaled(r0.z)};
    DD a[3], b[3];
    for (int i = 0; i < 3; ++i) {
      a[i] = two_sum(q[i], -p[i]);  // exact
      b[i] = two_sum(r[i], -p[i]);
    }
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, l = (i + 2) % 3;
      sum[i] = a[j] * b[l] - a[l] * b[j];
      magnitude[i] = std::abs(a[j].hi) * std::abs(b[l].hi) + std::abs(a[l].hi) * std::abs(b[j].hi);
    }
    operations = 3;
  } else {
    for (int k = 0; k < d; ++k) {
      const auto& p0 = points[corners[k]];
      const auto& q0 = points[corners[k + 1 == d ? 0 : k + 1]];
      const double p[3] = {scaled(p0.x), scaled(p0.y), scaled(p0.z)};
      const double q[3] = {scaled(q0.x), scaled(q0.y), scaled(q0.z)};
      for (int i = 0; i < 3; ++i) {
        // Component i: (p[j] - q[j]) (p[l] + q[l]) with (j, l) = (y, z), (z, x), (x, y).
        const int j = (i + 1) % 3, l = (i + 2) % 3;
        const DD diff = two_sum(p[j], -q[j]), total = two_sum(p[l], q[l]);  // exact
        sum[i] = sum[i] + diff * total;
        magnitude[i] += std::abs(diff.hi) * std::abs(total.hi);
      }
    }
    operations = 2 * d;
  }
  if (!exact) return n;
  for (int i = 0; i < 3; ++i) {
    n.hi[i] = sum[i].hi;
    n.lo[i] = sum[i].lo;
    // Each operation errs by at most 4u^2 times magnitudes that the sum of |term| bounds
    // (|lo| adds 2u); doubled, plus an absolute term for underflow.
    n.error[i] = 8 * (operations + 1) * kU2 * magnitude[i] * 1.01 + 0x1p-1000;
    if (std::abs(n.hi[i]) <= n.error[i]) {
      if (d == 3 &&
          projection_degenerate(points[corners[0]], points[corners[1]], points[corners[2]], i)) {
        n.hi[i] = n.lo[i] = n.error[i] = 0;
        continue;
      }
      const int j = (i + 1) % 3, l = (i + 2) % 3;
      ExactN component(0);
      for (int k = 0; k < d; ++k) {
        const auto& p = points[corners[k]];
        const auto& q = points[corners[k + 1 == d ? 0 : k + 1]];
        const double pq[2][3] = {{p.x, p.y, p.z}, {q.x, q.y, q.z}};
        component += (ExactN(pq[0][j]) - ExactN(pq[1][j])) * (ExactN(pq[0][l]) + ExactN(pq[1][l]));
      }
      if (CGAL::sign(component) == CGAL::ZERO) n.hi[i] = n.lo[i] = n.error[i] = 0;
    }
  }
  n.valid = true;
  return n;
}

/// The precise normal of a facet with a given exact normal (exact points): the components
/// scaled by one power of two (exactly) so that the largest is about 1, each split into a
/// double-double whose distance to it, an exact remainder, is enclosed for its error.
/// Needs round-to-nearest, as the double-double stage that uses it.
PreciseNormal precise_given(const V3<ExactN>& normal) {
  PreciseNormal n{};
  const ExactN* components[3] = {&normal.x, &normal.y, &normal.z};
  double largest = 0;
  for (const ExactN* c : components) largest = std::max(largest, std::abs(c->to_double()));
  if (!(largest > 0) || !std::isfinite(largest)) return n;
  const int shift = -std::ilogb(largest);
  if (std::abs(shift) > 900) return n;  // the scale must be a double
  const ExactN scale(std::ldexp(1.0, shift));
  for (int i = 0; i < 3; ++i) {
    const ExactN x = *components[i] * scale;
    if (CGAL::sign(x) == CGAL::ZERO) continue;  // exactly zero: hi = lo = error = 0
    const DD s = to_dd(x, n.error[i]);
    n.hi[i] = s.hi;
    n.lo[i] = s.lo;
  }
  n.valid = true;
  return n;
}

/// Upper bound on the Euclidean length of a precise normal (the sum of |components|).
double length_bound(const PreciseNormal& n) {
  return (std::abs(n.hi[0]) + std::abs(n.hi[1]) + std::abs(n.hi[2])) * (1 + 1e-15) + n.error[0] +
         n.error[1] + n.error[2];
}

/// Upper bound on the Euclidean length of a precise normal's error vector.
double error_bound(const PreciseNormal& n) { return n.error[0] + n.error[1] + n.error[2]; }

}  // namespace

const PreciseNormal& Polytope::precise_normal(int f) const {
  return precise_cache_->get(f, [&] {
    if (!given_normals.empty()) {
      PreciseNormal copy;
      return given_normals.precise(f, copy) ? copy : precise_given(given_normals[f]);
    }
    return precise_newell(points, &corner_vertex[face_begin[f]], degree(f));
  });
}

namespace {

constexpr double kUlp = 0x1p-52;  // one ulp relative to the result: any rounding mode

/// The unit vector of m (non-zero, finite) with a bound on its distance to the direction
/// of any vector within `radius` of m: 2 radius / |m| (the normalisation adds a few ulps;
/// margins cover the rounding of |m| and of the bound). Far from 1, both are first scaled by
/// a power of two (exactly) so that |m|^2 neither overflows nor underflows. Infinite error when m
/// does not tell a direction.
inline UnitNormal normalised(V3<double> m, double radius) {
  const double largest = std::max({std::abs(m.x), std::abs(m.y), std::abs(m.z)});
  if (!(largest > 0) || !std::isfinite(largest) || !std::isfinite(radius))
    return {0, 0, 0, std::numeric_limits<double>::infinity()};
  if (!(largest > 1e-100 && largest < 1e100)) {
    const double scale = std::ldexp(1.0, -std::ilogb(largest));
    m = {m.x * scale, m.y * scale, m.z * scale};
    radius *= scale;
  }
  const double inverse = 1 / std::sqrt(dot(m, m));
  double error = 2 * radius * inverse * (1 + 1e-10) + 4e-15;
  if (!std::isfinite(error) || error > 1) error = std::numeric_limits<double>::infinity();
  return {m.x * inverse, m.y * inverse, m.z * inverse, error};
}

/// Facet f's unit normal from its double points: centroid_unit_normal() of its Newell sum
/// relative to its centroid, in the operations of the operand check's planes (validate.cpp:
/// newell_plane(), the unrolled triangles and quadrilaterals, and the magnitude beside them),
/// so that make_operand takes the check's values instead of computing them again and every
/// path gives the same. Where that function refuses (|n| far from 1), normalised() with the
/// same radius.
UnitNormal unit_newell(const std::vector<V3<double>>& points, const int* corners, int d) {
  double cx = 0.0, cy = 0.0, cz = 0.0;
  for (int k = 0; k < d; ++k) {
    const V3<double>& p = points[corners[k]];
    cx += p.x;
    cy += p.y;
    cz += p.z;
  }
  const double scale = 1.0 / d;
  cx *= scale;
  cy *= scale;
  cz *= scale;
  double nx = 0.0, ny = 0.0, nz = 0.0, magnitude = 0.0;
  const V3<double>& p0 = points[corners[0]];
  const double a0[3] = {p0.x - cx, p0.y - cy, p0.z - cz};
  const double l0 = norm1(a0[0], a0[1], a0[2]);
  double ax = a0[0], ay = a0[1], az = a0[2], la = l0;
  for (int k = 0; k < d; ++k) {
    double bx, by, bz, lb;
    if (k + 1 == d) {
      bx = a0[0], by = a0[1], bz = a0[2], lb = l0;
    } else {
      const V3<double>& q = points[corners[k + 1]];
      bx = q.x - cx, by = q.y - cy, bz = q.z - cz;
      lb = norm1(bx, by, bz);
    }
    nx += ay * bz - az * by;
    ny += az * bx - ax * bz;
    nz += ax * by - ay * bx;
    magnitude += la * lb;
    ax = bx, ay = by, az = bz, la = lb;
  }
  const double length = std::sqrt((nx * nx + ny * ny) + nz * nz);
  UnitNormal u;
  if (centroid_unit_normal(nx, ny, nz, length, 1.0 / length, magnitude, d, u)) return u;
  return normalised({nx, ny, nz}, ((d + 4) * kUlp * 1.01 * magnitude + 3 * d * 0x1p-1000) * 1.01);
}

/// The unit normal of an interval enclosure n of a facet's Newell normal: its midpoint m,
/// within the box's half-diagonal of the exact normal (the width sums, rounded upwards
/// under the caller's RoundingGuard, bound the half-diagonal).
UnitNormal unit_of_enclosure(const V3<Interval>& n) {
  const V3<double> m{0.5 * (n.x.inf() + n.x.sup()), 0.5 * (n.y.inf() + n.y.sup()),
                     0.5 * (n.z.inf() + n.z.sup())};
  const double width = (n.x.sup() - n.x.inf()) + (n.y.sup() - n.y.inf()) + (n.z.sup() - n.z.inf());
  return normalised(m, width * 1.01);
}

/// The unit normal of a precise normal: its high parts, within sum(|lo| + error) of the
/// exact normal (times the copy's positive scale), which bounds the Euclidean distance; the
/// factor covers the rounding of the sum. Infinite error when the copy is not valid.
UnitNormal unit_of_precise(const PreciseNormal& n) {
  if (!n.valid) return {0, 0, 0, std::numeric_limits<double>::infinity()};
  double radius = 0;
  for (int i = 0; i < 3; ++i) radius += std::abs(n.lo[i]) + n.error[i];
  return normalised({n.hi[0], n.hi[1], n.hi[2]}, radius * 1.01);
}

}  // namespace

void Polytope::compute_normals(bool units_known) {
  const int nf = num_faces();
  unit_normals.resize(nf);
  exact_cache_ = std::make_shared<LazySlots<V3<ExactN>>>(nf);
  precise_cache_ = std::make_shared<FlatSlots<PreciseNormal>>(nf);
  if (units_known) {
    // Nothing to compute.
  } else if (given_normals.has_source()) {
    // Normals given by a source (an erosion's half-spaces): the unit normal from the precise
    // one (the half-space's double-double copy, else its exact normal's, made already where
    // there is no copy), as tight as a double point's Newell normal, and kept. The vertices'
    // enclosures give loose ones (an erosion's vertices of nearly parallel planes: at
    // icosphere level 6 by its rotated copy, about 2e-5 against 1e-14 from the meets'
    // intervals), which left the next sum's double filters undecided nearly everywhere.
    // (A copy the source has at hand goes straight into the cache, which no one reads yet.)
    parallel_chunks(nf, 1024, [&](int begin, int end) {
      RoundingGuard nearest(CGAL_FE_TONEAREST);  // (the precise copies' splits)
      PreciseNormal copy;
      for (int f = begin; f < end; ++f) {
        if (given_normals.precise(f, copy)) {
          precise_cache_->set(f, copy);
          unit_normals[f] = unit_of_precise(copy);
        } else {
          unit_normals[f] = unit_of_precise(precise_normal(f));
        }
      }
    });
  } else if (exact_points.empty()) {
    parallel_chunks(nf, 1024, [&](int begin, int end) {
      for (int f = begin; f < end; ++f)
        unit_normals[f] = unit_newell(points, &corner_vertex[face_begin[f]], degree(f));
    });
  } else {
    parallel_chunks(nf, 1024, [&](int begin, int end) {
      RoundingGuard guard;
      std::vector<V3<Interval>> cycle;  // conversions from rationals are worth caching
      for (int f = begin; f < end; ++f) {
        const int b = face_begin[f];
        cycle.clear();
        for (int k = 0; k < degree(f); ++k) cycle.push_back(interval_point(corner_vertex[b + k]));
        unit_normals[f] = unit_of_enclosure(newell_normal<Interval>(
            degree(f), [&](int i) -> const V3<Interval>& { return cycle[i]; }));
      }
    });
  }
}

int orient_normals_undecided(const NormalRef& a, const NormalRef& b, const NormalRef& c) {
  const int s = orient_normals_precise(a, b, c);
  return s != kUndecided ? s : orient_normals_exact(a, b, c);
}

int orient_normals_exact(const NormalRef& a, const NormalRef& b, const NormalRef& c) {
  return CGAL::sign(det(a.exact(), b.exact(), c.exact()));
}

namespace {

/// projection_degenerate for facet f of P (a triangle with double points; false otherwise).
bool component_surely_zero(const Polytope& P, int f, int i) {
  if (P.degree(f) != 3 || !P.given_normals.empty()) return false;
  const int* const c = &P.corner_vertex[P.face_begin[f]];
  return projection_degenerate(P.points[c[0]], P.points[c[1]], P.points[c[2]], i);
}

}  // namespace

/// N_x x N_y for a nearly parallel pair x, y, times a positive factor, as doubles w with a
/// bound eps on their (Euclidean) distance to it: the cross product in double-double of x's and
/// y's precise normals. False when a precise normal is not valid. Round-to-nearest (the
/// caller's guard). With X, Y the precise normals (sigma_x N_x + E_x, sigma_y N_y + E_y,
/// sigma > 0), W the computed X x Y and w its high parts:
///  - |W - X x Y| <= 32 u^2 (|X_j Y_l| + |X_l Y_j|) per component (precise_newell's triangle
///    bound: two products and a difference of double-doubles, doubled), with 1.01 for the
///    rounding of the magnitudes and 2^-1000 for underflow;
///  - |X x Y - sigma_x sigma_y N_x x N_y| <= |E_x| |Y| + |X*| |E_y| (length and error bounds);
///  - |w - W| <= sum |lo|;
/// eps sums the three (per-component bounds summed bound the Euclidean distance).
bool precise_cross(const NormalRef& x, const NormalRef& y, double w[3], double& eps) {
  const PreciseNormal& X = x.polytope->precise_normal(x.face);
  const PreciseNormal& Y = y.polytope->precise_normal(y.face);
  if (!X.valid || !Y.valid) return false;
  auto dd = [](const PreciseNormal& n, int i) { return DD{n.hi[i], n.lo[i]}; };
  eps = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, l = (i + 2) % 3;
    const DD c = dd(X, j) * dd(Y, l) - dd(X, l) * dd(Y, j);
    const double magnitude =
        std::abs(X.hi[j]) * std::abs(Y.hi[l]) + std::abs(X.hi[l]) * std::abs(Y.hi[j]);
    w[i] = c.hi;
    eps += 32 * kU2 * magnitude * 1.01 + 0x1p-1000 + std::abs(c.lo);
  }
  eps += error_bound(X) * length_bound(Y) + length_bound(X) * error_bound(Y);
  return true;
}

namespace {

/// Sign of z . (N_x x N_y) for a nearly parallel pair x, y (or kUndecided): precise_cross,
/// dotted in doubles with z's unit normal. The far normal z needs no precise normal:
/// det(x, y, z) of two nearly parallel normals is small because N_x x N_y is, and only that
/// product needs the extra precision. For w within eps of W* (a positive multiple of
/// N_x x N_y) and the unit normal z^ within e_z of z = N_z / |N_z| (|z| = 1), the double dot
/// D = z^ . w satisfies |D - z . W*| <= |D - z^ . w| + e_z |w| + eps, with |D - z^ . w| <= 3
/// ulps (any rounding) of sum |z^_i w_i| and |w| <= sum |w_i|: the bound below, with margins.
/// z . W* has the sign of det(N_x, N_y, N_z).
int orient_near_pair(const NormalRef& x, const NormalRef& y, const UnitNormal& z) {
  double w[3], eps;
  if (!std::isfinite(z.error) || !precise_cross(x, y, w, eps)) return kUndecided;
  const double d = z.x * w[0] + z.y * w[1] + z.z * w[2];
  const double size = std::abs(w[0]) + std::abs(w[1]) + std::abs(w[2]);
  const double products = std::abs(z.x * w[0]) + std::abs(z.y * w[1]) + std::abs(z.z * w[2]);
  const double bound = (z.error * size + eps + 4 * 0x1p-52 * products) * 1.01 + 0x1p-1000;
  if (d > bound) return 1;
  if (d < -bound) return -1;
  return kUndecided;
}

/// Sign of (N_x x N_y) . (N_z x N_t) for a nearly parallel pair x, y (or kUndecided):
/// precise_cross (w within eps of W*, a positive multiple of N_x x N_y), dotted in doubles with
/// v = z^ x t^ from the unit normals. For the unit vectors z, t of N_z, N_t: |z^ x t^ - z x t|
/// <= e_z |t^| + |z| e_t <= 1.01 e_z + e_t, and rounding v's components adds at most 2e-14
/// (kUnitPredicateRounding's bound on such unit evaluations): |v - z x t| <= ev. Then the
/// double dot D = w . v satisfies |D - W* . (z x t)| <= |D - w . v| + eps |v| + |W*| ev, with
/// |D - w . v| <= 3 ulps of sum |w_i v_i|, |v| <= sum |v_i| and |W*| <= sum |w_i| + eps.
int cross_dot_near_pair(const NormalRef& x, const NormalRef& y, const UnitNormal& z,
                        const UnitNormal& t) {
  double w[3], eps;
  if (!std::isfinite(z.error) || !std::isfinite(t.error) || !precise_cross(x, y, w, eps))
    return kUndecided;
  const double v[3] = {z.y * t.z - z.z * t.y, z.z * t.x - z.x * t.z, z.x * t.y - z.y * t.x};
  const double ev = 1.01 * z.error + t.error + kUnitPredicateRounding;
  const double d = w[0] * v[0] + w[1] * v[1] + w[2] * v[2];
  const double size_w = std::abs(w[0]) + std::abs(w[1]) + std::abs(w[2]);
  const double size_v = std::abs(v[0]) + std::abs(v[1]) + std::abs(v[2]);
  const double products = std::abs(w[0] * v[0]) + std::abs(w[1] * v[1]) + std::abs(w[2] * v[2]);
  const double bound =
      (eps * size_v + (size_w + eps) * ev + 4 * 0x1p-52 * products) * 1.01 + 0x1p-1000;
  if (d > bound) return 1;
  if (d < -bound) return -1;
  return kUndecided;
}

}  // namespace

namespace {

/// orient_normals_precise's last stage: det in double-double on the three precise normals
/// (round-to-nearest: the caller's guard).
int orient_full_stage(const NormalRef& a, const NormalRef& b, const NormalRef& c) {
  const PreciseNormal& p = a.polytope->precise_normal(a.face);
  const PreciseNormal& q = b.polytope->precise_normal(b.face);
  const PreciseNormal& r = c.polytope->precise_normal(c.face);
  if (p.valid && q.valid && r.valid) {
    // Three normals with the same zero component lie in one plane.
    for (int i = 0; i < 3; ++i)
      if (p.exactly_zero(i) && q.exactly_zero(i) && r.exactly_zero(i)) return 0;
    auto dd = [](const PreciseNormal& n, int i) { return DD{n.hi[i], n.lo[i]}; };
    auto minor = [&](int i, int j) { return dd(q, i) * dd(r, j) - dd(q, j) * dd(r, i); };
    const DD value = dd(p, 0) * minor(1, 2) + dd(p, 1) * minor(2, 0) + dd(p, 2) * minor(0, 1);
    // The evaluation: three levels of operations on terms bounded by the permanent.
    double permanent = 0;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, l = (i + 2) % 3;
      permanent += std::abs(p.hi[i]) * (std::abs(q.hi[j] * r.hi[l]) + std::abs(q.hi[l] * r.hi[j]));
    }
    // The inputs: det moves by at most |da| |b| |c| + |a'| |db| |c| + |a'| |b'| |dc|, with
    // x' = x + dx.
    const double la = length_bound(p), lb = length_bound(q), lc = length_bound(r);
    const double da = error_bound(p), db = error_bound(q), dc = error_bound(r);
    const double bound = (da * lb * lc + (la + da) * db * lc + (la + da) * (lb + db) * dc +
                          64 * kU2 * permanent * 1.1) *
                             1.01 +
                         0x1p-1000;
    if (value.hi > bound) return 1;
    if (value.hi < -bound) return -1;
  }
  return kUndecided;
}

}  // namespace

int orient_normals_precise(const NormalRef& a, const NormalRef& b, const NormalRef& c) {
  // Double-double needs round-to-nearest, whatever the caller set.
  RoundingGuard nearest(CGAL_FE_TONEAREST);
  // A component within the unit normals' error bounds of zero in all three may be exactly
  // zero in all three (mirror-symmetric facets): then det is zero, shown cheaply for
  // triangles by component_surely_zero, else by the full stage.
  const UnitNormal &ua = a.unit(), &ub = b.unit(), &uc = c.unit();
  const double pa[3] = {ua.x, ua.y, ua.z}, pb[3] = {ub.x, ub.y, ub.z}, pc[3] = {uc.x, uc.y, uc.z};
  bool may_share_zero = false;
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs(pa[i]) <= ua.error && std::abs(pb[i]) <= ub.error &&
          std::abs(pc[i]) <= uc.error))
      continue;
    may_share_zero = true;
    if (component_surely_zero(*a.polytope, a.face, i) &&
        component_surely_zero(*b.polytope, b.face, i) &&
        component_surely_zero(*c.polytope, c.face, i))
      return 0;
  }
  // Otherwise what the double stage leaves undecided is mostly a nearly parallel pair (two
  // fine spheres) with a far third normal: first orient_near_pair, which needs only the
  // pair's precise normals (det(a, b, c) = c . (a x b) = a . (b x c) = b . (c x a), the pair
  // the one whose unit normals' dot product is largest in magnitude). It cannot show a zero,
  // so triples that may share a zero component go straight to the full stage.
  if (!may_share_zero) {
    auto dot = [](const UnitNormal& u, const UnitNormal& v) {
      return std::abs(u.x * v.x + u.y * v.y + u.z * v.z);
    };
    const double ab = dot(ua, ub), bc = dot(ub, uc), ca = dot(uc, ua);
    const int s = ab >= bc && ab >= ca ? orient_near_pair(a, b, uc)
                  : bc >= ca           ? orient_near_pair(b, c, ua)
                                       : orient_near_pair(c, a, ub);
    if (s != kUndecided) return s;
  }
  return orient_full_stage(a, b, c);
}

int orient_normals_precise_full(const NormalRef& a, const NormalRef& b, const NormalRef& c) {
  RoundingGuard nearest(CGAL_FE_TONEAREST);
  return orient_full_stage(a, b, c);
}

int cross_dot_normals_undecided(const NormalRef& a, const NormalRef& b, const NormalRef& c,
                                const NormalRef& d) {
  const int s = cross_dot_normals_precise(a, b, c, d);
  return s != kUndecided ? s : cross_dot_normals_exact(a, b, c, d);
}

int cross_dot_normals_exact(const NormalRef& a, const NormalRef& b, const NormalRef& c,
                            const NormalRef& d) {
  return CGAL::sign(cross_dot(a.exact(), b.exact(), c.exact(), d.exact()));
}

int cross_dot_normals_precise(const NormalRef& a, const NormalRef& b, const NormalRef& c,
                              const NormalRef& d) {
  {
    // As orient_normals_undecided: double-double on precise normals (nearly parallel
    // normals give values far below what doubles resolve), in round-to-nearest.
    RoundingGuard nearest(CGAL_FE_TONEAREST);
    // First as orient_normals_precise, from the nearly parallel pair's precise normals only
    // (a x b or c x d, whichever pair's unit normals have the larger |dot|; the value is
    // symmetric in the two cross products).
    {
      const UnitNormal &ua = a.unit(), &ub = b.unit(), &uc = c.unit(), &ud = d.unit();
      const double ab = std::abs(ua.x * ub.x + ua.y * ub.y + ua.z * ub.z);
      const double cd = std::abs(uc.x * ud.x + uc.y * ud.y + uc.z * ud.z);
      const int s =
          ab >= cd ? cross_dot_near_pair(a, b, uc, ud) : cross_dot_near_pair(c, d, ua, ub);
      if (s != kUndecided) return s;
    }
    const PreciseNormal& p = a.polytope->precise_normal(a.face);
    const PreciseNormal& q = b.polytope->precise_normal(b.face);
    const PreciseNormal& r = c.polytope->precise_normal(c.face);
    const PreciseNormal& s = d.polytope->precise_normal(d.face);
    if (p.valid && q.valid && r.valid && s.valid) {
      auto dd = [](const PreciseNormal& n, int i) { return DD{n.hi[i], n.lo[i]}; };
      auto dot_dd = [&](const PreciseNormal& u, const PreciseNormal& v) {
        return dd(u, 0) * dd(v, 0) + dd(u, 1) * dd(v, 1) + dd(u, 2) * dd(v, 2);
      };
      auto dot_abs = [](const PreciseNormal& u, const PreciseNormal& v) {
        return std::abs(u.hi[0] * v.hi[0]) + std::abs(u.hi[1] * v.hi[1]) +
               std::abs(u.hi[2] * v.hi[2]);
      };
      const DD value = dot_dd(p, r) * dot_dd(q, s) - dot_dd(p, s) * dot_dd(q, r);
      // The evaluation: three levels of operations on terms bounded by the permanent
      // (each dot errs by 12 u^2 of its magnitude, each product of dots by 28, the
      // difference by 4 more: 32, doubled as in orient).
      const double permanent = dot_abs(p, r) * dot_abs(q, s) + dot_abs(p, s) * dot_abs(q, r);
      // The inputs: the value is multilinear, each of its two terms at most the product
      // of the four lengths, so replacing x by x' = x + dx moves it by at most
      // 2 |dx| times the other three lengths (each bound both exact and approximate).
      const double lp = length_bound(p), lq = length_bound(q), lr = length_bound(r),
                   ls = length_bound(s);
      const double dp = error_bound(p), dq = error_bound(q), dr = error_bound(r),
                   ds = error_bound(s);
      const double bound =
          (2 * (dp * lq * lr * ls + lp * dq * lr * ls + lp * lq * dr * ls + lp * lq * lr * ds) +
           64 * kU2 * permanent * 1.1) *
              1.01 +
          0x1p-1000;
      if (value.hi > bound) return 1;
      if (value.hi < -bound) return -1;
    }
  }
  return kUndecided;
}

namespace {

std::uint64_t key(int u, int w) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(u)) << 32) |
         static_cast<std::uint32_t>(w);
}

[[noreturn]] void fail(const char* name, const std::string& what) {
  throw not_convex(std::string(name) + ": " + what);
}

/// Fills faces, edges and fans of `p` from facet cycles (vertex indices into p.points).
/// The cycles must describe a closed, oriented 2-manifold.
void build_connectivity(Polytope& p, const std::vector<std::vector<int>>& faces, const char* name) {
  p.face_begin.assign(1, 0);
  p.corner_vertex.clear();
  for (const auto& cyc : faces) {
    p.corner_vertex.insert(p.corner_vertex.end(), cyc.begin(), cyc.end());
    p.face_begin.push_back(static_cast<int>(p.corner_vertex.size()));
  }
  const int nc = static_cast<int>(p.corner_vertex.size());
  const int nv = p.num_vertices();
  std::vector<int> corner_face(nc);
  for (int f = 0; f < p.num_faces(); ++f)
    std::fill(corner_face.begin() + p.face_begin[f], corner_face.begin() + p.face_begin[f + 1], f);
  // Each vertex's outgoing corners, as (the edge's end, corner), sorted by the end: a
  // directed edge is found by a search in its start's short list (a hash map of all the
  // edges took 15% of a closing of a UV sphere of 320 x 320 facets, its random probes
  // missing the cache).
  std::vector<int> out_begin(nv + 1, 0);
  for (int c = 0; c < nc; ++c) ++out_begin[p.corner_vertex[c] + 1];
  for (int v = 0; v < nv; ++v) out_begin[v + 1] += out_begin[v];
  std::vector<std::pair<int, int>> out(nc);
  {
    std::vector<int> cursor(out_begin.begin(), out_begin.end() - 1);
    for (int f = 0; f < p.num_faces(); ++f)
      for (int k = 0; k < p.degree(f); ++k) {
        const int c = p.face_begin[f] + k;
        out[cursor[p.corner_vertex[c]]++] = {p.corner(f, (k + 1) % p.degree(f)), c};
      }
  }
  for (int v = 0; v < nv; ++v) {
    const auto first = out.begin() + out_begin[v], last = out.begin() + out_begin[v + 1];
    std::sort(first, last);
    const auto twice = std::adjacent_find(
        first, last, [](const auto& x, const auto& y) { return x.first == y.first; });
    if (twice != last)
      fail(name, "edge " + std::to_string(v) + "-" + std::to_string(twice->first) +
                     " is used twice in one direction");
  }
  // The corner where directed edge u -> w starts, or -1.
  const auto corner_of = [&](int u, int w) {
    const auto first = out.begin() + out_begin[u], last = out.begin() + out_begin[u + 1];
    const auto it = std::lower_bound(first, last, std::pair<int, int>{w, -1});
    return it != last && it->first == w ? it->second : -1;
  };
  auto next_corner = [&](int c) {
    const int f = corner_face[c];
    return c + 1 == p.face_begin[f + 1] ? p.face_begin[f] : c + 1;
  };
  auto prev_corner = [&](int c) {
    const int f = corner_face[c];
    return c == p.face_begin[f] ? p.face_begin[f + 1] - 1 : c - 1;
  };
  p.corner_edge.assign(nc, -1);
  p.edges.clear();
  for (int c = 0; c < nc; ++c) {
    if (p.corner_edge[c] >= 0) continue;
    const int u = p.corner_vertex[c], w = p.corner_vertex[next_corner(c)];
    const int twin = corner_of(w, u);
    if (twin < 0)
      fail(name, "edge " + std::to_string(u) + "-" + std::to_string(w) + " has only one facet");
    const int e = static_cast<int>(p.edges.size());
    p.edges.push_back({u, w, corner_face[c], corner_face[twin]});
    p.corner_edge[c] = e;
    p.corner_edge[twin] = e;
  }
  // Fans: from facet f at v, the next facet counter-clockwise is the one across f's
  // incoming edge u -> v, i.e. the facet holding v -> u.
  std::vector<int> some_corner(nv, -1);
  for (int c = 0; c < nc; ++c) some_corner[p.corner_vertex[c]] = c;
  p.fan_begin.assign(nv + 1, 0);
  p.fan_face.clear();
  p.fan_edge.clear();
  p.fan_vertex.clear();
  for (int v = 0; v < nv; ++v) {
    p.fan_begin[v] = static_cast<int>(p.fan_face.size());
    const int start = some_corner[v];
    if (start < 0) continue;
    int c = start;
    int guard = 0;
    do {
      const int u = p.corner_vertex[prev_corner(c)];
      p.fan_face.push_back(corner_face[c]);
      p.fan_edge.push_back(p.corner_edge[prev_corner(c)]);
      p.fan_vertex.push_back(u);
      c = corner_of(v, u);  // (there: u -> v has a twin)
      if (++guard > nc) fail(name, "vertex " + std::to_string(v) + " has a broken fan");
    } while (c != start);
  }
  p.fan_begin[nv] = static_cast<int>(p.fan_face.size());
  // A vertex whose facets form several fans is not manifold.
  std::vector<int> count(nv, 0);
  for (int c = 0; c < nc; ++c) ++count[p.corner_vertex[c]];
  for (int v = 0; v < nv; ++v)
    if (count[v] != p.fan_begin[v + 1] - p.fan_begin[v])
      fail(name, "vertex " + std::to_string(v) + " is not manifold");
}

// Relative error bound of Shewchuk's orient3d evaluated in double, (7 + 56 eps) eps, with
// eps = 2^-52 (one ulp per operation) so that it holds in any rounding mode: is_canonical
// runs under a RoundingGuard, which rounds upward.
constexpr double kOrient3dErrorBound = (7.0 + 56.0 * 0x1p-52) * 0x1p-52;
// Below this permanent, products may underflow and the relative bound no longer holds.
constexpr double kOrient3dMinPermanent = 1e-280;

/// The vertex of triangle f other than u and w.
int third_vertex(const Polytope& p, int f, int u, int w) {
  const int* c = &p.corner_vertex[p.face_begin[f]];
  return c[0] != u && c[0] != w ? c[0] : c[1] != u && c[1] != w ? c[1] : c[2];
}

/// edge_convexity() between two triangles of double points, decided in double when a
/// static bound allows, else 2. With d = to - from and the far vertices a (of left) and b
/// (of right), N_left = d x (a - from) and N_right = (b - from) x d, so that
/// det(N_left, N_right, d) = -|d|^2 det(d, a - from, b - from): one orientation.
int triangle_edge_convexity(const Polytope& p, const Polytope::Edge& e) {
  const V3<double>& o = p.points[e.from];
  const V3<double> d = p.points[e.to] - o;
  const V3<double> a = p.points[third_vertex(p, e.left, e.from, e.to)] - o;
  const V3<double> b = p.points[third_vertex(p, e.right, e.from, e.to)] - o;
  const double ab_x = a.y * b.z - a.z * b.y, ab_y = a.z * b.x - a.x * b.z,
               ab_z = a.x * b.y - a.y * b.x;
  const double orientation = d.x * ab_x + d.y * ab_y + d.z * ab_z;
  using std::abs;
  const double permanent = abs(d.x) * (abs(a.y * b.z) + abs(a.z * b.y)) +
                           abs(d.y) * (abs(a.z * b.x) + abs(a.x * b.z)) +
                           abs(d.z) * (abs(a.x * b.y) + abs(a.y * b.x));
  if (!(permanent >= kOrient3dMinPermanent)) return 2;  // also NaN
  const double bound = kOrient3dErrorBound * permanent;
  if (orientation > bound) return -1;
  if (orientation < -bound) return 1;
  return 2;
}

/// edge_convexity() decided on the unit normals when their error bounds allow, else 2.
/// With unit normals a', b' within e_a, e_b of the exact ones' directions a, b (|a|, |b| =
/// 1) and d' within r of d = to - from: |det(a', b', d') - det(a, b, d)| <= (e_a + e_b)
/// |d'| + r, and the evaluation adds at most kUnitPredicateRounding |d'| (the unit bound,
/// scaled); any rounding mode.
inline int unit_edge_convexity(const Polytope& p, const Polytope::Edge& e) {
  const UnitNormal &a = p.unit_normals[e.left], &b = p.unit_normals[e.right];
  V3<double> d;
  double radius;
  if (p.exact_points.empty()) {
    d = p.points[e.to] - p.points[e.from];  // each component within an ulp
    radius = (std::abs(d.x) + std::abs(d.y) + std::abs(d.z)) * 0x1p-52 * 1.01;
  } else {
    RoundingGuard guard;  // enclosures of the difference
    const V3<Interval> di = p.interval_point(e.to) - p.interval_point(e.from);
    d = {0.5 * (di.x.inf() + di.x.sup()), 0.5 * (di.y.inf() + di.y.sup()),
         0.5 * (di.z.inf() + di.z.sup())};
    radius =
        ((di.x.sup() - di.x.inf()) + (di.y.sup() - di.y.inf()) + (di.z.sup() - di.z.inf())) * 1.01;
  }
  const double length = std::abs(d.x) + std::abs(d.y) + std::abs(d.z);  // >= |d'|
  // Products must not underflow (the bound is relative), nor |d'| overflow.
  if (!(length > 1e-250 && length < 1e250)) return 2;
  const double value =
      d.x * (a.y * b.z - a.z * b.y) + d.y * (a.z * b.x - a.x * b.z) + d.z * (a.x * b.y - a.y * b.x);
  const double bound = ((a.error + b.error + kUnitPredicateRounding) * length + radius) * 1.01;
  if (value > bound) return 1;
  if (value < -bound) return -1;
  return 2;
}

/// Sign of det(N_left, N_right, to - from): positive when the edge is strictly convex.
int edge_convexity(const Polytope& p, const Polytope::Edge& e) {
  // The unit normals decide all but nearly flat edges, reading less than the triangles.
  if (const int s = unit_edge_convexity(p, e); s != 2) return s;
  if (p.exact_points.empty() && p.degree(e.left) == 3 && p.degree(e.right) == 3) {
    if (const int s = triangle_edge_convexity(p, e); s != 2) return s;
  }
  if (p.exact_points.empty())
    return CGAL::sign(det(p.exact_normal(e.left), p.exact_normal(e.right),
                          to_exact_n(p.points[e.to]) - to_exact_n(p.points[e.from])));
  // X_to / W_to - X_from / W_from has the direction of X_to W_from - X_from W_to (W > 0):
  // dyadic, no rationals.
  const ExactPoints& x = p.exact_points;
  const ExactN &w_to = x.W(e.to), &w_from = x.W(e.from);
  const V3<ExactN>&a = x.X(e.to), &b = x.X(e.from);
  const V3<ExactN> direction{a.x * w_from - b.x * w_to, a.y * w_from - b.y * w_to,
                             a.z * w_from - b.z * w_to};
  return CGAL::sign(det(p.exact_normal(e.left), p.exact_normal(e.right), direction));
}

/// The Gauss map must be valid: the normals around every vertex turn strictly
/// counter-clockwise (a convex spherical polygon). `edges_convex`: every edge is known to be
/// strictly convex and every normal is Newell's of the double points; then a turn through
/// three triangles holds already and is not evaluated. With d_i = u_i - v for consecutive
/// triangles (v, u0, u1), (v, u1, u2), (v, u2, u3) of v's fan, their normals are d0 x d1,
/// d1 x d2, d2 x d3 and det(N_a, N_b, N_c) = det(d0, d1, d2) det(d1, d2, d3) exactly, where
/// det(d0, d1, d2) is -det(N_left, N_right, to - from) / |d1|^2 for the edge v-u1 (the same
/// for v-u2): two negative factors.
void check_gauss_map(const Polytope& p, const char* name, bool edges_convex = false) {
  // orient_normals works in any rounding mode: no RoundingGuard.
  const UnitNormal* unit = p.unit_normals.data();
  const int* face_begin = p.face_begin.data();
  const auto triangle = [&](int f) { return face_begin[f + 1] - face_begin[f] == 3; };
  // Only triangles: no turn left to evaluate, only the fan sizes.
  const bool all_proven =
      edges_convex && static_cast<long long>(p.corner_vertex.size()) == 3LL * p.num_faces();
  for (int v = 0; v < p.num_vertices(); ++v) {
    const int b = p.fan_begin[v], n = p.fan_begin[v + 1] - b;
    if (n < 3)
      fail(name, "vertex " + std::to_string(p.vertex_source[v]) + " has fewer than three facets");
    if (all_proven) continue;
    const int* fan = &p.fan_face[b];
    // Triple i is (fan[i], fan[i + 1], fan[i + 2]) cyclically: each step reads one new normal.
    const UnitNormal *px = &unit[fan[0]], *py = &unit[fan[1]];
    for (int i = 0; i < n; ++i) {
      const int k = i + 2 < n ? i + 2 : i + 2 - n;
      const UnitNormal* pz = &unit[fan[k]];
      // orient_normals' double filter, on the unit normals read straight from the array
      // (the same expression and bound); its later stages decide what it leaves.
      const UnitNormal &x = *px, &y = *py, &z = *pz;
      px = py;
      py = pz;
      if (edges_convex && triangle(fan[i]) && triangle(fan[i + 1 < n ? i + 1 : 0]) &&
          triangle(fan[k]))
        continue;
      const double d = x.x * (y.y * z.z - y.z * z.y) + x.y * (y.z * z.x - y.x * z.z) +
                       x.z * (y.x * z.y - y.y * z.x);
      const double bound = x.error + y.error + z.error + kUnitPredicateRounding;
      if (d > bound) continue;
      const int s = d < -bound ? -1
                               : orient_normals_undecided(NormalRef{&p, fan[i]},
                                                          NormalRef{&p, fan[i + 1 < n ? i + 1 : 0]},
                                                          NormalRef{&p, fan[k]});
      if (s <= 0)
        fail(name, "the facets around vertex " + std::to_string(p.vertex_source[v]) +
                       " do not turn convexly (the mesh is not convex)");
    }
  }
}

void check_edges_convex(const Polytope& p, const char* name) {
  RoundingGuard guard;
  for (const auto& e : p.edges)
    if (edge_convexity(p, e) <= 0)
      fail(name, "edge " + std::to_string(p.vertex_source[e.from]) + "-" +
                     std::to_string(p.vertex_source[e.to]) + " is not convex");
}

/// Whether every vertex has at least three facets.
bool fans_at_least_three(const Polytope& p) {
  for (int v = 0; v < p.num_vertices(); ++v)
    if (p.fan_begin[v + 1] - p.fan_begin[v] < 3) return false;
  return true;
}

/// Whether every edge is strictly convex and every vertex has at least three facets:
/// then the polytope is canonical as it is (nothing to merge or remove). `edges_convex`: every
/// edge is known to be strictly convex (make_operand's check proved it, see geometry_passes).
bool is_canonical(const Polytope& p, bool edges_convex = false) {
  if (!fans_at_least_three(p)) return false;
  if (edges_convex) return true;
  RoundingGuard guard;
  for (const auto& e : p.edges) {
    // edge_convexity's first stage here, so that only what it leaves costs a call.
    const int s = unit_edge_convexity(p, e);
    if (s < 0 || (s == 2 && edge_convexity(p, e) <= 0)) return false;
  }
  return true;
}

/// edges_and_turns_pass() of one quadrilateral y (corners p0..p3, a_k across its edge from p_k
/// to p_(k+1)), two corners in the lanes of each Pair: the same tests with the same bounds (each
/// lane does one corner's operations, in any rounding mode). The turns at all four corners; the
/// edges of corners 0 and 1, and those of corners 2 and 3 only with `last_edges`.
inline bool quad_edges_and_turns_pass(const UnitNormal& y, const UnitNormal& a0,
                                      const UnitNormal& a1, const UnitNormal& a2,
                                      const UnitNormal& a3, const V3<double>& p0,
                                      const V3<double>& p1, const V3<double>& p2,
                                      const V3<double>& p3, bool last_edges) {
  const Pair yx{y.x, y.x}, yy{y.y, y.y}, yz{y.z, y.z}, ye{y.error, y.error};
  // Corners 0, 1 in one pair, 2, 3 in the other.
  const Pair ax{a0.x, a1.x}, ay{a0.y, a1.y}, az{a0.z, a1.z}, ae{a0.error, a1.error};
  const Pair bx{a2.x, a3.x}, by{a2.y, a3.y}, bz{a2.z, a3.z}, be{a2.error, a3.error};
  // c_k = N_y x N_a_k.
  const Pair cx = yy * az - yz * ay, cy = yz * ax - yx * az, cz = yx * ay - yy * ax;
  const Pair dx = yy * bz - yz * by, dy = yz * bx - yx * bz, dz = yx * by - yy * bx;
  // The turns at corners 0, 1 read c_3, c_0; at corners 2, 3, c_1, c_2.
  const Pair k = {kUnitPredicateRounding, kUnitPredicateRounding};
  const Pair turn_a =
      ax * pair_high_low(dx, cx) + ay * pair_high_low(dy, cy) + az * pair_high_low(dz, cz);
  const Pair turn_b =
      bx * pair_high_low(cx, dx) + by * pair_high_low(cy, dy) + bz * pair_high_low(cz, dz);
  PairMask ok = (turn_a > ae + ye + pair_high_low(be, ae) + k) &
                (turn_b > be + ye + pair_high_low(ae, be) + k);
  // The edges p0-p1, p1-p2 (and p2-p3, p3-p0), with unit_edge_convexity's bound.
  const auto edges_pass = [&](const V3<double>& q0, const V3<double>& q1, const V3<double>& q2,
                              Pair nx, Pair ny, Pair nz, Pair error) {
    const Pair ux = Pair{q1.x, q2.x} - Pair{q0.x, q1.x}, uy = Pair{q1.y, q2.y} - Pair{q0.y, q1.y},
               uz = Pair{q1.z, q2.z} - Pair{q0.z, q1.z};
    const Pair length = pair_abs(ux) + pair_abs(uy) + pair_abs(uz);
    const Pair ulp = {0x1p-52 * 1.01, 0x1p-52 * 1.01}, margin = {1.01, 1.01};
    const Pair tiny = {1e-250, 1e-250}, huge = {1e250, 1e250};
    return (length > tiny) & (length < huge) &
           (ux * nx + uy * ny + uz * nz > ((ye + error + k) * length + length * ulp) * margin);
  };
  ok &= edges_pass(p0, p1, p2, cx, cy, cz, ae);
  if (last_edges) ok &= edges_pass(p2, p3, p0, dx, dy, dz, be);
  return both_true(ok);
}

/// is_canonical's edge test and check_gauss_map's turns at once, walking the facets, on the
/// double filters alone: true when every edge of p (double points, unit normals computed) is
/// shown strictly convex by unit_edge_convexity's filter and every turn of the Gauss map shown
/// positive by orient_normals' filter; false when any is not shown (the caller then runs the two
/// checks themselves, which decide it and name what fails). With the facet y, the facet a_k
/// across its edge from corner k to corner k + 1, and c_k = N_y x N_a_k (one cross product per
/// corner, shared by the two tests):
///  - the edge: det(N_y, N_a_k, p_(k+1) - p_k) = d_k . c_k, the same determinant whichever facet
///    holds the edge from -> to (from the other side both the normals and the direction swap),
///    with unit_edge_convexity's bound; each edge is tested from its facet of smaller index at
///    least (a quadrilateral skips two of the others, other facets test all theirs);
///  - the turn at corner k (vertex v): in v's fan, the facet before y is the one across y's edge
///    leaving v (a_k), the one after it across the edge entering v (a_(k-1)), so the turn is
///    det(a_k, y, a_(k-1)) = a_k . c_(k-1), with orient_normals' bound; every corner is the
///    middle of one turn, so this covers every turn.
/// Both bounds hold in any rounding mode.
/// `across_ending`, when given: the facet across the edge that ends at each corner
/// (OperandTopology's), read instead of the edges.
bool edges_and_turns_pass(const Polytope& p, const int* across_ending = nullptr) {
  const UnitNormal* const unit = p.unit_normals.data();
  const V3<double>* const points = p.points.data();
  const int* const face_begin = p.face_begin.data();
  const int* const corner_vertex = p.corner_vertex.data();
  const int* const corner_edge = p.corner_edge.data();
  const Polytope::Edge* const edges = p.edges.data();
  bool pass = true;
  for (int f = 0, nf = p.num_faces(); f < nf; ++f) {
    const int b = face_begin[f], n = face_begin[f + 1] - b;
    const UnitNormal y = unit[f];
    // The facet across the edge from corner c to the next: the one across the edge that ends
    // at the next corner.
    const auto across = [&](int c) {
      if (across_ending) return across_ending[c + 1 < b + n ? c + 1 : b];
      const Polytope::Edge& e = edges[corner_edge[c]];
      return e.left ^ e.right ^ f;
    };
    if (n == 4) {
      const int a[4] = {across(b), across(b + 1), across(b + 2), across(b + 3)};
      // Each edge is tested from its facet of smaller index at least (both sides give the same
      // determinant): when those this facet tests are two corners that follow each other, they
      // are put first and the other two corners' edges are not tested.
      const unsigned own =
          static_cast<unsigned>(f <= a[0]) | (f <= a[1]) << 1 | (f <= a[2]) << 2 | (f <= a[3]) << 3;
      const int r = (own & 0b1100) == 0 ? 0 : (own & 0b1001) == 0 ? 1 : (own & 0b0011) == 0 ? 2 : 3;
      const bool last_edges = r == 3 && (own & 0b0110) != 0;
      pass &= quad_edges_and_turns_pass(y, unit[a[r]], unit[a[(r + 1) & 3]], unit[a[(r + 2) & 3]],
                                        unit[a[(r + 3) & 3]], points[corner_vertex[b + r]],
                                        points[corner_vertex[b + ((r + 1) & 3)]],
                                        points[corner_vertex[b + ((r + 2) & 3)]],
                                        points[corner_vertex[b + ((r + 3) & 3)]], last_edges);
      continue;
    }
    // c_(k-1) and its facet's error, from the last corner's edge.
    const UnitNormal& last = unit[across(b + n - 1)];
    double cx = y.y * last.z - y.z * last.y, cy = y.z * last.x - y.x * last.z,
           cz = y.x * last.y - y.y * last.x, previous_error = last.error;
    V3<double> from = points[corner_vertex[b]];
    for (int k = 0; k < n; ++k) {
      const UnitNormal& a = unit[across(b + k)];
      const double turn = a.x * cx + a.y * cy + a.z * cz;
      pass &= turn > a.error + y.error + previous_error + kUnitPredicateRounding;
      cx = y.y * a.z - y.z * a.y;
      cy = y.z * a.x - y.x * a.z;
      cz = y.x * a.y - y.y * a.x;
      previous_error = a.error;
      const V3<double> to = points[corner_vertex[k + 1 < n ? b + k + 1 : b]];
      const V3<double> d = to - from;
      from = to;
      const double length = std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
      const double radius = length * 0x1p-52 * 1.01;
      const double value = d.x * cx + d.y * cy + d.z * cz;
      pass &= length > 1e-250 && length < 1e250 &&
              value > ((y.error + a.error + kUnitPredicateRounding) * length + radius) * 1.01;
    }
  }
  return pass;
}

/// The rest of check_operand's topological checks on a mesh whose halfedges
/// connectivity_from_halfedges found consistent (every vertex one fan reaching each
/// neighbour once): every vertex's halfedge leaves it (where the check's fan walk starts),
/// the vertices are connected, and V - E + F = 2. `descending`: every vertex but vertex 0 has a
/// neighbour of smaller index (the fan walk found it), which proves them connected: steps to
/// smaller neighbours from any vertex end at one without any, vertex 0. The usual numberings
/// (a subdivision's, a grid's) have it; otherwise a search decides.
bool operand_topology(const Polytope& p, const HalfedgeArrays& arrays, int nf, bool descending) {
  const int nv = p.num_vertices();
  const int nh = static_cast<int>(p.corner_vertex.size());
  for (int v = 0; v < nv; ++v) {
    const int h = arrays.halfedge_of_vertex(v);
    if (h < 0 || h >= nh || arrays.to(h ^ 1) != v) return false;
  }
  const bool euler = static_cast<long long>(nv) - nh / 2 + nf == 2;
  // The search's branch on each neighbour mispredicts often: skipped when connectivity is proven.
  if (descending) return euler;
  // A search through the fans from vertex 0, as the check's. Each vertex is pushed at most
  // once: the stack needs nv slots (written before read, left uninitialised).
  std::vector<char> reached(nv, 0);
  std::unique_ptr<int[]> stack(new int[nv > 0 ? nv : 1]);
  const int* const fan_begin = p.fan_begin.data();
  const int* const fan_vertex = p.fan_vertex.data();
  int top = 0, count = 0;
  if (nv > 0) {
    reached[0] = 1;
    stack[top++] = 0;
  }
  while (top > 0) {
    const int v = stack[--top];
    ++count;
    for (int s = fan_begin[v], end = fan_begin[v + 1]; s < end; ++s) {
      const int w = fan_vertex[s];
      if (reached[w]) continue;
      reached[w] = 1;
      stack[top++] = w;
    }
  }
  return count == nv && euler;
}

/// What make_operand's checked path (checked_polytope) reads off the halfedges beside the
/// polytope's connectivity: the face across the edge that ends at each corner (check_operand's
/// face cycles, see FaceCycleView), and whether the mesh passes check_operand's topological
/// checks.
struct OperandTopology {
  std::unique_ptr<int[]> across;  // one per corner, all written by a walk that passes
  bool passes = false;
};

/// Faces, edges and fans of `p` straight from the halfedges of `mesh` (closed, manifold,
/// no deleted elements), each facet reversed if `order` says so. The numbering is the one
/// build_connectivity gives the mesh's face cycles: facets in face order, corners from the
/// face circulator's first vertex, edges in order of first use. Returns the mesh edge of
/// each polytope edge. With `topology` (as given only), also tells whether check_operand's
/// topological checks pass, from what the walks read anyway (see checked_polytope).
/// In three instances (as given with and without `topology`, reversed without), so that each
/// walk's loop tests neither the order nor `topology` and keeps more of its values in registers.
template <bool reversed, bool checked>
std::vector<int> connectivity_walks(Polytope& p, const Mesh& mesh, OperandTopology* topology) {
  static_assert(!(reversed && checked), "the checked path reads the faces as given");
  const int nv = static_cast<int>(mesh.n_vertices());
  const int nf = static_cast<int>(mesh.n_faces());
  const int nh = static_cast<int>(mesh.n_halfedges());
  // Corner c is a halfedge of its face: leaving the corner's vertex when as given; when
  // reversed, entering it (the facet runs against the halfedges). What the walks know of
  // mesh edge h / 2 (OpenMesh stores the two halfedges of edge e as 2e and 2e + 1), in its
  // two low bits: bit h & 1 set once the corner of halfedge h has met it; above them, the
  // polytope edge once it has one (below 2^30: at most nh / 2).
  std::vector<unsigned> edge_state(nh / 2, 0);
  p.face_begin.resize(nf + 1);
  p.corner_vertex.resize(nh);
  p.corner_edge.resize(nh);
  // Each edge has two corners once every halfedge is one face's: at most nh / 2 edges,
  // written by index in order of first use (at the smaller corner).
  std::vector<int> mesh_edge(nh / 2);
  int* const mesh_edge_of = mesh_edge.data();
  p.edges.resize(nh / 2);
  int* const corner_vertex = p.corner_vertex.data();
  int* const corner_edge = p.corner_edge.data();
  Polytope::Edge* const edges = p.edges.data();
  // Where the fan of each vertex starts: at its last corner, as the halfedge its fan slot reads
  // (see the fan walk below).
  std::vector<int> some_slot(nv, -1);
  const HalfedgeArrays arrays(mesh);
  // The checked path's findings: whether every halfedge's opposite ends at the corner's vertex
  // (the check reads it), and `across`.
  bool consistent = true;
  int* across = nullptr;
  if constexpr (checked) {
    topology->passes = false;
    topology->across = std::make_unique_for_overwrite<int[]>(nh);
    across = topology->across.get();
  }
  // One walk around each face: its corners, and each edge as its first corner meets it
  // (the edge's from, left facet and mesh edge) and completed at its second (to, right
  // facet). The walk follows next links (prev when reversed); each halfedge must name the
  // face and link back to the one before (the fan walk follows the other links and the faces
  // of halfedges).
  int c = 0, e = 0;
  for (int f = 0; f < nf; ++f) {
    const int begin = c;
    p.face_begin[f] = begin;
    const int h0 = arrays.halfedge_of_face(f);
    // The face circulator starts at the target of h0. As given, a corner's vertex is the
    // target of the halfedge before it (read with the link to the next one).
    const int start = reversed ? arrays.prev(h0) : arrays.next(h0);
    int from = arrays.to(h0);
    int previous = h0;  // the halfedge walked before h (as given: it ends at the corner)
    int h = start;
    do {
      // Each halfedge once (its bit not set): with the count below, every halfedge is some
      // face's. Each corner sets its halfedge's bit, so at most nh corners are written (c < nh
      // while some halfedge is unwalked).
      unsigned& state = edge_state[h >> 1];
      const unsigned bit = 1u << (h & 1);
      if ((state & bit) != 0 || arrays.face(h) != f ||
          (reversed ? arrays.next(h) : arrays.prev(h)) != previous)
        throw error("internal error: a mesh face is not a closed cycle");
      const int vertex = reversed ? arrays.to(h) : from;
      corner_vertex[c] = vertex;
      some_slot[vertex] = previous;
      int edge;
      if (state == 0) {  // the edge's first corner
        edge = e++;
        state = (static_cast<unsigned>(edge) << 2) | bit;
        edges[edge].from = vertex;
        edges[edge].left = f;
        mesh_edge_of[edge] = h >> 1;
      } else {
        edge = static_cast<int>(state >> 2);
        state |= bit;
        edges[edge].to = vertex;
        edges[edge].right = f;
      }
      corner_edge[c] = edge;
      if constexpr (checked) {
        across[c] = arrays.face(previous ^ 1);
        consistent &= arrays.to(h ^ 1) == from;
      }
      previous = h;
      ++c;
      if (!reversed) from = arrays.to(h);
      h = reversed ? arrays.prev(h) : arrays.next(h);
    } while (h != start);
  }
  p.face_begin[nf] = c;
  if (c != nh) throw error("internal error: a mesh halfedge has no face");
  // Every halfedge has been walked once, so each edge's two corners have both been met: e is
  // nh / 2, and every edge state holds its polytope edge.
  const int nc = c;
  p.fan_begin.resize(nv + 1);
  p.fan_face.resize(nc);
  p.fan_edge.resize(nc);
  p.fan_vertex.resize(nc);
  int* const fan_face = p.fan_face.data();
  int* const fan_edge = p.fan_edge.data();
  int* const fan_vertex = p.fan_vertex.data();
  int slot = 0;
  // The checked path: the vertex whose fan last reached each vertex (a neighbour reached
  // twice means two edges between the same vertices).
  std::vector<int> seen(checked ? nv : 0, -1);
  // The checked path: whether every vertex but vertex 0 has a smaller neighbour (see
  // operand_topology).
  bool descending = true;
  // The fans as build_connectivity walks them (from facet f at v, the next facet is the one
  // across f's incoming edge u -> v), read straight off the halfedges: the slot of a corner at
  // v is, as given, the halfedge g = u -> v of its face (the face, u = to(g ^ 1), the edge),
  // the next slot prev(g ^ 1); reversed, the halfedge o = v -> u of its face (u = to(o)), the
  // next slot next(o ^ 1). Each step reads one mesh edge's record and its state.
  for (int v = 0; v < nv; ++v) {
    p.fan_begin[v] = slot;
    const int first = some_slot[v];
    if (first < 0) {
      consistent = false;  // isolated
      continue;
    }
    int g = first;
    int smallest = v;  // the smallest of v and its neighbours
    do {
      if (slot == nc) throw error("internal error: a mesh vertex has a broken fan");
      fan_face[slot] = arrays.face(g);
      fan_edge[slot] = static_cast<int>(edge_state[g >> 1] >> 2);
      const int w = reversed ? arrays.to(g) : arrays.to(g ^ 1);
      fan_vertex[slot] = w;
      if constexpr (checked) {
        consistent &= seen[w] != v;
        seen[w] = v;
        smallest = std::min(smallest, w);
      }
      ++slot;
      g = reversed ? arrays.next(g ^ 1) : arrays.prev(g ^ 1);
    } while (g != first);
    descending &= (smallest < v) | (v == 0);
  }
  p.fan_begin[nv] = slot;
  if (slot != nc) throw error("internal error: a mesh vertex has several fans");
  if (checked && consistent) topology->passes = operand_topology(p, arrays, nf, descending);
  return mesh_edge;
}

std::vector<int> connectivity_from_halfedges(Polytope& p, const Mesh& mesh, FaceOrder order,
                                             OperandTopology* topology = nullptr) {
  if (order == FaceOrder::reversed) return connectivity_walks<true, false>(p, mesh, nullptr);
  if (topology) return connectivity_walks<false, true>(p, mesh, topology);
  return connectivity_walks<false, false>(p, mesh, nullptr);
}

// Whether any of these status flags marks its element deleted: the flags or-ed together, a loop
// without exits that the compiler vectorises (almost every mesh has none deleted, so any_of's
// early exit would not pay for its branch per element).
template <class Statuses>
bool any_status_deleted(const Statuses& status) {
  unsigned bits = 0;
  for (const auto& s : status) bits |= s.bits();
  return (bits & OpenMesh::Attributes::DELETED) != 0;
}

// Whether any vertex, edge or face is marked deleted (read straight from the status
// arrays: OpenMesh's status() looks the property up on every call).
bool has_deleted_elements(const Mesh& mesh) {
  const auto any_deleted = [&](const auto& status_handle) {
    return any_status_deleted(mesh.property(status_handle).data_vector());
  };
  return (mesh.has_vertex_status() && any_deleted(mesh.vertex_status_pph())) ||
         (mesh.has_edge_status() && any_deleted(mesh.edge_status_pph())) ||
         (mesh.has_face_status() && any_deleted(mesh.face_status_pph()));
}

// Whether make_polytope may read `mesh` before it is validated: every coordinate is finite
// (exact arithmetic needs finite values). Holds for every mesh that passes the check. An open
// mesh needs no test: connectivity_from_halfedges counts the corners of the face cycles
// (each halfedge is in at most one) and throws unless they cover every halfedge, before it
// follows any link between faces; the cycle path throws on an edge with one facet.
bool readable(const Mesh& mesh) {
  const Point* q = mesh.points();
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v)
    if (!std::isfinite(q[v][0]) || !std::isfinite(q[v][1]) || !std::isfinite(q[v][2])) return false;
  return true;
}

}  // namespace

namespace {

/// Facet f's normal of `normals[source[f]]`, for each f.
GivenNormals remapped(const std::vector<V3<ExactN>>& normals, const std::vector<int>& source) {
  std::vector<V3<ExactN>> out(source.size());
  for (std::size_t f = 0; f < source.size(); ++f) out[f] = normals[source[f]];
  return GivenNormals(std::move(out));
}

}  // namespace

Polytope make_polytope(std::vector<V3<double>> points, ExactPoints exact_points,
                       const std::vector<std::vector<int>>& input_faces,
                       std::vector<V3<ExactN>> given_normals, const char* name) {
  if (!exact_points.empty() && given_normals.size() != input_faces.size())
    throw error("internal error: a polytope with exact points needs one exact normal per facet");
  std::vector<std::vector<int>> faces = input_faces;
  std::vector<int> face_source(faces.size());
  std::iota(face_source.begin(), face_source.end(), 0);
  Polytope p;
  p.points = std::move(points);
  p.exact_points = std::move(exact_points);
  for (int round = 0;; ++round) {
    build_connectivity(p, faces, name);
    if (!given_normals.empty()) p.given_normals = remapped(given_normals, face_source);
    p.compute_normals();
    UnionFind groups(p.num_faces());
    bool merged = false;
    {
      RoundingGuard guard;
      for (const auto& e : p.edges) {
        if (edge_convexity(p, e) <= 0) {
          groups.unite(e.left, e.right);
          merged = true;
        }
      }
    }
    bool small_fan = false;
    for (int v = 0; v < p.num_vertices() && !small_fan; ++v)
      small_fan = p.fan_begin[v + 1] - p.fan_begin[v] < 3 && p.fan_begin[v + 1] > p.fan_begin[v];
    if (!merged && !small_fan) break;
    if (round > 8) fail(name, "facets do not settle into a convex polyhedron");
    // Boundary of each group: the directed edges whose twin lies in another group.
    const int nf = p.num_faces();
    std::vector<int> group_of(nf);
    for (int f = 0; f < nf; ++f) group_of[f] = groups.find(f);
    std::unordered_map<std::uint64_t, int>
        next_of;  // (group, vertex) -> next vertex on the boundary
    std::vector<int> start_of(nf, -1), boundary_count(nf, 0);
    for (const auto& e : p.edges) {
      const int gl = group_of[e.left], gr = group_of[e.right];
      if (gl == gr) continue;
      if (!next_of.emplace(key(gl, e.from), e.to).second ||
          !next_of.emplace(key(gr, e.to), e.from).second)
        fail(name, "merged coplanar facets around vertex " + std::to_string(e.from) +
                       " do not form a disc");
      start_of[gl] = e.from;
      start_of[gr] = e.to;
      ++boundary_count[gl];
      ++boundary_count[gr];
    }
    // Vertices with fewer than three distinct groups around them are not vertices of
    // the polyhedron (they lie inside an edge or a facet).
    std::vector<char> keep(p.num_vertices(), 0);
    for (int v = 0; v < p.num_vertices(); ++v) {
      int distinct = 0;
      int first = -1, second = -1;
      for (int s = p.fan_begin[v]; s < p.fan_begin[v + 1]; ++s) {
        const int g = group_of[p.fan_face[s]];
        if (g == first || g == second) continue;
        if (first < 0)
          first = g;
        else if (second < 0)
          second = g;
        ++distinct;
        if (distinct >= 3) break;
      }
      keep[v] = distinct >= 3;
    }
    std::vector<std::vector<int>> merged_faces;
    std::vector<int> merged_source;
    for (int f = 0; f < nf; ++f) {
      if (group_of[f] != f) continue;
      if (start_of[f] < 0) fail(name, "all facets are coplanar");
      std::vector<int> cyc;
      int v = start_of[f];
      int steps = 0;
      do {
        if (keep[v]) cyc.push_back(v);
        v = next_of.at(key(f, v));
        if (++steps > static_cast<int>(p.corner_vertex.size()))
          fail(name, "merged facet " + std::to_string(face_source[f]) + " has a broken boundary");
      } while (v != start_of[f]);
      if (steps != boundary_count[f])
        fail(name, "coplanar facets around facet " + std::to_string(face_source[f]) +
                       " do not form a disc");
      if (cyc.size() < 3)
        fail(name, "facet " + std::to_string(face_source[f]) + " degenerates when merged");
      merged_faces.push_back(std::move(cyc));
      merged_source.push_back(face_source[f]);
    }
    faces = std::move(merged_faces);
    face_source = std::move(merged_source);
  }
  // Drop unused vertices.
  std::vector<int> new_index(p.num_vertices(), -1);
  int used = 0;
  for (const auto& cyc : faces)
    for (int v : cyc)
      if (new_index[v] < 0) new_index[v] = used++;
  if (used != p.num_vertices()) {
    std::vector<V3<double>> pts(used);
    const bool exact = !p.exact_points.empty();
    ExactPoints epts;
    if (exact) epts.resize(used);
    std::vector<int> vsrc(used);
    for (int v = 0; v < p.num_vertices(); ++v) {
      if (new_index[v] < 0) continue;
      pts[new_index[v]] = p.points[v];
      if (exact) {  // (lazy exact points are computed here: they are renumbered)
        epts.numerator[new_index[v]] = p.exact_points.X(v);
        epts.denominator[new_index[v]] = p.exact_points.W(v);
        epts.enclosure[new_index[v]] = p.exact_points.enclosure[v];
        if (!p.exact_points.precise.empty()) {
          epts.precise.resize(used);
          epts.precise[new_index[v]] = p.exact_points.precise[v];
        }
      }
      vsrc[new_index[v]] = v;
    }
    for (auto& cyc : faces)
      for (int& v : cyc) v = new_index[v];
    p.points = std::move(pts);
    p.exact_points = std::move(epts);
    p.vertex_source = std::move(vsrc);
    build_connectivity(p, faces, name);
    if (!given_normals.empty()) p.given_normals = remapped(given_normals, face_source);
    p.compute_normals();
  } else {
    p.vertex_source.resize(used);
    std::iota(p.vertex_source.begin(), p.vertex_source.end(), 0);
  }
  p.face_source = face_source;
  // Edges are labelled by their own index unless a mesh says otherwise (make_polytope(Mesh)).
  p.edge_source.resize(p.num_edges());
  std::iota(p.edge_source.begin(), p.edge_source.end(), 0);
  check_gauss_map(p, name);
  check_edges_convex(p, name);
  return p;
}

Polytope make_polytope_from_cycles(const Mesh& mesh, const char* name, FaceOrder order) {
  // Dense numbering of the mesh's live vertices and faces (identity without deleted ones).
  std::vector<int> dense(mesh.n_vertices(), -1), mesh_vertex, mesh_face;
  std::vector<V3<double>> points;
  points.reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    const auto& q = mesh.point(v);
    dense[v.idx()] = static_cast<int>(points.size());
    points.push_back({q[0], q[1], q[2]});
    mesh_vertex.push_back(v.idx());
  }
  std::vector<std::vector<int>> faces;
  faces.reserve(mesh.n_faces());
  for (auto f : mesh.faces()) {
    std::vector<int> cyc;
    for (auto v : f.vertices()) cyc.push_back(dense[v.idx()]);
    if (order == FaceOrder::reversed) std::reverse(cyc.begin(), cyc.end());
    faces.push_back(std::move(cyc));
    mesh_face.push_back(f.idx());
  }
  Polytope p = make_polytope(std::move(points), {}, faces, {}, name);
  for (int& v : p.vertex_source) v = mesh_vertex[v];
  for (int& f : p.face_source) f = mesh_face[f];
  for (int e = 0; e < p.num_edges(); ++e) {
    const auto u = mesh.vertex_handle(p.vertex_source[p.edges[e].from]);
    const auto w = mesh.vertex_handle(p.vertex_source[p.edges[e].to]);
    auto h = mesh.find_halfedge(u, w);
    if (!h.is_valid()) {
      // The polytope edge spans removed vertices: label it with its first mesh edge, the
      // one at u on the side of its left facet (the face runs u -> x, or x -> u when the
      // faces are reversed).
      for (auto oh : mesh.voh_range(u)) {
        const auto side = order == FaceOrder::reversed ? mesh.opposite_halfedge_handle(oh) : oh;
        if (mesh.face_handle(side).is_valid() &&
            mesh.face_handle(side).idx() == p.face_source[p.edges[e].left]) {
          h = oh;
          break;
        }
      }
    }
    p.edge_source[e] = h.is_valid() ? mesh.edge_handle(h).idx() : -1;
  }
  return p;
}

namespace {

/// make_polytope(mesh, name, order) once connectivity_from_halfedges has filled p's facets,
/// edges and fans: the normals, the canonical form, the labels and the Gauss map. The facet
/// cycles are only read (they end in the result, or stay in p).
/// `units_known`: p.unit_normals already holds the facets' unit normals; `edges_convex`: and
/// every edge is known to be strictly convex. `across`, when given: OperandTopology's (the facet
/// across the edge that ends at each corner).
Polytope finish_from_halfedges(Polytope& p, std::vector<int> mesh_edge, const Mesh& mesh,
                               const char* name, FaceOrder order, bool units_known = false,
                               bool edges_convex = false, const int* across = nullptr) {
  p.compute_normals(units_known);
  // The edges and turns on their filters in one pass where the check did not prove them; the
  // two checks themselves otherwise (or when the filters leave any undecided).
  const bool proven = units_known && edges_convex;
  const bool passes = !proven && fans_at_least_three(p) && edges_and_turns_pass(p, across);
  if (!passes && !is_canonical(p, proven)) return make_polytope_from_cycles(mesh, name, order);
  p.vertex_source.resize(p.num_vertices());
  std::iota(p.vertex_source.begin(), p.vertex_source.end(), 0);
  p.face_source.resize(p.num_faces());
  std::iota(p.face_source.begin(), p.face_source.end(), 0);
  p.edge_source = std::move(mesh_edge);
  // Every edge is strictly convex (is_canonical); the Gauss map is left to check, where
  // that does not already prove it (turns through three triangles).
  if (!passes) check_gauss_map(p, name, true);
  return std::move(p);
}

// Below this many facets, checked_polytope checks and builds in sequence even when threads
// allow: waking a worker costs more than the check.
constexpr int kParallelOperandFaces = 1000;

/// The mesh's points into p, and whether the mesh is readable() (every coordinate finite),
/// in one pass; with `box`, also the points' bounding box as the operand check computes it (see
/// geometry_passes).
bool copy_points(Polytope& p, const Mesh& mesh, PointBox* box = nullptr) {
  const int n = static_cast<int>(mesh.n_vertices());
  p.points.resize(n);
  const Point* q = mesh.points();
  V3<double>* const points = p.points.data();
  bool finite = true;
  if (!box) {
    for (int v = 0; v < n; ++v) {
      const V3<double> x{q[v][0], q[v][1], q[v][2]};
      finite &= std::isfinite(x.x) & std::isfinite(x.y) & std::isfinite(x.z);
      points[v] = x;
    }
    return finite;
  }
  // The box in two halves, even and odd vertices, so that each minimum and maximum is two
  // chains of half the length. Point's minimize() is std::min(lo, q) (maximize() std::max(hi,
  // q)): in index order it keeps the first vertex among those equal to the extreme, so the
  // halves' results combine to the same, except where they are equal as numbers but not as
  // bits (+0 and -0): then the box is computed again in index order.
  constexpr double inf = std::numeric_limits<double>::infinity();
  double lo[2][3] = {{inf, inf, inf}, {inf, inf, inf}};
  double hi[2][3] = {{-inf, -inf, -inf}, {-inf, -inf, -inf}};
  const auto add = [&](int half, int v) {
    const double x = q[v][0], y = q[v][1], z = q[v][2];
    finite &= std::isfinite(x) & std::isfinite(y) & std::isfinite(z);
    points[v] = {x, y, z};
    lo[half][0] = std::min(lo[half][0], x);
    lo[half][1] = std::min(lo[half][1], y);
    lo[half][2] = std::min(lo[half][2], z);
    hi[half][0] = std::max(hi[half][0], x);
    hi[half][1] = std::max(hi[half][1], y);
    hi[half][2] = std::max(hi[half][2], z);
  };
  int v = 0;
  for (; v + 1 < n; v += 2) {
    add(0, v);
    add(1, v + 1);
  }
  if (v < n) add(0, v);
  bool tie = false;
  Point box_lo, box_hi;
  for (int i = 0; i < 3; ++i) {
    tie |= (lo[0][i] == 0 && lo[1][i] == 0 && std::signbit(lo[0][i]) != std::signbit(lo[1][i])) |
           (hi[0][i] == 0 && hi[1][i] == 0 && std::signbit(hi[0][i]) != std::signbit(hi[1][i]));
    box_lo[i] = std::min(lo[0][i], lo[1][i]);
    box_hi[i] = std::max(hi[0][i], hi[1][i]);
  }
  if (tie) {
    box_lo = Point(inf, inf, inf);
    box_hi = Point(-inf, -inf, -inf);
    for (int u = 0; u < n; ++u) {
      box_lo.minimize(q[u]);
      box_hi.maximize(q[u]);
    }
  }
  *box = {box_lo, box_hi};
  return finite;
}

/// make_operand(mesh, name) in one pass for a mesh that is an operand as it is (the usual
/// case): the halfedge walks that build the polytope also find whether check_operand's
/// topological checks pass, and its geometric checks then run on the polytope's facet cycles
/// (geometry_passes), so the mesh's connectivity is read once (with threads to spare, a large
/// mesh's check reads its own cycles instead, beside the walks). Returns nothing when the check
/// would not pass the mesh as it is (an error, an inverted mesh, a deleted element) or the
/// walks meet anything unusual: make_operand then checks and builds as before, for the same
/// messages. The polytope is make_polytope(mesh, name)'s, built by the same code.
std::optional<Polytope> checked_polytope(const Mesh& mesh, const char* name) {
  if (mesh.n_faces() == 0 || has_deleted_elements(mesh)) return std::nullopt;
  // The check counts only live halfedges.
  if (mesh.has_halfedge_status() &&
      any_status_deleted(mesh.property(mesh.halfedge_status_pph()).data_vector()))
    return std::nullopt;
  Polytope p;
  PointBox box;
  if (!copy_points(p, mesh, &box) || p.num_vertices() == 0) return std::nullopt;
  OperandTopology topology;
  std::vector<int> mesh_edge;
  // The halfedge walks; false when they meet a broken face cycle or fan (the check names it).
  const auto walk = [&] {
    try {
      mesh_edge = connectivity_from_halfedges(p, mesh, FaceOrder::as_given, &topology);
    } catch (const error&) {
      return false;
    }
    return true;
  };
  // The geometric checks and the rest of the build both only read the facet cycles. The
  // check's verdict decides, as in make_operand.
  std::atomic<bool> rejected{false};
  bool passes = false, walked = false, units_known = false, edges_convex = false;
  std::optional<Polytope> built;
  std::exception_ptr build_error;
  const auto build = [&] {
    if (rejected) return;
    try {
      built = finish_from_halfedges(p, std::move(mesh_edge), mesh, name, FaceOrder::as_given,
                                    units_known, edges_convex, topology.across.get());
    } catch (...) {
      build_error = std::current_exception();
    }
  };
  if (static_cast<int>(mesh.n_faces()) >= kParallelOperandFaces &&
      tbb::this_task_arena::max_concurrency() > 1) {
    // Beside each other from the start: the check on face cycles of its own (the same as the
    // walks', whenever the topology passes), the walks then the build on this thread. The
    // check is the first function, the one another thread takes: two operands made side by
    // side (make_operands) end sooner when the thread done with the smaller one takes the
    // larger one's check, instead of waiting for its walks.
    run_both(
        [&] {
          passes = geometry_passes(mesh);
          rejected = !passes;
        },
        [&] {
          walked = walk() && topology.passes;
          if (walked) build();
        });
  } else {
    // In sequence, the check on the walks' cycles (read once), before the build; the check
    // leaves the facets' unit normals from the planes it computes (the facets are the faces,
    // the cycles the same), so the build need not compute them again, and proves the edges
    // strictly convex with them where it can, so the build need not test them again.
    walked = walk() && topology.passes;
    if (!walked) return std::nullopt;
    const FaceCycleView cycles{p.face_begin.data(), p.corner_vertex.data(), topology.across.get()};
    p.unit_normals.resize(p.num_faces());
    passes = geometry_passes(mesh, cycles, p.unit_normals.data(), units_known, edges_convex, &box);
    rejected = !passes;
    build();
  }
  if (!walked || !passes) return std::nullopt;
  if (build_error) std::rethrow_exception(build_error);
  return built;
}

}  // namespace

Polytope make_polytope(const Mesh& mesh, const char* name, FaceOrder order) {
  if (has_deleted_elements(mesh)) return make_polytope_from_cycles(mesh, name, order);
  Polytope p;
  copy_points(p, mesh);  // finiteness: make_operand reads the mesh only once it is readable()
  std::vector<int> mesh_edge = connectivity_from_halfedges(p, mesh, order);
  return finish_from_halfedges(p, std::move(mesh_edge), mesh, name, order);
}

Polytope make_operand(const Mesh& mesh, const char* name) {
  if (std::optional<Polytope> p = checked_polytope(mesh, name)) return std::move(*p);
  // Anything else (an error, an inverted mesh, deleted elements): the polytope is built while the
  // mesh is checked (on another thread when there is one), as if the mesh were valid and outward:
  // its halfedges are read before the check has passed, which is safe once every coordinate is
  // finite (all make_polytope's other assumptions, a closed mesh first, are tested as it goes, or
  // only make it throw). The check's verdict decides: its error wins, an inverted mesh is built
  // again reversed, and otherwise the build's result (or error) is the one the sequential order
  // would give.
  std::atomic<bool> rejected{false};
  bool inverted = false, built = false;
  Polytope p;
  std::exception_ptr build_error;
  // The build is the first function, which never throws (its error is kept), so the check's
  // error is the one run_both rethrows. With one thread TBB runs the second function first:
  // the check, so a rejected mesh is not built at all.
  run_both(
      [&] {
        if (rejected || !readable(mesh)) return;
        try {
          p = make_polytope(mesh, name);
          built = true;
        } catch (...) {
          build_error = std::current_exception();
        }
      },
      [&] {
        try {
          inverted = check_operand(mesh, name).has_value();
        } catch (...) {
          rejected = true;
          throw;
        }
      });
  if (inverted) return make_polytope(mesh, name, FaceOrder::reversed);
  if (build_error) std::rethrow_exception(build_error);
  return built ? std::move(p) : make_polytope(mesh, name);
}

Operands make_operands(const Mesh& A, const Mesh& B) {
  Operands op;
  run_both([&] { op.a = make_operand(A, "A"); }, [&] { op.b = make_operand(B, "B"); });
  return op;
}

Mesh to_mesh(const Polytope& p) {
  Mesh mesh;
  std::vector<Mesh::VertexHandle> vh;
  vh.reserve(p.num_vertices());
  for (const auto& q : p.points) vh.push_back(mesh.add_vertex(Point(q.x, q.y, q.z)));
  std::vector<Mesh::VertexHandle> face;
  for (int f = 0; f < p.num_faces(); ++f) {
    face.clear();
    for (int k = 0; k < p.degree(f); ++k) face.push_back(vh[p.corner(f, k)]);
    if (!mesh.add_face(face).is_valid())
      throw error("internal error: facet " + std::to_string(f) +
                  " of a result could not be added to the mesh");
  }
  return mesh;
}

}  // namespace morph::detail
