// Private: exact queries on the Gauss map of a Polytope (see polytope.h): locating a
// direction, classifying how two arcs meet, and the angular order of arcs around a
// point. These are the only geometric decisions of the FIMS kernel.
#pragma once

#include <cmath>
#include <memory>
#include <vector>

#include "polytope.h"

namespace morph::detail {

/// The feature of a Gauss map that contains a direction.
struct Location {
  enum class Kind : unsigned char { vertex, edge, face };
  Kind kind = Kind::vertex;
  int index = -1;
};

/// Whether facets f of P and g of Q (polytopes whose exact normals are Newell's of their
/// double points) have similar vertex cycles, up to where the cycles start: exact
/// translates, or q_k - q_0 = 2^e (p_k - p_0) for all k (a copy scaled by a power of two,
/// e.g. 0.5 or 2: its Newell normal is 2^(2e) times p's). Then their exact normals have the
/// same direction (Newell's normal is invariant under translation). See same_normal.
bool similar_cycles(const Polytope& P, int f, const Polytope& Q, int g);

/// Whether the exact normals of x and y are known to have the same direction, by a cheap
/// exact test: the same facet, or similar_cycles. False when that does not show it, even
/// if the directions are equal: callers then decide by the general predicates. Operands
/// with common facet directions (A (+) A, A (+) -A of a centrally symmetric A, A (+) an exact
/// translate or a copy scaled by 0.5) make every predicate on such normals exactly zero, and
/// this spares the double-double and exact stages their work on them. Inline, the usual
/// answer (far apart unit normals, or two facets of one polytope, whose directions differ:
/// canonical form) costs a few comparisons.
inline bool same_normal(const NormalRef& x, const NormalRef& y) {
  if (x.polytope == y.polytope) return x.face == y.face;
  // Equal directions have unit normals within the sum of their bounds (doubled against
  // the rounding of the differences): a cheap way out for the others. It only saves work.
  const UnitNormal &u = x.unit(), &v = y.unit();
  const double reach = 2 * (u.error + v.error);
  return std::abs(u.x - v.x) <= reach && std::abs(u.y - v.y) <= reach &&
         std::abs(u.z - v.z) <= reach && similar_cycles(*x.polytope, x.face, *y.polytope, y.face);
}

/// Unit normals with the same doubles: what the unit normals of translated cycles starting
/// at the same corner (A (+) A) have, so a hint to try same_normal before anything else.
inline bool same_unit(const NormalRef& x, const NormalRef& y) {
  const UnitNormal &u = x.unit(), &v = y.unit();
  return u.x == v.x && u.y == v.y && u.z == v.z;
}

struct NearPairs;

/// While alive, the calling thread's orient_undecided keeps the double-double cross products
/// N_x x N_y of the nearly parallel pairs it meets (the stage that decides them: see
/// orient_normals_precise), for the other predicates on the same pair: around a facet normal
/// of one map that a normal of the other nearly coincides with, every arc from it is tested
/// against that normal (in the walks, the edge facets and the overlay), each a determinant
/// with the same nearly parallel pair. Only for pairs of normals of a and b, which must
/// outlive it (a task of another call that the thread runs meanwhile, on other polytopes,
/// keeps nothing: those may be freed and others made at their addresses). Scopes nest.
class NearPairScope {
 public:
  NearPairScope(const Polytope& a, const Polytope& b);
  ~NearPairScope();
  NearPairScope(const NearPairScope&) = delete;
  NearPairScope& operator=(const NearPairScope&) = delete;

 private:
  std::unique_ptr<NearPairs> pairs_;
  NearPairs* previous_;
};

/// orient_normals_undecided (for what the double filter leaves undecided), with
/// same_normal's shortcut: two equal directions make the determinant zero. Tried before
/// the double-double stage when the unit normals hint at it (equal doubles, or, when the
/// caller expects coincident normals (`likely_equal`), any within reach), else only
/// before the exact stage, so that nearly parallel normals (fine spheres) pay little for it.
int orient_undecided(const NormalRef& a, const NormalRef& b, const NormalRef& c,
                     bool likely_equal = false);

/// Sign of det(a, b, c) for three normals (the overlay's, at a point where the maps'
/// normals often coincide): orient_normals' double filter, then orient_undecided.
inline int orient(const NormalRef& a, const NormalRef& b, const NormalRef& c) {
  const int s = orient_normals_filter(a, b, c);
  return s != kUndecided ? s : orient_undecided(a, b, c, true);
}

/// The plane of an arc of a Gauss map: N_left x N_right of its edge, from the unit normals
/// in doubles, and the sum of their error bounds. The double stage of
/// orient(N_left, N_right, x) is then one dot product: det(x, N_left, N_right) expanded
/// along x, the same operations as orient_normals (hence its bound).
struct ArcPlane {
  double x, y, z, error;
};

/// The plane q x r of the arc from unit normal q to unit normal r.
inline ArcPlane cross_plane(const UnitNormal& q, const UnitNormal& r) {
  return {q.y * r.z - q.z * r.y, q.z * r.x - q.x * r.z, q.x * r.y - q.y * r.x, q.error + r.error};
}
/// The plane of edge e's arc.
inline ArcPlane arc_plane(const Polytope& P, int e) {
  return cross_plane(P.unit_normals[P.edges[e].left], P.unit_normals[P.edges[e].right]);
}

/// The planes of all arcs of P's Gauss map, indexed by edge.
std::vector<ArcPlane> arc_planes(const Polytope& P);

/// The planes of a Gauss map's fan slots (slot_planes), left uninitialised until made.
class SlotPlanes {
 public:
  SlotPlanes() = default;
  explicit SlotPlanes(std::size_t n)
      : planes_(std::make_unique_for_overwrite<ArcPlane[]>(n)), size_(n) {}
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  /// Null when empty.
  const ArcPlane* data() const { return planes_.get(); }
  ArcPlane* data() { return planes_.get(); }
  const ArcPlane& operator[](std::size_t s) const { return planes_[s]; }

 private:
  std::unique_ptr<ArcPlane[]> planes_;
  std::size_t size_ = 0;
};

/// The planes per fan slot (polytope.h), each oriented as the slot runs: slot s's plane is
/// N_fan[s] x N_fan[s + 1], its edge's plane or that negated (the same doubles: the
/// products commute and a - b = -(b - a) exactly). A region's test then reads one
/// contiguous block, with no edge lookups.
SlotPlanes slot_planes(const Polytope& P);

/// Sign of det(N_left, N_right, x) for edge e of P, whose arc's plane is `plane`.
/// Its double stage alone: the sign, or kUndecided (polytope.h).
/// The double stage's value of det(N_left, N_right, u) and the bound on its error.
struct ArcFilter {
  double value, bound;
};
inline ArcFilter arc_filter(const ArcPlane& plane, const UnitNormal& u) {
  return {u.x * plane.x + u.y * plane.y + u.z * plane.z,
          plane.error + u.error + kUnitPredicateRounding};
}
inline int orient_arc_filter(const ArcPlane& plane, const NormalRef& x) {
  const ArcFilter f = arc_filter(plane, x.unit());
  if (f.value > f.bound) return 1;
  if (f.value < -f.bound) return -1;
  return kUndecided;
}
inline int orient_arc(const Polytope& P, int e, const ArcPlane& plane, const NormalRef& x) {
  const int s = orient_arc_filter(plane, x);
  if (s != kUndecided) return s;
  return orient_undecided(NormalRef{&P, P.edges[e].left}, NormalRef{&P, P.edges[e].right}, x);
}

/// Locates the direction `p` in P's Gauss map (`slots`: its slot_planes, or null to form each
/// slot's plane as it is tested, cheaper for a few directions): the vertex whose region
/// contains it in its interior (the contributing vertex), the edge whose arc contains it, or the
/// facet whose normal has its direction. The walk starts at vertex `hint`, takes one step up
/// the support function in doubles (only to choose where to start; not when `step` is false,
/// for a hint already chosen by support or likely the answer), then walks exactly from region
/// to region; the answer is exact and does not depend on the hint. Expected O(distance walked).
Location locate(const Polytope& P, const ArcPlane* slots, const NormalRef& p, int hint,
                bool step = true);

/// A cap of directions around c (unit, in doubles) where a region's double filter certainly
/// passes on every slot: a direction whose unit normal u (error at most kCapQueryError) has
/// u . c > threshold is then in the region's interior, known from one dot product instead of
/// a test per slot (a walk that stays in its region, the usual one, pays only that). The
/// threshold is 2, beyond any dot product, where the region has no useful cap.
struct RegionCap {
  double x, y, z, threshold;
};
/// The largest unit normal error a cap admits (unit normals of double points are within
/// about 1e-16 of theirs).
inline constexpr double kCapQueryError = 1e-12;
/// Whether the cap certainly contains the direction u (see RegionCap).
inline bool in_cap(const RegionCap& cap, const UnitNormal& u) {
  return u.x * cap.x + u.y * cap.y + u.z * cap.z > cap.threshold && u.error <= kCapQueryError;
}

/// P's slot planes (slot_planes), each region's made when a walk first tests it: for one
/// thread's walks, which then share the making of them with the other threads' instead of
/// waiting for all to be made first. With each region's planes, its RegionCap when `caps`
/// (making one costs about as much as a few region tests: for many walks per region).
class SlotCache {
 public:
  explicit SlotCache(const Polytope& P, bool caps = false);
  bool has_caps() const { return caps_ != nullptr; }
  /// The planes, indexed by slot, those of v's region made.
  const ArcPlane* region(int v) {
    if (!made_[v]) make(v);
    return planes_.get();
  }
  /// v's cap (made with its planes; has_caps() only).
  const RegionCap& cap(int v) {
    if (!made_[v]) make(v);
    return caps_[v];
  }

 private:
  void make(int v);
  const Polytope* P_;
  std::unique_ptr<ArcPlane[]> planes_;
  std::unique_ptr<RegionCap[]> caps_;
  std::vector<unsigned char> made_;
};

/// The cap of v's region (RegionCap) from its slot planes (P's slot_planes, or those of v's
/// region at least).
RegionCap region_cap(const Polytope& P, const ArcPlane* slots, int v);

/// locate, with the slots' planes from a SlotCache.
Location locate(const Polytope& P, SlotCache& slots, const NormalRef& p, int hint,
                bool step = true);

/// A vertex of the feature `loc` (the contributing vertex when it is a vertex region).
inline int location_vertex(const Polytope& P, const Location& loc) {
  switch (loc.kind) {
    case Location::Kind::vertex:
      return loc.index;
    case Location::Kind::edge:
      return P.edges[loc.index].from;
    case Location::Kind::face:
      return P.corner(loc.index, 0);
  }
  return 0;
}

/// Locates every facet normal of `from` in the Gauss map of `in`, in parallel, each walk
/// starting from the previous facet's answer (facets near in index order are usually
/// near on the sphere), or where `hints` says (a vertex of `in` per facet of `from`, chosen
/// by support: the walk then takes no step first; -1: where the previous facet's ended).
std::vector<Location> locate_all(const Polytope& from, const Polytope& in,
                                 const std::vector<int>* hints = nullptr);

/// How the arc (n1, n2) meets the arc (m1, m2) (both shorter than a half circle).
struct ArcContact {
  bool touches = false;  // the closed arcs share a point
  bool crosses = false;  // they cross at a point interior to both
  int side = 0;          // when crossing: sign of det(n1, n2, m2) (where m2 lies)
};
/// s1 and s2 are orient(n1, n2, m1) and orient(n1, n2, m2), which a caller testing many
/// arcs against one computes once per normal; t1 and t2 are orient(m1, m2, n1) and
/// orient(m1, m2, n2), needed only when s1 * s2 <= 0 and not s1 == s2 == 0 (otherwise
/// the arcs' contact follows from s1 and s2 alone, and a caller may pass anything).
/// arc_contact decides the usual cases inline and the rest (the arcs may touch at an end,
/// or lie on one great circle) with arc_contact_general, which decides them all.
ArcContact arc_contact_general(const NormalRef& n1, const NormalRef& n2, const NormalRef& m1,
                               const NormalRef& m2, int s1, int s2, int t1, int t2);
inline ArcContact arc_contact(const NormalRef& n1, const NormalRef& n2, const NormalRef& m1,
                              const NormalRef& m2, int s1, int s2, int t1, int t2) {
  // The usual cases inline: m strictly on one side of n's great circle (no contact), or
  // each arc's ends strictly on both sides of the other's circle.
  ArcContact c;
  if (s1 * s2 > 0) return c;
  if (s1 * s2 < 0 && t1 * t2 != 0) {
    // The great circles meet at +-X; the arcs share X (not -X) iff t1 == -s1.
    if (t1 * t2 < 0) {
      c.touches = c.crosses = t1 == -s1;
      c.side = s2;
    }
    return c;
  }
  return arc_contact_general(n1, n2, m1, m2, s1, s2, t1, t2);
}

/// Whether arc_contact needs t1 and t2 for these s1 and s2.
inline bool arc_contact_needs_t(int s1, int s2) { return s1 * s2 <= 0 && (s1 != 0 || s2 != 0); }

/// An arc of a Gauss map leaving a point, toward the normal `to`, followed
/// counter-clockwise by the region of vertex `after`.
struct Arc {
  NormalRef to;
  int after;
};

/// The arcs of P's Gauss map around a point lying on the given feature, counter-clockwise.
/// A vertex region has none.
void arcs_around(const Polytope& P, const Location& where, std::vector<Arc>& out);

/// The regions around the point `p` after overlaying two maps: x_arcs (non-empty,
/// counter-clockwise) and y_arcs (counter-clockwise, possibly empty, in which case the
/// point lies inside the region y_region). Appends (x vertex, y vertex) pairs,
/// counter-clockwise, one per distinct arc direction. `halves` is scratch.
void overlay_regions(const NormalRef& p, const std::vector<Arc>& x_arcs,
                     const std::vector<Arc>& y_arcs, int y_region,
                     std::vector<std::pair<int, int>>& out, std::vector<int>& halves);

}  // namespace morph::detail
