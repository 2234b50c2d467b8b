// Private: erosion of a convex polytope by a convex element, as an exact intersection of
// half-spaces (each facet plane of A moved inwards by B's support value along its
// normal), and the underlying exact half-space intersection.
#pragma once

#include <morph/morphology.h>

#include <optional>
#include <string>

#include "polytope.h"

namespace morph::detail {

/// A closed half-space { x : <normal, x> <= offset }, exact. `source` is a facet index
/// carried to the result's facet labels.
struct HalfSpace {
  V3<ExactN> normal;  // dyadic: a facet normal of a polytope with double points
  Exact offset;
  int source = -1;
};

/// A polytope, or why there is none.
struct MaybePolytope {
  std::optional<Polytope> polytope;
  EmptyReason reason = EmptyReason::none;
  std::string message;
};

/// The intersection of bounded half-spaces (their normals must positively span space).
/// `hint` is a point that is often strictly inside (checked exactly; an exact linear
/// program finds one otherwise). Empty or flat intersections are reported, not thrown.
MaybePolytope intersect_halfspaces(const std::vector<HalfSpace>& halfspaces, const V3<double>& hint);

/// A (-) B = intersection over facets f of A of { x : <N_f, x> <= h_A(N_f) - h_B(N_f) }.
MaybePolytope erode_polytope(const Polytope& A, const Polytope& B);

}  // namespace morph::detail
