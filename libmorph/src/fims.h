// Private: the FIMS kernel proper, on Polytopes, and the assembly of its output.
#pragma once

#include <morph/minkowski_sum.h>

#include <cstdint>
#include <vector>

#include "polytope.h"

namespace morph::detail {

/// The facets of A (+) B as cycles of vertex pairs (i of A, j of B), counter-clockwise,
/// with their origins; translated facets first (in A's facet order), then corner facets
/// (B's facet order), then edge facets (A's edge order, then B's).
struct SumFacets {
  std::vector<int> face_begin{0};
  std::vector<std::uint64_t> corners;  // (i << 32) | j
  std::vector<FacetOrigin> origins;
  int num_faces() const { return static_cast<int>(face_begin.size()) - 1; }
};

inline std::uint64_t pair_key(int i, int j) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
         static_cast<std::uint32_t>(j);
}
inline int pair_first(std::uint64_t k) { return static_cast<int>(k >> 32); }
inline int pair_second(std::uint64_t k) { return static_cast<int>(k & 0xffffffffu); }

/// Computes the facets of A (+) B. Runs in the calling TBB arena.
SumFacets fims_facets(const Polytope& A, const Polytope& B);

/// The vertices of A (+) B as its facets use them: the distinct pairs (i, j), sorted, and
/// each corner's index among them (sum_mesh and sum_polytope number S's vertices so).
/// Linear in the number of corners: with one thread, each corner's pair is looked up among
/// the few found so far at its vertex of the operand with more vertices, and the pairs are
/// then counting-sorted; with threads (or when a vertex has so many partners that the lists
/// would cost more than a few steps a corner), a counting sort buckets the corners by their
/// vertex of A, and in each bucket only the distinct partners in B are sorted.
void index_vertices(const SumFacets& facets, int num_a, int num_b,
                    std::vector<std::uint64_t>& pairs, std::vector<int>& corners);

/// The rounded result as a mesh: vertex i + j at the correctly rounded sum. Vertices
/// that round to the same point are merged (see docs/algorithm.md, "below double
/// precision"); facets left with fewer than three vertices are dropped.
LabelledMesh sum_mesh(const Polytope& A, const Polytope& B, const SumFacets& facets);
/// The same, taking the facets' origins when each facet is a face of the mesh (no merges).
LabelledMesh sum_mesh(const Polytope& A, const Polytope& B, SumFacets&& facets);

/// The exact result as a polytope (exact vertex sums), for chaining operations.
Polytope sum_polytope(const Polytope& A, const Polytope& B, const SumFacets& facets);

/// Features of an exact result smaller than this fraction of its bounding-box diagonal
/// are below what doubles (and the validation tolerance, kPlanarityTolerance = 1e-9)
/// can represent faithfully: they come from rounding noise in the input, e.g. planes
/// that meet almost, but not exactly, in one point. Edges shorter than this are
/// collapsed in the output. Chosen well below any visible feature and well above the
/// noise of floating-point input (about 1e-15 relative).
inline constexpr double kFeatureTolerance = 1e-11;

/// Builds the output mesh from rounded points and facet cycles of an exact result,
/// merging what lies below kFeatureTolerance times the diagonal: corners of a facet that
/// close (each cluster keeps its lowest-index vertex); adjacent facets coplanar to within
/// it, and needles (facets thinner than it) with a neighbour they lie flat on, into one
/// polygon; vertices left with fewer than three facets around them. When the merged
/// cycles are not a closed manifold of convex polygons, the exact convex hull of the
/// points (exact predicates on the doubles) is grouped the same way instead. Linear in
/// the result's size except in that fallback. `source` (optional) receives, per output
/// face, its facet index (of its largest member when facets merged; -1 for none).
/// `corners` by value: when nothing merges they become the mesh's facets as they are.
Mesh clean_mesh(const std::vector<V3<double>>& points, const std::vector<int>& face_begin,
                std::vector<int> corners, std::vector<int>* source);

/// How many times clean_mesh has rebuilt a result from the hull of its points (for tests:
/// which inputs take that slow path).
long clean_mesh_hull_fallbacks();

}  // namespace morph::detail
