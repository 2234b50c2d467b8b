// Mathematical morphology of convex polyhedra by a convex structuring element B.
//
// Conventions (as in Serra's and Soille's texts, without reflection in erosion):
//   dilate(A, B) = A (+) B       = { a + b : a in A, b in B }
//   erode(A, B)  = A (-) B       = { x : x + B subset of A }
//   open(A, B)   = (A (-) B) (+) B   (the union of the translates of B inside A)
//   close(A, B)  = (A (+) B) (-) B
// The origin of B is its coordinate origin; parametric elements are centred on it. An
// element that does not contain the origin translates the results accordingly.
//
// Exactness: results are computed exactly (exact predicates and rational coordinates)
// and each vertex is rounded once, to the nearest double. An exact result can contain
// features far below what doubles represent (planes of floating-point facets that meet
// almost, but not exactly, in one point): corners of a facet closer than 1e-11 times the
// result's bounding-box diagonal are merged (keeping one exact vertex), and facets left
// without area are dropped. See docs/algorithm.md, "Features below double precision".
//
// All inputs are taken by const reference and never modified. Inputs must pass
// check_convex_polyhedron(); a violation throws invalid_mesh / not_convex naming "A"
// or "B". Opening and closing chain their two steps on exact values and round once.
#pragma once

#include <morph/mesh.h>
#include <morph/minkowski_sum.h>

#include <string>
#include <vector>

namespace morph {

struct MorphologyOptions {
  int threads = 0;  // 0: all cores; 1: sequential. Results are identical for any value.
};

/// Why a result has no interior.
enum class EmptyReason {
  none,   // the result is a solid (a closed convex mesh)
  empty,  // B fits nowhere inside A: the set is empty
  flat,   // B fits only on a plane, a segment or a point: the set has no interior
};

/// The result of a morphological operation.
struct MorphResult {
  Mesh mesh;  // empty (no vertices) when `empty_reason != none`
  // One per face. Dilation and opening: as minkowski_sum labels them. Erosion: every facet
  // is a facet of A moved inwards by a vertex of B that supports B along its normal
  // (kind translated, a = A's facet, b = B's vertex). Closing: the label of the facet of
  // A (+) B each facet lies on (for a convex A, translated facets of A). Empty when empty.
  std::vector<FacetOrigin> origins;
  EmptyReason empty_reason = EmptyReason::none;
  std::string message;  // why it is empty, for callers and apps to report
  bool is_empty() const { return empty_reason != EmptyReason::none; }
};

/// A (+) B. Complexity O(n_A + n_B + n_out).
MorphResult dilate(const Mesh& A, const Mesh& B, const MorphologyOptions& options = {});

/// A (-) B: A's facet half-spaces, each moved inwards by B's support value along its
/// normal, intersected exactly. Facets of A that vanish are dropped. When B does not
/// fit, the result is empty with `empty_reason` set (not an exception).
MorphResult erode(const Mesh& A, const Mesh& B, const MorphologyOptions& options = {});

/// (A (-) B) (+) B; empty when the erosion is.
MorphResult open(const Mesh& A, const Mesh& B, const MorphologyOptions& options = {});

/// (A (+) B) (-) B; for convex A this is A itself.
MorphResult close(const Mesh& A, const Mesh& B, const MorphologyOptions& options = {});

}  // namespace morph
