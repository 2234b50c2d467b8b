// Test operands: seeded, reproducible convex polytopes as morph::Mesh.
//
// Hulls are computed exactly (CGAL, in polytopes.cpp / oracle.cpp), so a generated hull is
// exactly convex and its polygon faces are exactly planar: coplanar hull triangles are
// merged only when they are exactly coplanar. Meshes built by transforming vertices
// (rotated quads) are only approximately planar; each generator says which it is.
#pragma once

#include <morph/mesh.h>

#include <cstdint>
#include <vector>

namespace morph::test {

/// A mesh from points and faces (vertex index lists, counter-clockwise seen from outside).
Mesh mesh_from_polygons(const std::vector<Point>& points,
                        const std::vector<std::vector<int>>& faces);

/// The convex hull of `points`, with exactly coplanar adjacent hull triangles merged into
/// one polygon and points that are not extreme dropped. Exactly convex and planar.
/// Throws std::invalid_argument when the points do not span a solid.
Mesh convex_hull_mesh(const std::vector<Point>& points);

/// Seeded uniform numbers (own formulas, so streams do not depend on the standard
/// library's distributions).
class Random {
 public:
  explicit Random(std::uint64_t seed);
  double uniform();                      // [0, 1)
  double uniform(double lo, double hi);  // [lo, hi)
  int integer(int lo, int hi);           // [lo, hi]
  Point on_sphere(double radius);        // uniform direction times radius
  std::uint64_t next();

 private:
  std::uint64_t state_;
};

/// Hull of n random points on the sphere of `radius` (almost always simplicial).
Mesh random_sphere_polytope(int n, std::uint64_t seed, double radius = 1.0);

/// Hull of n random points in the cube [-half, half]^3.
Mesh random_cube_polytope(int n, std::uint64_t seed, double half = 1.0);

/// Hull of n random integer points in [-range, range]^3: many exactly coplanar and
/// parallel facets, and every sum, difference and translation by an integer is exact.
/// Retries with new points until the hull is solid.
Mesh random_integer_polytope(int n, std::uint64_t seed, int range = 3);

/// Hull of n random points on a grid of step 2^-20 in [-1, 1]^3: general position in
/// practice, yet sums with other grid meshes and translations by grid vectors are exact.
Mesh random_grid_polytope(int n, std::uint64_t seed);

/// A row-major 3x3 rotation matrix from a seeded uniform random unit quaternion.
std::vector<double> random_rotation(std::uint64_t seed);

/// Every vertex multiplied by the row-major 3x3 matrix `m`; faces kept as they are (so
/// planar polygons become only approximately planar).
Mesh transformed(const Mesh& mesh, const std::vector<double>& m);

/// Axis-aligned box [lo, hi] as 6 quads (exactly planar).
Mesh box(Point lo, Point hi);

/// The cube [-edge/2, edge/2]^3 (exactly planar for dyadic edges).
Mesh cube(double edge);

/// Cube of `edge` centred on the origin, rotated by random_rotation(seed).
/// As 6 quads (approximately planar, as the library accepts them) ...
Mesh rotated_cube_quads(double edge, std::uint64_t seed);
/// ... or as the exact hull of its 8 rotated corners (triangles, exactly convex).
Mesh rotated_cube_triangles(double edge, std::uint64_t seed);

/// The regular tetrahedron with vertices s*(1,1,1), s*(1,-1,-1), s*(-1,1,-1), s*(-1,-1,1).
Mesh tetrahedron(double s = 1.0);

/// The octahedron with vertices +-r on the axes.
Mesh octahedron(double r = 1.0);

/// The mesh translated by t (coordinates rounded; exact for integer or grid meshes and t).
Mesh translated(const Mesh& mesh, Point t);

/// -A: coordinates negated and face orientation reversed (exact).
Mesh reflected(const Mesh& mesh);

/// The mesh scaled by s about the origin (exact for powers of two).
Mesh scaled(const Mesh& mesh, double s);

/// Vertex positions in index order.
std::vector<Point> positions(const Mesh& mesh);

}  // namespace morph::test
