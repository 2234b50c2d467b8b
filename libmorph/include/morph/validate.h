// Public checks on the operands of libmorph's operations. Every operation requires a
// *convex polyhedron*: a mesh that passes check_convex_polyhedron(). The checks name the
// first offending element in their message.
//
// The convexity rule, stated once:
//   1. the mesh is non-empty, closed (every edge has two faces), 2-manifold (edges and
//      vertices), connected, of genus 0, and every face has >= 3 distinct vertices and
//      non-zero area (its width, twice its area over its longest edge, above 1e-14 D: not
//      collinear up to rounding); its size (bounding-box diagonal) lies in
//      [kMinSize, kMaxSize];
//   2. faces are consistently oriented with outward normals (positive volume);
//   3. every face is planar to within kPlanarityTolerance: each of its vertices lies
//      within kPlanarityTolerance * D of the plane through the face's centroid with the
//      face's Newell normal, D the diagonal of the mesh's bounding box;
//   4. every edge is convex to within the same tolerance: the vertices of each face lie
//      on or below the plane of every neighbouring face, to within kPlanarityTolerance*D.
// A closed surface of genus 0 that is convex at every edge bounds a convex body.
// The tolerance only accepts or rejects input; the kernel's own decisions are exact.
// Every check is linear in the mesh size (the convexity pass is linear in the sum of the
// squared facet degrees) and never throws, except prepare_convex_polyhedron.
#pragma once

#include <morph/mesh.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace morph {

/// Relative tolerance (fraction of the bounding-box diagonal) for planarity and
/// convexity of floating-point meshes. Chosen far above double rounding (1e-16) so that
/// meshes computed in floating point (a UV sphere's quads) pass, and far below any
/// visible feature.
inline constexpr double kPlanarityTolerance = 1e-9;

/// The sizes (bounding-box diagonals) of meshes libmorph accepts: volumes and areas,
/// computed in doubles by the checks, neither underflow nor overflow within this range.
inline constexpr double kMinSize = 1e-80;
inline constexpr double kMaxSize = 1e80;

struct ValidationOptions {
  double planarity_tolerance = kPlanarityTolerance;  // relative to the bbox diagonal
  bool fix_inverted = true;  // a closed mesh oriented inwards everywhere is flipped (with a note)
};

/// A finding of the checks: empty `problem` means the check passed.
struct CheckResult {
  std::string problem;             // first violation, naming the element ("face 12 ...")
  std::vector<std::string> notes;  // things fixed or worth knowing ("orientation was inverted ...")
  bool ok() const { return problem.empty(); }
};

/// Closed and 2-manifold: every edge has exactly two faces, every vertex one fan.
CheckResult check_closed_manifold(const Mesh& mesh);

/// Faces consistently oriented, and outward (positive signed volume).
CheckResult check_outward_oriented(const Mesh& mesh);

/// Faces with >= 3 distinct vertices and non-zero area, finite coordinates, and a size in
/// [kMinSize, kMaxSize].
CheckResult check_nondegenerate(const Mesh& mesh);

/// The full rule above (1-4).
CheckResult check_convex_polyhedron(const Mesh& mesh, const ValidationOptions& options = {});

/// Returns `mesh` ready to be an operand: checks the full rule and, when allowed and
/// needed, flips a fully inverted mesh (notes say so). `name` ("A", a file name) is put
/// in messages. Throws invalid_mesh or not_convex with the first problem.
struct PreparedMesh {
  Mesh mesh;
  std::vector<std::string> notes;
};
PreparedMesh prepare_convex_polyhedron(const Mesh& mesh, std::string_view name,
                                       const ValidationOptions& options = {});

/// Signed volume (positive for outward orientation) by the divergence theorem over a
/// fan triangulation of each face.
double signed_volume(const Mesh& mesh);

}  // namespace morph
