// Private: erosion of a convex polytope by a convex element, as an exact intersection of
// half-spaces (each facet plane of A moved inwards by B's support value along its
// normal), and the underlying exact half-space intersection.
#pragma once

#include <morph/morphology.h>

#include <optional>
#include <string>

#include "polytope.h"

namespace morph::detail {

/// A closed half-space { x : <normal, x> <= offset / denominator }, exact. Dyadic offsets
/// (polytopes with double or dyadic points) have denominator 1; a rational offset p/q is
/// stored as offset p, denominator q. `source` and `element` are carried to the facets of
/// the result for their labels.
struct HalfSpace {
  V3<ExactN> normal;  // dyadic: a facet normal of a polytope; becomes the result facet's normal
  ExactN offset;
  ExactN denominator = ExactN(1);  // positive
  int source = -1;                 // erosion: the facet of A (its label)
  int element = -1;                // erosion: the vertex of B that moved it inwards (its label)
};

/// The half-space <normal, x> <= offset for any rational offset.
HalfSpace make_halfspace(const V3<ExactN>& normal, const Exact& offset, int source);

/// Which hull gave an intersection (for tests and profiling).
enum class HullRoute : unsigned char {
  none,         // empty or flat: no hull
  incremental,  // the exact incremental hull on the planes, checked exactly
  exact,        // CGAL's hull of the exact dual points (its check failed, or it was not tried)
};

/// An intersection as it is written out: its vertices rounded to nearest (from their exact
/// values), and facet cycles counter-clockwise about the outward normal. The same
/// numbering as the polytope's, when there is one.
struct RoundedPolytope {
  std::vector<V3<double>> points;
  std::vector<int> face_begin;     // size F + 1
  std::vector<int> corner_vertex;  // corner k of facet f: corner_vertex[face_begin[f] + k]
  std::vector<int> face_source;    // the `source` of each facet's half-space
  std::vector<int> face_element;   // the `element` of each facet's half-space
};

/// A polytope, or why there is none.
struct MaybePolytope {
  std::optional<Polytope> polytope;  // exact, when IntersectOptions::polytope
  RoundedPolytope rounded;           // whenever the intersection is a solid
  EmptyReason reason = EmptyReason::none;
  std::string message;
  HullRoute route = HullRoute::none;
};

/// Options of intersect_halfspaces.
struct IntersectOptions {
  bool incremental = true;  // false: go straight to the exact hull (tests compare the routes)
  bool polytope = true;     // false: only `rounded` (a final result: no rationals, no Polytope)
};

/// The intersection of bounded half-spaces (their normals must positively span space).
/// `hint` is a point that is often strictly inside (checked exactly; an exact linear
/// program finds one otherwise). Empty or flat intersections are reported, not thrown.
/// The result is exact and canonical (numbered by the half-spaces through each vertex),
/// whichever route computed it. Expected O(n log n) for n half-spaces (exact arithmetic
/// only where interval filters cannot decide).
MaybePolytope intersect_halfspaces(const std::vector<HalfSpace>& halfspaces, const V3<double>& hint,
                                   const IntersectOptions& options = {});

/// A (-) B = intersection over facets f of A of { x : <N_f, x> <= h_A(N_f) - h_B(N_f) }.
MaybePolytope erode_polytope(const Polytope& A, const Polytope& B,
                             const IntersectOptions& options = {});

}  // namespace morph::detail
