// The independent oracle for the FIMS kernel and the morphology layer.
//
// Everything here is computed without libmorph: the Minkowski sum as CGAL's exact convex
// hull of all vertex sums, the erosion as an exact intersection of half-spaces (own
// double-description clipping on exact rationals). CGAL stays inside oracle.cpp.
//
// Results are compared through a Description: vertex positions as doubles (exact
// coordinates rounded to nearest, which for a sum a_i + b_j is the IEEE double sum),
// facets as sorted sets of positions, counts and volume.
#pragma once

#include <morph/mesh.h>

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace morph::test {

using Position = std::array<double, 3>;

/// A facet plane in doubles: unit outward normal n and offset d (n.x <= d inside).
struct Plane {
  Position normal{};
  double offset = 0.0;
  bool reliable = true;  // false for a (nearly) zero-area face: its direction is noise
};

/// A convex polyhedron described independently of its mesh data structure.
struct Description {
  std::vector<Position> vertices;             // sorted, one per vertex
  std::vector<std::vector<Position>> facets;  // each sorted, list sorted
  std::vector<Plane> planes;                  // one per facet, same order as `facets`
  std::size_t vertex_count = 0;
  std::size_t edge_count = 0;  // half the sum of facet degrees
  std::size_t facet_count = 0;
  double volume = 0.0;
  bool exact_positions = false;  // oracle only: every vertex coordinate is a double exactly
  std::vector<std::size_t> facet_degrees() const;  // sorted
};

/// The exact Minkowski sum: CGAL convex_hull_3 over all sums a_i + b_j in exact
/// rationals, exactly coplanar adjacent hull triangles grouped into facets, non-extreme
/// points dropped. Volume is the exact volume rounded to double.
Description exact_hull_of_sums(const Mesh& A, const Mesh& B);

/// The same description of a mesh: its vertices, faces (as position sets), counts, and
/// volume (divergence theorem, fan triangulation, in doubles); planes from Newell normals.
Description describe(const Mesh& mesh);

/// An exactly computed set: its dimension, vertices (rounded to nearest, sorted) and,
/// when solid, its description.
struct ExactSet {
  int dimension = -1;              // -1 empty, 0 point, 1 segment, 2 polygon, 3 solid
  std::vector<Position> vertices;  // also for flat results
  Description description;         // when dimension == 3
};

/// The exact erosion A (-) B = intersection over faces f of A of the half-space of f
/// moved inwards by max_b <n_f, b> (own double-description clipping on exact rationals).
/// Plane normals from three vertices of each face, exactly (for an exactly planar face
/// any three give the same plane; for a bent one, the three spanning the largest area).
ExactSet exact_erosion(const Mesh& A, const Mesh& B);

/// The exact opening (A (-) B) (+) B: the hull of the exact erosion's vertices plus B's,
/// rounded once. `dimension` is the erosion's; the description is set when it is 3.
ExactSet exact_opening(const Mesh& A, const Mesh& B);

/// First difference between two descriptions compared exactly (positions, facets as
/// position sets, counts), volume to `volume_rel_tol`; empty when they agree.
std::string compare_exact(const Description& got, const Description& want,
                          double volume_rel_tol = 1e-12);

/// First difference between two convex bodies compared with tolerances: every vertex of
/// each lies within `dist_tol` (absolute) of the other's facet planes, and volumes agree to
/// `volume_rel_tol`. For approximately planar operands, whose exact hulls split facets.
std::string compare_close(const Description& got, const Description& want, double dist_tol,
                          double volume_rel_tol);

/// Largest signed distance of a vertex of `inner` above a facet plane of `outer`
/// (<= 0 when inner's vertices are all inside outer).
double max_excess(const Description& inner, const Description& outer);

/// The first feature of an exact description smaller than `tol` (absolute), or empty: two
/// vertices closer than `tol`, a facet thinner than `tol` (its vertices within `tol` of
/// the line through its two farthest ones), or two facets sharing an edge whose vertices
/// all lie within `tol` of the other's plane. The library merges such features
/// (kFeatureTolerance, docs/algorithm.md), so a result is compared with a description that
/// has any only to within the feature size.
std::string subresolution_feature(const Description& d, double tol);

/// The library's feature size (kFeatureTolerance = 1e-11 of the diagonal) with margin, for
/// finding features of an exact set that it merges; and half of it, for finding features
/// a result must not keep.
inline constexpr double kLibraryFeatureTolerance = 2e-11;
inline constexpr double kResultFeatureTolerance = 0.5e-11;

/// True when every face of the mesh is exactly planar (exact orientation tests).
bool exactly_planar(const Mesh& mesh);

/// Options of the clean-mesh check.
struct CleanOptions {
  /// true: for meshes whose coordinates are exact (integer or grid operands): planarity,
  /// convexity and minimality (no coplanar neighbours, >= 3 face planes at every vertex)
  /// decided exactly.
  /// false: for vertices rounded from exact values: planarity and convexity to
  /// `tolerance` times the bounding-box diagonal; minimality only as "every vertex has
  /// >= 3 faces". Rounding can make nearly coplanar neighbours (legitimate where operands
  /// are nearly degenerate, e.g. a triangulated rotated cube) exactly coplanar, so
  /// minimality of rounded results is decided by comparing facets with the exact oracle.
  bool exact = true;
  double tolerance = 1e-9;  // the library's own acceptance (kPlanarityTolerance)
};

/// The first violation of "clean convex mesh", or empty: closed, 2-manifold, connected,
/// Euler characteristic 2, outward (positive volume), faces with >= 3 distinct vertices
/// and non-zero area, planar, convex, minimal (see CleanOptions), no duplicate vertex
/// positions.
std::string clean_mesh_problem(const Mesh& mesh, const CleanOptions& options = {});

/// The strictest fair check of a result whose exact reference is known: exact when the
/// reference's vertices are all exactly doubles, else to the tolerance.
CleanOptions clean_options_for(const Description& exact_reference);

/// For rounded results without an exact reference.
inline constexpr CleanOptions kRoundedClean{.exact = false};

/// The diagonal of the bounding box.
double bbox_diagonal(const Mesh& mesh);

/// Positions and face vertex lists equal (bit-exact), for "inputs never modified" and
/// determinism checks.
bool identical(const Mesh& a, const Mesh& b);

}  // namespace morph::test
