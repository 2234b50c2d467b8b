#include "gauss_map.h"

#include <morph/error.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "parallel.h"

namespace morph::detail {

namespace {

/// The narrowest cap (its angular radius) worth testing (RegionCap).
constexpr double kMinCapAngle = 1e-3;

/// X lies on the closed arc (p, q), given that it lies on the great circle through them.
bool between(const NormalRef& p, const NormalRef& x, const NormalRef& q) {
  // At an end: (p x p) . (p x q) = 0 and (p x q) . (p x q) > 0 (p, q the distinct ends
  // of an arc), and likewise at q. Shortcuts as in orient_undecided: first when the unit
  // normals hint at it, else between the double-double and the exact stages.
  if ((same_unit(x, p) && same_normal(x, p)) || (same_unit(x, q) && same_normal(x, q))) return true;
  auto sign = [](const NormalRef& a, const NormalRef& b, const NormalRef& c, const NormalRef& d) {
    const int s = cross_dot_normals_filter(a, b, c, d);
    return s != kUndecided ? s : cross_dot_normals_precise(a, b, c, d);
  };
  const int s1 = sign(p, x, p, q);
  if (s1 < 0) return false;
  const int s2 = sign(x, q, p, q);
  if (s2 < 0) return false;
  if (s1 != kUndecided && s2 != kUndecided) return true;
  if (same_normal(x, p) || same_normal(x, q)) return true;
  return (s1 != kUndecided || cross_dot_normals_exact(p, x, p, q) >= 0) &&
         (s2 != kUndecided || cross_dot_normals_exact(x, q, p, q) >= 0);
}

/// region_test's exact part, for a region whose slots the double filter left undecided (none
/// certainly negative): decides each. Out of line, so that the usual test stays small.
[[gnu::noinline]] int decide_slots(const Polytope& P, const ArcPlane* slots, int v,
                                   const NormalRef& p, int zeros[2], int& nzeros) {
  const int b = P.fan_begin[v], n = P.fan_begin[v + 1] - b;
  const int* const fan = P.fan_face.data() + b;
  for (int i = 0; i < n; ++i) {
    const NormalRef l{&P, fan[i]}, r{&P, fan[i + 1 == n ? 0 : i + 1]};
    int s = orient_arc_filter(slots ? slots[b + i] : cross_plane(l.unit(), r.unit()), p);
    if (s == kUndecided)
      // p at a facet normal of this map (A (+) A) is the usual reason for an undecided slot.
      s = orient_undecided(l, r, p, true);
    if (s < 0) return i;
    if (s == 0) {
      if (nzeros == 2) throw error("internal error: a direction lies on three arcs of one region");
      zeros[nzeros++] = i;
    }
  }
  return -1;
}

/// Signs of det(N_fan[i], N_fan[i+1], p) for the slots of v's region (`slots`: P's
/// slot_planes, or null to form them here). Returns a slot whose sign is negative (the one
/// the double filter finds most negative, when it finds one: the walk heads toward p), or
/// -1 when p is in the closed region, with `zeros` then holding the slots whose arc
/// contains p.
inline int region_test(const Polytope& P, const ArcPlane* slots, int v, const NormalRef& p,
                       int zeros[2], int& nzeros) {
  const int b = P.fan_begin[v], n = P.fan_begin[v + 1] - b;
  const int* const fan = P.fan_face.data() + b;
  nzeros = 0;
  // The double stage of orient_arc on every slot at once.
  const UnitNormal& u = p.unit();
  bool inside = true;
  int most = -1;
  double lowest = 0;
  // arc_filter's bound, with p's share added once: plane.error + (u.error + rounding) bounds
  // the same error as arc_filter's sum (its margin covers the order of the additions).
  const double p_bound = u.error + kUnitPredicateRounding;
  auto scan = [&](auto&& plane_of) {
    for (int i = 0; i < n; ++i) {
      const ArcPlane& plane = plane_of(i);
      const double value = u.x * plane.x + u.y * plane.y + u.z * plane.z;
      const double bound = plane.error + p_bound;
      if (!(value > bound)) inside = false;
      if (value < -bound && value < lowest) {
        lowest = value;
        most = i;
      }
    }
  };
  if (slots)
    scan([&](int i) -> const ArcPlane& { return slots[b + i]; });
  else
    scan([&](int i) {
      return cross_plane(P.unit_normals[fan[i]], P.unit_normals[fan[i + 1 == n ? 0 : i + 1]]);
    });
  if (inside) return -1;
  if (most >= 0) return most;
  return decide_slots(P, slots, v, p, zeros, nzeros);
}

Location classify(const Polytope& P, int v, const int zeros[2], int nzeros) {
  const int b = P.fan_begin[v], n = P.fan_begin[v + 1] - b;
  if (nzeros == 0) return {Location::Kind::vertex, v};
  if (nzeros == 1) return {Location::Kind::edge, P.fan_edge[b + zeros[0]]};
  // Two arcs: p is their common end, the normal of the facet between them.
  const int i = zeros[0], j = zeros[1];
  const int shared = (i + 1) % n == j ? j : i;  // slot i ends at fan_face[i+1]
  return {Location::Kind::face, P.fan_face[b + shared]};
}

}  // namespace

bool similar_cycles(const Polytope& P, int f, const Polytope& Q, int g) {
  const int d = P.degree(f);
  if (Q.degree(g) != d || !P.given_normals.empty() || !Q.given_normals.empty()) return false;
  const V3<double>* const pp = P.points.data();
  const V3<double>* const qp = Q.points.data();
  const int* const p = &P.corner_vertex[P.face_begin[f]];
  const int* const q = &Q.corner_vertex[Q.face_begin[g]];
  auto at = [&](int r, int k) -> const V3<double>& { return qp[q[r + k < d ? r + k : r + k - d]]; };
  // Where q's cycle may start (r): a translate's first edge is the same vector as p's,
  // rounded alike (in whatever mode), and usually no start passes (only a shortcut: its
  // x first, the usual way out). Then the same points (compared as numbers), or
  // translates: q_k - p_k the same vector for all k. In round-to-nearest, two_sum gives
  // each difference exactly as (its rounding, the remainder), a function of the real
  // difference: equal pairs are equal differences (finite: no overflow).
  const V3<double>& p0 = pp[p[0]];
  const V3<double>& p1 = pp[p[1]];
  const double edge_x = p1.x - p0.x;
  auto same_edge = [&](int r) {
    const V3<double>&a = at(r, 0), &b = at(r, 1);
    return b.x - a.x == edge_x && b.y - a.y == p1.y - p0.y && b.z - a.z == p1.z - p0.z;
  };
  auto same_points = [&](int r) {
    for (int k = 0; k < d; ++k) {
      const V3<double>& a = pp[p[k]];
      const V3<double>& b = at(r, k);
      if (!(a.x == b.x && a.y == b.y && a.z == b.z)) return false;
    }
    return true;
  };
  auto translates = [&](int r) {
    // Equal differences round alike (in whatever mode): a cheap way out first.
    const V3<double> t0 = at(r, 0) - p0;
    for (int k = 1; k < d; ++k) {
      const V3<double> t = at(r, k) - pp[p[k]];
      if (!(t.x == t0.x && t.y == t0.y && t.z == t0.z)) return false;
    }
    RoundingGuard nearest(CGAL_FE_TONEAREST);
    auto difference = [](const V3<double>& b, const V3<double>& a, DD t[3]) {
      t[0] = two_sum(b.x, -a.x);
      t[1] = two_sum(b.y, -a.y);
      t[2] = two_sum(b.z, -a.z);
      return std::isfinite(t[0].hi) && std::isfinite(t[1].hi) && std::isfinite(t[2].hi);
    };
    DD t[3], s[3];
    if (!difference(at(r, 0), p0, t)) return false;
    for (int k = 1; k < d; ++k) {
      if (!difference(at(r, k), pp[p[k]], s)) return false;
      if (!(s[0].hi == t[0].hi && s[0].lo == t[0].lo && s[1].hi == t[1].hi && s[1].lo == t[1].lo &&
            s[2].hi == t[2].hi && s[2].lo == t[2].lo))
        return false;
    }
    return true;
  };
  // Scaled copies: q_{r+k} - q_r = 2^e (p_k - p_0) for all k. Multiplying by 2^e is exact
  // in any rounding mode when the product is normal (or both are zero), so such edges'
  // rounded components are those of p's first edge times one 2^e: the same sign and
  // significand bits (a shortcut giving e; usually the x component already differs).
  constexpr std::uint64_t kSignificand = 0x800FFFFFFFFFFFFFull;  // and the sign
  int e = 0;
  auto scaled_edge = [&](int r) {
    const V3<double>&a = at(r, 0), &b = at(r, 1);
    bool known = false;
    auto component = [&](double u, double v) {
      if (u == 0 || v == 0) return u == v;
      std::uint64_t x, y;
      std::memcpy(&x, &u, sizeof x);
      std::memcpy(&y, &v, sizeof y);
      const int ex = int(x >> 52 & 0x7FF), ey = int(y >> 52 & 0x7FF);
      if (((x ^ y) & kSignificand) != 0 || ex == 0 || ey == 0 || ex == 0x7FF || ey == 0x7FF)
        return false;
      if (known) return ey - ex == e;
      known = true;
      e = ey - ex;
      return e != 0;  // e = 0: same_edge (translates) was tried
    };
    return component(edge_x, b.x - a.x) && component(p1.y - p0.y, b.y - a.y) &&
           component(p1.z - p0.z, b.z - a.z) && known;
  };
  auto scales = [&](int r) {
    // The same in round-to-nearest on two_sum pairs (exact differences, see above), each
    // pair of p's cycle scaled by 2^e, rejected where that may be inexact: a product
    // neither normal nor an exact zero.
    const double s = std::ldexp(1.0, e);
    if (!std::isnormal(s)) return false;
    RoundingGuard nearest(CGAL_FE_TONEAREST);
    auto same = [s](double pb, double pa, double qb, double qa) {
      const DD u = two_sum(pb, -pa), v = two_sum(qb, -qa);
      const double hi = u.hi * s, lo = u.lo * s;
      return (u.hi == 0 || std::isnormal(hi)) && (u.lo == 0 || std::isnormal(lo)) && hi == v.hi &&
             lo == v.lo;
    };
    const V3<double>& q0 = at(r, 0);
    for (int k = 1; k < d; ++k) {
      const V3<double>&a = pp[p[k]], &b = at(r, k);
      if (!(same(a.x, p0.x, b.x, q0.x) && same(a.y, p0.y, b.y, q0.y) && same(a.z, p0.z, b.z, q0.z)))
        return false;
    }
    return true;
  };
  // One pass over the starts, the x component of the first edge first: equal (then
  // translates; scaled only when it is zero), or else the sign and significand bits.
  std::uint64_t edge_bits;
  std::memcpy(&edge_bits, &edge_x, sizeof edge_bits);
  for (int r = 0; r < d; ++r) {
    const double dx = at(r, 1).x - at(r, 0).x;
    if (dx == edge_x) {
      if (same_edge(r) && (same_points(r) || translates(r))) return true;
      if (edge_x != 0) continue;
    } else {
      std::uint64_t bits;
      std::memcpy(&bits, &dx, sizeof bits);
      if (((bits ^ edge_bits) & kSignificand) != 0) continue;
    }
    if (scaled_edge(r) && scales(r)) return true;
  }
  return false;
}

/// The cross products of NearPairScope: a table of the last pair per hash slot.
struct NearPairs {
  struct Entry {
    const Polytope *px, *py;  // px null: empty
    int fx, fy;
    bool valid;  // both precise normals valid
    double w[3], eps;
  };
  static constexpr int kSize = 256;  // a power of two; pairs per sum: about 60 (ico 320 + 1280)
  const Polytope *a, *b;             // the scope's polytopes
  Entry entries[kSize];
};

namespace {

thread_local NearPairs* near_pairs = nullptr;

/// precise_cross (polytope.cpp) in round-to-nearest.
bool near_cross(const NormalRef& x, const NormalRef& y, double w[3], double& eps) {
  RoundingGuard nearest(CGAL_FE_TONEAREST);
  return precise_cross(x, y, w, eps);
}

/// Sign of det(a, b, c), or kUndecided: orient_normals_precise's first stage (orient_near_pair
/// on the nearly parallel pair, the same choice of pair, the same bound), with the pair's
/// cross product from `pairs` (undecided for a pair not of the scope's polytopes). Undecided
/// where that stage is not tried (a component that may be zero in all three: the determinant
/// may be zero, which only the later stages show; trying this stage first there measured
/// slower). `tried`: set when this stage ran (decided or not), so that the caller skips
/// orient_normals_precise's repetition of it.
int orient_near_cached(NearPairs& pairs, const NormalRef& a, const NormalRef& b, const NormalRef& c,
                       bool& tried) {
  const UnitNormal &ua = a.unit(), &ub = b.unit(), &uc = c.unit();
  auto may_be_zero = [](double pa, double pb, double pc, double ea, double eb, double ec) {
    return std::abs(pa) <= ea && std::abs(pb) <= eb && std::abs(pc) <= ec;
  };
  if (may_be_zero(ua.x, ub.x, uc.x, ua.error, ub.error, uc.error) ||
      may_be_zero(ua.y, ub.y, uc.y, ua.error, ub.error, uc.error) ||
      may_be_zero(ua.z, ub.z, uc.z, ua.error, ub.error, uc.error))
    return kUndecided;
  auto dot = [](const UnitNormal& u, const UnitNormal& v) {
    return std::abs(u.x * v.x + u.y * v.y + u.z * v.z);
  };
  const double ab = dot(ua, ub), bc = dot(ub, uc), ca = dot(uc, ua);
  // det(a, b, c) = c . (a x b) = a . (b x c) = b . (c x a).
  const NormalRef *x, *y;
  const UnitNormal* z;
  if (ab >= bc && ab >= ca)
    x = &a, y = &b, z = &uc;
  else if (bc >= ca)
    x = &b, y = &c, z = &ua;
  else
    x = &c, y = &a, z = &ub;
  auto kept = [&pairs](const Polytope* P) { return P == pairs.a || P == pairs.b; };
  if (!kept(x->polytope) || !kept(y->polytope)) return kUndecided;
  tried = true;
  if (!std::isfinite(z->error)) return kUndecided;
  const unsigned hash = (static_cast<unsigned>(x->face) * 0x9E3779B1u) ^
                        (static_cast<unsigned>(y->face) * 0x85EBCA77u);
  NearPairs::Entry& e = pairs.entries[(hash >> 16) & (NearPairs::kSize - 1)];
  if (!(e.px == x->polytope && e.fx == x->face && e.py == y->polytope && e.fy == y->face)) {
    e.px = x->polytope, e.fx = x->face, e.py = y->polytope, e.fy = y->face;
    e.valid = near_cross(*x, *y, e.w, e.eps);
  }
  if (!e.valid) return kUndecided;
  // orient_near_pair's evaluation and bound (see there).
  const double* const w = e.w;
  const double d = z->x * w[0] + z->y * w[1] + z->z * w[2];
  const double size = std::abs(w[0]) + std::abs(w[1]) + std::abs(w[2]);
  const double products = std::abs(z->x * w[0]) + std::abs(z->y * w[1]) + std::abs(z->z * w[2]);
  const double bound = (z->error * size + e.eps + 4 * 0x1p-52 * products) * 1.01 + 0x1p-1000;
  if (d > bound) return 1;
  if (d < -bound) return -1;
  return kUndecided;
}

}  // namespace

NearPairScope::NearPairScope(const Polytope& a, const Polytope& b)
    : pairs_(std::make_unique_for_overwrite<NearPairs>()), previous_(near_pairs) {
  pairs_->a = &a, pairs_->b = &b;
  for (auto& e : pairs_->entries) e.px = nullptr;
  near_pairs = pairs_.get();
}

NearPairScope::~NearPairScope() { near_pairs = previous_; }

int orient_undecided(const NormalRef& a, const NormalRef& b, const NormalRef& c,
                     bool likely_equal) {
  if (likely_equal
          ? same_normal(a, c) || same_normal(b, c)
          : (same_unit(a, c) && same_normal(a, c)) || (same_unit(b, c) && same_normal(b, c)))
    return 0;
  bool tried = false;
  if (near_pairs) {
    const int s = orient_near_cached(*near_pairs, a, b, c, tried);
    if (s != kUndecided) return s;
  }
  // The pair's step again would give the same (exact signs, whichever rounding mode).
  const int s = tried ? orient_normals_precise_full(a, b, c) : orient_normals_precise(a, b, c);
  if (s != kUndecided) return s;
  if (same_normal(a, c) || same_normal(b, c) || same_normal(a, b)) return 0;
  return orient_normals_exact(a, b, c);
}

std::vector<ArcPlane> arc_planes(const Polytope& P) {
  std::vector<ArcPlane> planes(P.num_edges());
  parallel_chunks(P.num_edges(), 4096, [&](int begin, int end) {
    for (int e = begin; e < end; ++e) {
      const UnitNormal &q = P.unit_normals[P.edges[e].left], &r = P.unit_normals[P.edges[e].right];
      planes[e] = cross_plane(q, r);
    }
  });
  return planes;
}

namespace {

/// The slot planes of v's region (its fan's consecutive facet normals), into `out`
/// (P.fan_begin[v] onwards): slot_planes and SlotCache make the same doubles with it.
void region_slot_planes(const Polytope& P, int v, ArcPlane* out) {
  // Each normal loaded once, into locals (the stores cannot alias them): every slot's second
  // normal is the next slot's first.
  const UnitNormal* const units = P.unit_normals.data();
  const int* const fan = P.fan_face.data();
  const int b = P.fan_begin[v], e = P.fan_begin[v + 1];
  if (b == e) return;
  const UnitNormal first = units[fan[b]];
  UnitNormal q = first;
  for (int s = b; s + 1 < e; ++s) {
    const UnitNormal r = units[fan[s + 1]];
    out[s] = cross_plane(q, r);
    q = r;
  }
  out[e - 1] = cross_plane(q, first);
}

}  // namespace

SlotPlanes slot_planes(const Polytope& P) {
  SlotPlanes slots(P.fan_face.size());
  parallel_chunks(P.num_vertices(), 1024, [&](int begin, int end) {
    for (int v = begin; v < end; ++v) region_slot_planes(P, v, slots.data());
  });
  return slots;
}

namespace {

/// locate, with slots_of(v) giving the slot planes for v's region (or null), and
/// in_cap_of(v) whether p is certainly inside v's region by its cap (RegionCap).
template <class SlotsOf, class InCap>
Location walk(const Polytope& P, const SlotsOf& slots_of, const InCap& in_cap_of,
              const NormalRef& p, int hint, bool step) {
  // The hint's cap first: a direction in it is in the hint's region (no step, no region test).
  if (in_cap_of(hint)) return {Location::Kind::vertex, hint};
  // First one cheap step in doubles: to the neighbour of the hint with the largest support
  // value <p, x>, if it beats the hint's. It only picks where the exact walk starts, which
  // then usually finds the region at once (climbing on to the top in doubles costs a scan
  // of the top's neighbours, more than the region test it would spare).
  int v = hint;
  if (step) {
    const UnitNormal& d = p.unit();
    auto support = [&](int w) {
      return d.x * P.points[w].x + d.y * P.points[w].y + d.z * P.points[w].z;
    };
    double best = support(hint);
    for (int s = P.fan_begin[hint]; s < P.fan_begin[hint + 1]; ++s) {
      const double h = support(P.fan_vertex[s]);
      if (h > best) {
        best = h;
        v = P.fan_vertex[s];
      }
    }
  }
  int zeros[2];
  int nzeros = 0;
  const int limit = P.num_vertices() + 16;
  for (int steps = 0; steps < limit; ++steps) {
    if (v != hint && in_cap_of(v)) return {Location::Kind::vertex, v};
    const int cross = region_test(P, slots_of(v), v, p, zeros, nzeros);
    if (cross < 0) return classify(P, v, zeros, nzeros);
    v = P.fan_vertex[P.fan_begin[v] + cross];
  }
  // The walk climbs the support function and cannot loop on a polytope whose facets are
  // exactly planar; on facets planar only within the tolerance it might, so fall back
  // to testing every region.
  for (v = 0; v < P.num_vertices(); ++v)
    if (region_test(P, slots_of(v), v, p, zeros, nzeros) < 0) return classify(P, v, zeros, nzeros);
  throw error("internal error: a direction lies in no region of the Gauss map");
}

}  // namespace

Location locate(const Polytope& P, const ArcPlane* slots, const NormalRef& p, int hint, bool step) {
  return walk(
      P, [slots](int) { return slots; }, [](int) { return false; }, p, hint, step);
}

Location locate(const Polytope& P, SlotCache& slots, const NormalRef& p, int hint, bool step) {
  const UnitNormal& u = p.unit();
  return walk(
      P, [&slots](int v) { return slots.region(v); },
      [&slots, &u](int v) { return slots.has_caps() && in_cap(slots.cap(v), u); }, p, hint, step);
}

RegionCap region_cap(const Polytope& P, const ArcPlane* slots, int v) {
  // Why the cap is safe (all in reals; the margins cover the doubles' rounding, below
  // 1e-14 here). Let d_i be the signed angle from the centre c to slot i's great circle
  // (sin d_i = c . P_i / |P_i| =: delta_i, so d_i >= delta_i when positive), and b the angle
  // between c and a direction u^ = u / |u|. Angles to a great circle are 1-Lipschitz, so
  // u^'s is at least d_i - b, in (0, pi/2] when b < alpha <= delta_i - 2 beta_i; then
  // u . P_i = |u| |P_i| sin(its angle) >= |u| |P_i| (d_i - b) / 2 > |u| |P_i| beta_i, with
  // |P_i| beta_i = 1.1 (P_i.error + kCapQueryError + kUnitPredicateRounding) + 1e-14: above
  // the filter's bound (arc_filter's) by more than its rounding, so the filter passes on
  // slot i. And u^ . c > 1 - alpha^2 / 2 + alpha^4 / 24 >= cos(alpha) gives b < alpha.
  constexpr RegionCap none{0, 0, 0, 2};
  const int b = P.fan_begin[v], n = P.fan_begin[v + 1] - b;
  const int* const fan = P.fan_face.data() + b;
  double cx = 0, cy = 0, cz = 0;  // the centre: the fan's unit normals' mean direction
  for (int i = 0; i < n; ++i) {
    const UnitNormal& u = P.unit_normals[fan[i]];
    cx += u.x, cy += u.y, cz += u.z;
  }
  const double length = std::sqrt(cx * cx + cy * cy + cz * cz);
  if (!(length > 0.5)) return none;
  const double scale = 1 / length;
  cx *= scale, cy *= scale, cz *= scale;
  // alpha = min over the slots of delta_i - 2 beta_i = t_i / |P_i| (all positive), from the
  // smallest square: one square root in all, and no branch per slot.
  double alpha2 = 1;  // alpha = 1 (no slot can allow more: delta_i <= 1)
  bool positive = true;
  for (int i = 0; i < n; ++i) {
    const ArcPlane& s = slots[b + i];
    const double t = cx * s.x + cy * s.y + cz * s.z -
                     2 * (1.1 * (s.error + kCapQueryError + kUnitPredicateRounding) + 1e-14);
    const double q = s.x * s.x + s.y * s.y + s.z * s.z;
    positive &= t > 0 && q > 1e-12;
    alpha2 = std::min(alpha2, t * t / q);
  }
  if (!positive) return none;
  const double alpha = std::sqrt(alpha2) - 1e-9;  // 1e-9: the rounding, widely
  // Caps narrower than this would seldom contain a direction: not worth a test.
  if (!(alpha >= kMinCapAngle)) return none;
  const double a2 = alpha * alpha;
  // 1e-9: the rounding of the dot product and of |u|, |c| about 1.
  return {cx, cy, cz, 1 - a2 / 2 + a2 * a2 / 24 + 1e-9};
}

SlotCache::SlotCache(const Polytope& P, bool caps)
    : P_(&P),
      planes_(std::make_unique_for_overwrite<ArcPlane[]>(P.fan_face.size())),
      caps_(caps ? std::make_unique_for_overwrite<RegionCap[]>(P.num_vertices()) : nullptr),
      made_(P.num_vertices(), 0) {}

void SlotCache::make(int v) {
  region_slot_planes(*P_, v, planes_.get());
  if (caps_) caps_[v] = region_cap(*P_, planes_.get(), v);
  made_[v] = 1;
}

std::vector<Location> locate_all(const Polytope& from, const Polytope& in,
                                 const std::vector<int>* hints) {
  // A walk tests about ten slots, and forming a slot's plane costs about as much as testing
  // it: making them all first pays only when the walks are many for the slots (at least a
  // quarter as many), else each is formed as it is tested. Either way the same doubles.
  SlotPlanes slots;
  if (4 * static_cast<std::size_t>(from.num_faces()) >= in.fan_face.size()) slots = slot_planes(in);
  const ArcPlane* const in_slots = slots.data();
  std::vector<Location> loc(from.num_faces());
  parallel_chunks(from.num_faces(), 256, [&](int begin, int end) {
    int hint = 0;
    for (int f = begin; f < end; ++f) {
      const bool hinted = hints && (*hints)[f] >= 0;
      if (hinted) hint = (*hints)[f];
      loc[f] = locate(in, in_slots, NormalRef{&from, f}, hint, !hinted);
      hint = location_vertex(in, loc[f]);
    }
  });
  return loc;
}

ArcContact arc_contact_general(const NormalRef& n1, const NormalRef& n2, const NormalRef& m1,
                               const NormalRef& m2, int s1, int s2, int t1, int t2) {
  ArcContact c;
  if (s1 == 0 && s2 == 0) {  // on one great circle: touching iff they overlap
    c.touches = between(n1, m1, n2) || between(n1, m2, n2) || between(m1, n1, m2);
    return c;
  }
  // Both ends strictly on one side of n's great circle: so is all of m, which then
  // shares no point with n (nor with its great circle).
  if (s1 * s2 > 0) return c;
  if (s1 * s2 < 0 && t1 * t2 < 0) {
    // The great circles meet at +-X; the arcs share X (not -X) iff t1 == -s1.
    if (t1 == -s1) c.touches = c.crosses = true;
    c.side = s2;
    return c;
  }
  c.touches = (s1 == 0 && between(n1, m1, n2)) || (s2 == 0 && between(n1, m2, n2)) ||
              (t1 == 0 && between(m1, n1, m2)) || (t2 == 0 && between(m1, n2, m2));
  return c;
}

void arcs_around(const Polytope& P, const Location& where, std::vector<Arc>& out) {
  out.clear();
  switch (where.kind) {
    case Location::Kind::vertex:
      return;
    case Location::Kind::edge: {
      // Forward (toward the right facet) the region of `to` lies on the left.
      const auto& e = P.edges[where.index];
      out.push_back({NormalRef{&P, e.right}, e.to});
      out.push_back({NormalRef{&P, e.left}, e.from});
      return;
    }
    case Location::Kind::face: {
      // Around N_f the arcs lead to the facets across f's edges; between the arcs toward
      // the neighbours across edges k-1 and k lies the region of corner k.
      const int f = where.index, d = P.degree(f), b = P.face_begin[f];
      for (int k = 0; k < d; ++k) {
        const auto& e = P.edges[P.corner_edge[b + k]];
        const int across = e.left == f ? e.right : e.left;
        out.push_back({NormalRef{&P, across}, P.corner_vertex[b + (k + 1 == d ? 0 : k + 1)]});
      }
      return;
    }
  }
}

void overlay_regions(const NormalRef& p, const std::vector<Arc>& x_arcs,
                     const std::vector<Arc>& y_arcs, int y_region,
                     std::vector<std::pair<int, int>>& out, std::vector<int>& halves) {
  const int nx = static_cast<int>(x_arcs.size()), ny = static_cast<int>(y_arcs.size());
  if (ny == 0) {
    for (int i = 0; i < nx; ++i) out.emplace_back(x_arcs[i].after, y_region);
    return;
  }
  // Angles are measured counter-clockwise from the first x arc, by half-plane and then
  // by orientation within it: half 0 is angle 0, 1 is (0, pi), 2 is pi, 3 is (pi, 2 pi).
  const NormalRef& r = x_arcs[0].to;
  auto half = [&](const NormalRef& q) {
    const int s = orient(p, r, q);
    if (s > 0) return 1;
    if (s < 0) return 3;
    // q in r's direction: (p x r) . (p x q) > 0, r being neither p nor -p.
    if (same_normal(q, r)) return 0;
    return cross_dot_normals(p, r, p, q) > 0 ? 0 : 2;
  };
  auto compare = [&](const NormalRef& q1, int h1, const NormalRef& q2, int h2) {
    if (h1 != h2) return h1 < h2 ? -1 : 1;
    if (h1 == 0 || h1 == 2) return 0;
    return -orient(p, q1, q2);  // q1 before q2 when q2 is counter-clockwise of q1
  };
  halves.resize(nx + ny);  // the x arcs' halves, then the y arcs'
  int* const hx = halves.data();
  int* const hy = hx + nx;
  for (int i = 0; i < nx; ++i) hx[i] = i == 0 ? 0 : half(x_arcs[i].to);
  for (int j = 0; j < ny; ++j) hy[j] = half(y_arcs[j].to);
  // The y arcs are cyclically sorted: start at the smallest angle.
  int start = 0;
  for (int j = 1; j < ny; ++j)
    if (compare(y_arcs[j].to, hy[j], y_arcs[start].to, hy[start]) < 0) start = j;
  int cur_x = x_arcs[nx - 1].after;
  int cur_y = y_arcs[(start + ny - 1) % ny].after;
  int i = 0, j = 0;
  while (i < nx || j < ny) {
    int c;
    if (i == nx)
      c = 1;
    else if (j == ny)
      c = -1;
    else {
      const int jj = (start + j) % ny;
      c = compare(x_arcs[i].to, hx[i], y_arcs[jj].to, hy[jj]);
    }
    if (c <= 0) cur_x = x_arcs[i++].after;
    if (c >= 0) cur_y = y_arcs[(start + j++) % ny].after;
    out.emplace_back(cur_x, cur_y);
  }
}

}  // namespace morph::detail
