// The FIMS kernel: the exact Minkowski sum of two convex polyhedra, built facet by
// facet (Barki, Denis, Dupont, "Contributing vertices-based Minkowski sum computation
// of convex polyhedra", CAD 2009).
#pragma once

#include <morph/mesh.h>

#include <cstdint>
#include <vector>

namespace morph {

/// Which part of an operand an output facet comes from.
struct Element {
  enum class Kind : std::uint8_t { none, vertex, edge, facet };
  Kind kind = Kind::none;
  int index = -1;  // index in the operand mesh (vertex, edge or face index)
};

/// The three kinds of facets of A (+) B.
enum class FacetKind : std::uint8_t {
  translated,  // a facet of A moved by its contributing vertex (or edge/facet) of B
  corner,      // a facet of B placed at a vertex (or edge) of A
  edge,        // a parallelogram: an edge of A (+) an edge of B
};

/// Origin of one output facet: its kind and the elements of A and B whose sum it is.
struct FacetOrigin {
  FacetKind kind = FacetKind::translated;
  Element a;
  Element b;
};

struct MinkowskiOptions {
  int threads = 0;  // 0: all cores; 1: sequential. The result is identical for any value.
};

/// A mesh with the origin of each of its facets (origins[f] for face index f).
struct LabelledMesh {
  Mesh mesh;
  std::vector<FacetOrigin> origins;
};

/// S = A (+) B = { a + b : a in A, b in B } for closed convex polyhedra A and B.
///
/// Preconditions: A and B pass check_convex_polyhedron() (they are validated here;
/// a violation throws invalid_mesh / not_convex naming "A" or "B").
/// Result: a closed, 2-manifold, outward-oriented convex polygon mesh; every vertex is
/// a sum a_i + b_j of input vertices rounded once to double; adjacent coplanar facets are
/// merged, so it equals the convex hull of all vertex sums with its facets as polygons.
/// All combinatorial decisions are exact; vertices are rounded to the nearest double.
/// Corners of a facet closer than 1e-11 of the bounding-box diagonal (features of the
/// exact sum that doubles cannot represent) are merged, as in morphology.h.
/// Output is identical for any thread count.
/// Complexity: O(n_A + n_B + n_S) expected (contributing vertices by walking B's normal
/// graph from a neighbour's answer), parallel over facets, vertices and edges of A.
LabelledMesh minkowski_sum(const Mesh& A, const Mesh& B, const MinkowskiOptions& options = {});

}  // namespace morph
