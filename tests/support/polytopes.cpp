// Test operands. Hulls come from the oracle's exact hull (convex_hull_mesh in oracle.cpp).
#include "support/polytopes.h"

#include <cmath>
#include <stdexcept>

namespace morph::test {

Mesh mesh_from_polygons(const std::vector<Point>& points,
                        const std::vector<std::vector<int>>& faces) {
  Mesh mesh;
  std::vector<Mesh::VertexHandle> handles;
  handles.reserve(points.size());
  for (const Point& p : points) handles.push_back(mesh.add_vertex(p));
  for (const auto& face : faces) {
    std::vector<Mesh::VertexHandle> fv;
    for (int i : face) fv.push_back(handles.at(static_cast<std::size_t>(i)));
    if (!mesh.add_face(fv).is_valid())
      throw std::invalid_argument("mesh_from_polygons: face rejected by OpenMesh");
  }
  return mesh;
}

// splitmix64: small, well mixed, and the same on every platform.
Random::Random(std::uint64_t seed) : state_(seed) {}

std::uint64_t Random::next() {
  std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double Random::uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

double Random::uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

int Random::integer(int lo, int hi) {
  return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1));
}

Point Random::on_sphere(double radius) {
  for (;;) {
    const Point p(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    const double n = p.norm();
    if (n > 0.1 && n <= 1.0) return p * (radius / n);
  }
}

Mesh random_sphere_polytope(int n, std::uint64_t seed, double radius) {
  Random rng(seed);
  std::vector<Point> pts;
  for (int i = 0; i < n; ++i) pts.push_back(rng.on_sphere(radius));
  return convex_hull_mesh(pts);
}

Mesh random_cube_polytope(int n, std::uint64_t seed, double half) {
  Random rng(seed);
  std::vector<Point> pts;
  for (int i = 0; i < n; ++i)
    pts.emplace_back(rng.uniform(-half, half), rng.uniform(-half, half), rng.uniform(-half, half));
  return convex_hull_mesh(pts);
}

Mesh random_integer_polytope(int n, std::uint64_t seed, int range) {
  Random rng(seed);
  for (;;) {
    std::vector<Point> pts;
    for (int i = 0; i < n; ++i) {
      pts.emplace_back(rng.integer(-range, range), rng.integer(-range, range),
                       rng.integer(-range, range));
    }
    try {
      return convex_hull_mesh(pts);
    } catch (const std::invalid_argument&) {
      // flat: draw again
    }
  }
}

Mesh random_grid_polytope(int n, std::uint64_t seed) {
  Random rng(seed);
  std::vector<Point> pts;
  for (int i = 0; i < n; ++i) {
    const Point p = rng.on_sphere(1.0);
    pts.emplace_back(std::round(p[0] * 0x1.0p20) * 0x1.0p-20,
                     std::round(p[1] * 0x1.0p20) * 0x1.0p-20,
                     std::round(p[2] * 0x1.0p20) * 0x1.0p-20);
  }
  return convex_hull_mesh(pts);
}

std::vector<double> random_rotation(std::uint64_t seed) {
  Random rng(seed);
  double q[4];
  double len = 0;
  do {
    len = 0;
    for (double& c : q) {
      c = rng.uniform(-1, 1);
      len += c * c;
    }
  } while (len < 0.01 || len > 1.0);
  len = std::sqrt(len);
  for (double& c : q) c /= len;
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

Mesh transformed(const Mesh& mesh, const std::vector<double>& m) {
  Mesh out = mesh;
  for (auto v : out.vertices()) {
    const Point p = mesh.point(v);
    out.set_point(
        v, Point(m[0] * p[0] + m[1] * p[1] + m[2] * p[2], m[3] * p[0] + m[4] * p[1] + m[5] * p[2],
                 m[6] * p[0] + m[7] * p[1] + m[8] * p[2]));
  }
  return out;
}

Mesh box(Point lo, Point hi) {
  std::vector<Point> p;
  for (int c = 0; c < 8; ++c)
    p.emplace_back(c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]);
  // Corner c has bit 0 = x, bit 1 = y, bit 2 = z; faces counter-clockwise from outside.
  return mesh_from_polygons(
      p, {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}});
}

Mesh cube(double edge) {
  return box(Point(-edge / 2, -edge / 2, -edge / 2), Point(edge / 2, edge / 2, edge / 2));
}

Mesh rotated_cube_quads(double edge, std::uint64_t seed) {
  return transformed(cube(edge), random_rotation(seed));
}

Mesh rotated_cube_triangles(double edge, std::uint64_t seed) {
  return convex_hull_mesh(positions(rotated_cube_quads(edge, seed)));
}

Mesh tetrahedron(double s) {
  return mesh_from_polygons({Point(s, s, s), Point(s, -s, -s), Point(-s, s, -s), Point(-s, -s, s)},
                            {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {1, 3, 2}});
}

Mesh octahedron(double r) {
  return mesh_from_polygons(
      {Point(r, 0, 0), Point(-r, 0, 0), Point(0, r, 0), Point(0, -r, 0), Point(0, 0, r),
       Point(0, 0, -r)},
      {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
}

Mesh translated(const Mesh& mesh, Point t) {
  Mesh out = mesh;
  for (auto v : out.vertices()) out.set_point(v, mesh.point(v) + t);
  return out;
}

Mesh scaled(const Mesh& mesh, double s) {
  Mesh out = mesh;
  for (auto v : out.vertices()) out.set_point(v, mesh.point(v) * s);
  return out;
}

Mesh reflected(const Mesh& mesh) {
  std::vector<Point> p;
  for (auto v : mesh.vertices()) p.push_back(-mesh.point(v));
  std::vector<std::vector<int>> faces;
  for (auto f : mesh.faces()) {
    std::vector<int> face;
    for (auto v : mesh.fv_range(f)) face.push_back(v.idx());
    faces.emplace_back(face.rbegin(), face.rend());
  }
  return mesh_from_polygons(p, faces);
}

std::vector<Point> positions(const Mesh& mesh) {
  std::vector<Point> p;
  for (auto v : mesh.vertices()) p.push_back(mesh.point(v));
  return p;
}

}  // namespace morph::test
