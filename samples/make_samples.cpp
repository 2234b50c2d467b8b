// Writes the sample meshes of samples/ (see README.md there):
//   make-samples <output directory>
// Every mesh is checked with check_convex_polyhedron before it is written, and written
// with 17 significant digits (write_mesh), so the files are exact copies of the doubles.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/convex_hull_3.h>
#include <morph/error.h>
#include <morph/io.h>
#include <morph/structuring_element.h>
#include <morph/validate.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using HullMesh = CGAL::Surface_mesh<Kernel::Point_3>;

// Convex hull of `points` with coplanar neighbouring facets joined into one polygon.
// Coplanarity is decided by CGAL's exact predicate, so only exactly coplanar facets
// (integer-like coordinates) are joined; random points in general position have none.
morph::Mesh convex_hull(const std::vector<morph::Point>& points) {
  std::vector<Kernel::Point_3> input;
  for (const auto& p : points) input.emplace_back(p[0], p[1], p[2]);
  HullMesh hull;
  CGAL::convex_hull_3(input.begin(), input.end(), hull);
  std::vector<HullMesh::Edge_index> edges(hull.edges().begin(), hull.edges().end());
  for (auto e : edges) {
    const auto h = hull.halfedge(e);
    const auto& a = hull.point(hull.source(h));
    const auto& b = hull.point(hull.target(h));
    const auto& c = hull.point(hull.target(hull.next(h)));
    const auto& d = hull.point(hull.target(hull.next(hull.opposite(h))));
    if (CGAL::coplanar(a, b, c, d)) CGAL::Euler::join_face(h, hull);
  }
  hull.collect_garbage();

  // Vertices in input order and faces in a canonical order (smallest index first,
  // sorted), since CGAL may shuffle its input: the files are then reproducible.
  std::map<std::array<double, 3>, int> input_index;
  for (std::size_t i = 0; i < points.size(); ++i)
    input_index.emplace(std::array<double, 3>{points[i][0], points[i][1], points[i][2]},
                        static_cast<int>(i));
  std::map<int, int> used;  // input index -> mesh index
  std::vector<std::vector<int>> faces;
  for (auto f : hull.faces()) {
    std::vector<int> face;
    for (auto v : CGAL::vertices_around_face(hull.halfedge(f), hull)) {
      const auto& p = hull.point(v);
      face.push_back(input_index.at({p.x(), p.y(), p.z()}));
      used[face.back()] = 0;
    }
    std::rotate(face.begin(), std::min_element(face.begin(), face.end()), face.end());
    faces.push_back(std::move(face));
  }
  std::sort(faces.begin(), faces.end());
  morph::Mesh mesh;
  for (auto& [input, index] : used) index = mesh.add_vertex(points[input]).idx();
  for (const auto& face : faces) {
    std::vector<morph::Mesh::VertexHandle> loop;
    for (int i : face) loop.emplace_back(used[i]);
    mesh.add_face(loop);
  }
  return mesh;
}

// `count` points uniform in the unit ball from a fixed seed. mt19937_64's output is
// specified by the standard, and the mapping to [0, 1) is done here, so every platform
// draws the same points.
std::vector<morph::Point> random_points_in_ball(int count, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  const auto uniform = [&] { return static_cast<double>(engine() >> 11) * 0x1p-53 * 2 - 1; };
  std::vector<morph::Point> points;
  while (static_cast<int>(points.size()) < count) {
    const morph::Point p(uniform(), uniform(), uniform());
    if (p.sqrnorm() <= 1) points.push_back(p);
  }
  return points;
}

// Truncated octahedron: all permutations of (0, +-1/2, +-1); edge sqrt(2)/2, volume 4.
std::vector<morph::Point> truncated_octahedron_points() {
  std::vector<morph::Point> points;
  const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& permutation : permutations)
    for (double s : {-1.0, 1.0})
      for (double t : {-1.0, 1.0}) {
        const double values[3] = {0, 0.5 * s, t};
        morph::Point p;
        for (int i = 0; i < 3; ++i) p[permutation[i]] = values[i];
        points.push_back(p);
      }
  return points;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make-samples <output directory>\n";
    return 2;
  }
  const std::filesystem::path directory = argv[1];
  const std::vector<std::pair<std::string, morph::Mesh>> samples = {
      {"cube.off", morph::make_box(1, 1, 1)},
      {"hedra.off", morph::make_octahedron(1)},
      {"tetrahedron.off", morph::make_tetrahedron(1)},
      {"dodecahedron.off", morph::make_dodecahedron(1)},
      {"icosphere_80.off", morph::make_icosphere(1, 1)},
      {"icosphere_320.off", morph::make_icosphere(1, 2)},
      {"icosphere_1280.off", morph::make_icosphere(1, 3)},
      {"icosphere_5120.off", morph::make_icosphere(1, 4)},
      {"uvsphere_1600.off", morph::make_uv_sphere(1, 40)},
      {"snub_dodecahedron.off", morph::make_snub_dodecahedron(1)},
      {"cylinder_16.off", morph::make_cylinder(0.5, 1, 16)},
      {"truncated_octahedron.off", convex_hull(truncated_octahedron_points())},
      {"random_hull_200.off", convex_hull(random_points_in_ball(200, 20240501))},
  };
  try {
    for (const auto& [name, mesh] : samples) {
      const auto check = morph::check_convex_polyhedron(mesh);
      if (!check.ok()) {
        std::cerr << "make-samples: " << name << " is not a convex polyhedron: " << check.problem
                  << '\n';
        return 1;
      }
      morph::write_mesh(mesh, directory / name);
      std::cout << name << ": " << mesh.n_vertices() << " vertices, " << mesh.n_edges()
                << " edges, " << mesh.n_faces() << " faces, volume " << morph::signed_volume(mesh)
                << '\n';
    }
  } catch (const std::exception& error) {
    std::cerr << "make-samples: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
