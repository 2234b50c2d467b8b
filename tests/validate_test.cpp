// Verdicts of the operand checks on meshes built here, each good or broken in one known
// way: the expected verdict comes from the construction, not from an earlier run.
#include <doctest/doctest.h>
#include <morph/error.h>
#include <morph/io.h>
#include <morph/structuring_element.h>
#include <morph/validate.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "../libmorph/src/validate_detail.h"
#include "support/polytopes.h"

namespace {

using morph::Mesh;
using morph::Point;

// A mesh from points and index loops; `added` counts the faces OpenMesh accepted.
Mesh mesh_of(const std::vector<Point>& points, const std::vector<std::vector<int>>& faces,
             int* added = nullptr) {
  Mesh mesh;
  std::vector<Mesh::VertexHandle> handles;
  for (const auto& p : points) handles.push_back(mesh.add_vertex(p));
  int count = 0;
  for (const auto& face : faces) {
    std::vector<Mesh::VertexHandle> loop;
    for (int i : face) loop.push_back(handles[i]);
    if (mesh.add_face(loop).is_valid()) ++count;
  }
  if (added) *added = count;
  return mesh;
}

// Unit cube [0,1]^3: corner i has coordinates (i&1, i>>1&1, i>>2&1).
std::vector<Point> cube_points(Point offset = {0, 0, 0}) {
  std::vector<Point> points;
  for (int i = 0; i < 8; ++i) points.push_back(Point(i & 1, (i >> 1) & 1, (i >> 2) & 1) + offset);
  return points;
}
const std::vector<std::vector<int>> kCubeQuads = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                                  {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

std::vector<std::vector<int>> reversed(std::vector<std::vector<int>> faces) {
  for (auto& f : faces) std::reverse(f.begin(), f.end());
  return faces;
}

// The cube's quads split into triangles along one diagonal each (all outward).
std::vector<std::vector<int>> cube_triangles() {
  std::vector<std::vector<int>> triangles;
  for (const auto& q : kCubeQuads) {
    triangles.push_back({q[0], q[1], q[2]});
    triangles.push_back({q[0], q[2], q[3]});
  }
  return triangles;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// prepare_convex_polyhedron must reject `mesh` as invalid (not merely non-convex), with
// a message that starts with `expected`.
void check_rejected_as_invalid(const Mesh& mesh, const std::string& expected) {
  try {
    morph::prepare_convex_polyhedron(mesh, "A");
    FAIL("an invalid mesh was accepted");
  } catch (const morph::not_convex& error) {
    FAIL("an invalid mesh was reported as merely not convex: " << error.what());
  } catch (const morph::invalid_mesh& error) {
    CHECK(std::string(error.what()).rfind(expected, 0) == 0);
  }
}

}  // namespace

TEST_CASE("validate: unit cube passes every check, volume 1") {
  const Mesh cube = mesh_of(cube_points(), kCubeQuads);
  CHECK(morph::check_closed_manifold(cube).ok());
  CHECK(morph::check_outward_oriented(cube).ok());
  CHECK(morph::check_nondegenerate(cube).ok());
  CHECK(morph::check_convex_polyhedron(cube).ok());
  CHECK(morph::signed_volume(cube) == doctest::Approx(1.0).epsilon(1e-15));
  const auto prepared = morph::prepare_convex_polyhedron(cube, "A");
  CHECK(prepared.notes.empty());
  CHECK(prepared.mesh.n_faces() == 6);
}

TEST_CASE("validate: triangulated cube is convex (coplanar neighbours are not reflex)") {
  CHECK(morph::check_convex_polyhedron(mesh_of(cube_points(), cube_triangles())).ok());
}

TEST_CASE("validate: open cube (a face removed) is not closed") {
  auto faces = kCubeQuads;
  faces.pop_back();
  const Mesh open = mesh_of(cube_points(), faces);
  const auto result = morph::check_closed_manifold(open);
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.problem, "not closed"));
  CHECK(contains(result.problem, "edge "));
  CHECK_FALSE(morph::check_outward_oriented(open).ok());
  CHECK_FALSE(morph::check_convex_polyhedron(open).ok());
  check_rejected_as_invalid(open, "A: edge ");
}

TEST_CASE("validate: inverted cube is flipped by prepare, with a note") {
  const Mesh inverted = mesh_of(cube_points(), reversed(kCubeQuads));
  CHECK(morph::check_closed_manifold(inverted).ok());
  CHECK(morph::signed_volume(inverted) == doctest::Approx(-1.0).epsilon(1e-15));
  const auto oriented = morph::check_outward_oriented(inverted);
  REQUIRE_FALSE(oriented.ok());
  CHECK(contains(oriented.problem, "inwards"));
  CHECK_FALSE(morph::check_convex_polyhedron(inverted).ok());

  const auto prepared = morph::prepare_convex_polyhedron(inverted, "B");
  REQUIRE(prepared.notes.size() == 1);
  CHECK(contains(prepared.notes[0], "B: orientation was inverted"));
  CHECK(morph::check_convex_polyhedron(prepared.mesh).ok());
  CHECK(morph::signed_volume(prepared.mesh) == doctest::Approx(1.0).epsilon(1e-15));
  CHECK(prepared.mesh.n_faces() == 6);
  CHECK(prepared.mesh.n_vertices() == 8);

  morph::ValidationOptions strict;
  strict.fix_inverted = false;
  CHECK_THROWS_AS(morph::prepare_convex_polyhedron(inverted, "B", strict), morph::invalid_mesh);
}

TEST_CASE("validate: cube with a vertex pushed inwards has a reflex edge") {
  auto points = cube_points();
  points[7] = Point(0.6, 0.6, 0.6);  // corner (1,1,1) pushed towards the centre
  const Mesh dented = mesh_of(points, cube_triangles());
  CHECK(morph::check_closed_manifold(dented).ok());
  CHECK(morph::check_outward_oriented(dented).ok());
  const auto result = morph::check_convex_polyhedron(dented);
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.problem, "is reflex"));
  CHECK_THROWS_AS(morph::prepare_convex_polyhedron(dented, "A"), morph::not_convex);
}

TEST_CASE("validate: L-shaped prism is not convex") {
  // L-shaped hexagon in z=0 (counter-clockwise seen from +z), extruded to z=1.
  const std::vector<Point> l = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  std::vector<Point> points = l;
  for (const auto& p : l) points.push_back(p + Point(0, 0, 1));
  std::vector<std::vector<int>> faces = {{5, 4, 3, 2, 1, 0}, {6, 7, 8, 9, 10, 11}};
  for (int i = 0; i < 6; ++i) faces.push_back({i, (i + 1) % 6, 6 + (i + 1) % 6, 6 + i});
  const Mesh prism = mesh_of(points, faces);
  REQUIRE(morph::check_closed_manifold(prism).ok());
  CHECK(morph::signed_volume(prism) == doctest::Approx(3.0));
  const auto result = morph::check_convex_polyhedron(prism);
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.problem, "is reflex"));
  // every reflex edge touches the inner corner (vertices 3 and 9): the vertical edge
  // there, or a cap edge next to it where the cap turns inwards
  std::smatch edge;
  REQUIRE(std::regex_search(result.problem, edge, std::regex(R"(\(vertices (\d+)-(\d+)\))")));
  const int a = std::stoi(edge[1]), b = std::stoi(edge[2]);
  CHECK((a == 3 || b == 3 || a == 9 || b == 9));
}

TEST_CASE("validate: non-planar quad beyond the tolerance, and within it") {
  auto points = cube_points();
  points[7][2] += 1e-6;  // D ~ sqrt(3): tolerance ~1.7e-9
  const auto result = morph::check_convex_polyhedron(mesh_of(points, kCubeQuads));
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.problem, "is not planar: vertex "));
  CHECK(contains(result.problem, "tolerance 1.7e-09"));
  CHECK_THROWS_AS(morph::prepare_convex_polyhedron(mesh_of(points, kCubeQuads), "A"),
                  morph::not_convex);

  points = cube_points();
  points[7][2] += 1e-12;
  CHECK(morph::check_convex_polyhedron(mesh_of(points, kCubeQuads)).ok());
  morph::ValidationOptions exact;
  exact.planarity_tolerance = 1e-14;
  CHECK_FALSE(morph::check_convex_polyhedron(mesh_of(points, kCubeQuads), exact).ok());
}

TEST_CASE("validate: a zero-area face is degenerate") {
  // Tetrahedron A C D E with edge A-C split at its midpoint B by a flat triangle A C B.
  const std::vector<Point> points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {1, 2, 0}, {1, 1, 2}};
  enum { A, B, C, D, E };
  int added = 0;
  const Mesh mesh =
      mesh_of(points, {{A, D, C}, {A, C, B}, {A, B, C, E}, {C, D, E}, {D, A, E}}, &added);
  REQUIRE(added == 5);
  REQUIRE(morph::check_closed_manifold(mesh).ok());
  const auto result = morph::check_nondegenerate(mesh);
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.problem, "face 1 has zero area"));
  CHECK_FALSE(morph::check_convex_polyhedron(mesh).ok());
  check_rejected_as_invalid(mesh, "A: face 1 has zero area");
  // Off the line by 1e-15, below the width tolerance (1e-14 D): still zero area.
  std::vector<Point> thin = points;
  thin[B] = Point(1, 1e-15, 0);
  const Mesh nearly = mesh_of(thin, {{A, D, C}, {A, C, B}, {A, B, C, E}, {C, D, E}, {D, A, E}});
  CHECK(contains(morph::check_nondegenerate(nearly).problem, "face 1 has zero area"));
}

TEST_CASE("validate: a face that is small but not thin has area") {
  // The unit cube with its corner (1, 1, 1) cut off 2^-24 deep: the cut is a triangle of
  // edge 8.4e-8, twice its area 6.2e-15, below 1e-14 D^2 = 3e-14 but 7.3e-8 wide. It is a
  // proper face (an erosion makes such facets: see morphology_test.cpp).
  const double d = std::ldexp(1.0, -24);
  std::vector<Point> points;
  for (int k = 0; k < 7; ++k) points.emplace_back(k & 1, k >> 1 & 1, k >> 2 & 1);
  points.emplace_back(1, 1, 1 - d);
  points.emplace_back(1, 1 - d, 1);
  points.emplace_back(1 - d, 1, 1);
  const Mesh cut = morph::test::convex_hull_mesh(points);
  REQUIRE(cut.n_faces() == 7);
  CHECK(morph::check_nondegenerate(cut).ok());
  CHECK(morph::check_convex_polyhedron(cut).ok());
  CHECK(morph::prepare_convex_polyhedron(cut, "A").mesh.n_faces() == 7);
}

TEST_CASE("validate: non-finite coordinates are rejected") {
  auto points = cube_points();
  points[3][0] = std::nan("");
  const auto result = morph::check_convex_polyhedron(mesh_of(points, kCubeQuads));
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.problem, "vertex 3 has a coordinate that is not finite"));
}

TEST_CASE("validate: sizes outside [kMinSize, kMaxSize] are rejected with one clear message") {
  for (double scale : {1e-100, 1e-200, 1e100, 1e200}) {
    CAPTURE(scale);
    auto points = cube_points();
    for (auto& p : points) p *= scale;
    const Mesh mesh = mesh_of(points, kCubeQuads);
    const auto result = morph::check_convex_polyhedron(mesh);
    REQUIRE_FALSE(result.ok());
    CHECK(contains(result.problem, "is outside the supported range [1e-80, 1e+80]"));
    check_rejected_as_invalid(mesh, "A: the mesh's size (bounding-box diagonal");
  }
  for (double scale : {1e-70, 1e70}) {  // inside: every check still works
    CAPTURE(scale);
    auto points = cube_points();
    for (auto& p : points) p *= scale;
    CHECK(morph::check_convex_polyhedron(mesh_of(points, kCubeQuads)).ok());
    CHECK(morph::check_convex_polyhedron(mesh_of(points, cube_triangles())).ok());
    points[7] *= 0.9;  // pushed inwards: reflex edges
    CHECK_FALSE(morph::check_convex_polyhedron(mesh_of(points, kCubeQuads)).ok());
  }
}

TEST_CASE("validate: two disjoint cubes are not connected") {
  auto points = cube_points();
  for (const auto& p : cube_points({3, 0, 0})) points.push_back(p);
  auto faces = kCubeQuads;
  for (auto f : kCubeQuads) {
    for (auto& i : f) i += 8;
    faces.push_back(f);
  }
  const auto result = morph::check_closed_manifold(mesh_of(points, faces));
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.problem, "not connected"));
}

TEST_CASE("validate: a polyhedral torus has genus 1") {
  // 4 x 4 quads on a torus of radii 3 and 1 (V = 16, E = 32, F = 16).
  std::vector<Point> points;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double u = M_PI / 2 * i, v = M_PI / 2 * j;
      points.emplace_back((3 + std::cos(v)) * std::cos(u), (3 + std::cos(v)) * std::sin(u),
                          std::sin(v));
    }
  std::vector<std::vector<int>> faces;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      faces.push_back(
          {4 * i + j, 4 * ((i + 1) % 4) + j, 4 * ((i + 1) % 4) + (j + 1) % 4, 4 * i + (j + 1) % 4});
  int added = 0;
  const Mesh torus = mesh_of(points, faces, &added);
  REQUIRE(added == 16);
  const auto result = morph::check_closed_manifold(torus);
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.problem, "genus 1"));
  CHECK(contains(result.problem, "16 - 32 + 16 = 0"));
}

TEST_CASE("validate: two tetrahedra sharing only a vertex are rejected") {
  // OpenMesh cannot close a second fan around vertex 0 (add_face fails), so the pinched
  // mesh is left with a hole; the check reports it.
  const std::vector<Point> points = {{0, 0, 0},  {1, 0, 0},  {0, 1, 0}, {0, 0, 1},
                                     {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  const std::vector<std::vector<int>> faces = {{0, 2, 1}, {0, 4, 5}, {0, 1, 3}, {0, 6, 4},
                                               {0, 3, 2}, {0, 5, 6}, {1, 2, 3}, {4, 6, 5}};
  int added = 0;
  const Mesh pinched = mesh_of(points, faces, &added);
  CHECK(added < 8);
  const auto result = morph::check_closed_manifold(pinched);
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.problem, "not closed"));
}

TEST_CASE("validate: a face deleted (not garbage-collected) leaves the box open") {
  Mesh box = morph::make_box(1, 1, 1);
  REQUIRE(morph::check_convex_polyhedron(box).ok());
  box.delete_face(*box.faces().begin(), false);
  CHECK(contains(morph::check_closed_manifold(box).problem, "not closed"));
  CHECK_THROWS_AS(morph::prepare_convex_polyhedron(box, "A"), morph::invalid_mesh);
}

TEST_CASE("validate: empty mesh and isolated vertex") {
  Mesh empty;
  CHECK(contains(morph::check_closed_manifold(empty).problem, "empty"));
  CHECK_THROWS_AS(morph::prepare_convex_polyhedron(empty, "A"), morph::invalid_mesh);

  Mesh cube = mesh_of(cube_points(), kCubeQuads);
  cube.add_vertex(Point(5, 5, 5));
  CHECK(contains(morph::check_closed_manifold(cube).problem, "vertex 8 is isolated"));
}

TEST_CASE("validate: a flat double-sided square encloses no volume") {
  const Mesh pillow =
      mesh_of({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2, 3}, {3, 2, 1, 0}});
  REQUIRE(morph::check_closed_manifold(pillow).ok());
  const auto result = morph::check_outward_oriented(pillow);
  REQUIRE_FALSE(result.ok());
  CHECK(contains(result.problem, "no volume"));
}

TEST_CASE("validate: a 40 x 40 UV sphere passes (quads planar only up to rounding)") {
  const Mesh sphere = morph::make_uv_sphere(1.0, 40);
  const auto result = morph::check_convex_polyhedron(sphere);
  CHECK_MESSAGE(result.ok(), result.problem);
}

TEST_CASE("validate: a 327,680-triangle icosphere passes and its volume approaches the ball's") {
  const Mesh sphere = morph::make_icosphere(1.0, 7);
  REQUIRE(sphere.n_faces() == 327680);
  const auto result = morph::check_convex_polyhedron(sphere);
  CHECK_MESSAGE(result.ok(), result.problem);
  const double volume = morph::signed_volume(sphere);
  CHECK(volume < 4.0 / 3.0 * M_PI);
  CHECK(volume > 4.0 / 3.0 * M_PI * (1 - 1e-4));
}

// Triangles take a shortcut through the geometric checks (validate.cpp, triangle_passes):
// the general path's arithmetic unrolled. Its verdicts and messages must be the general
// path's, to the last bit of every height: the expected messages below are what the
// general path gave for every face before the shortcut existed. The planarity tolerances
// are tiny on purpose, so that rounding-level heights decide which face is named first.
TEST_CASE("validate: triangle faces keep the general path's verdicts and messages") {
  const auto problem = [](const Mesh& mesh, double tolerance = morph::kPlanarityTolerance) {
    morph::ValidationOptions options;
    options.planarity_tolerance = tolerance;
    return morph::check_convex_polyhedron(mesh, options).problem;
  };
  SUBCASE("rejections of a triangle fall back to the general path's message") {
    auto points = cube_points();
    points[3] = Point(0.5, 0, 0);  // on the edge 0-1: triangle {0, 3, 1} is flat
    CHECK(problem(mesh_of(points, cube_triangles())) ==
          "face 1 has zero area (its vertices are collinear)");
    points[3] = Point(1, 0, 0);  // on vertex 1
    CHECK(problem(mesh_of(points, cube_triangles())) ==
          "face 1 has two vertices at the same position");
  }
  SUBCASE("reflex edges between triangles, and between a triangle and quads") {
    auto points = cube_points();
    points[7] = Point(1, 1, 0.5);  // the top's diagonal 4-7 turns reflex; the sides stay planar
    CHECK(problem(mesh_of(points, cube_triangles())) ==
          "edge 7 (vertices 7-4) is reflex: vertex 6 of face 3 is 0.45 above the plane of face "
          "2 (tolerance 1.7e-09)");
    auto mixed = kCubeQuads;  // only the top split into triangles
    mixed[1] = {4, 5, 7};
    mixed.push_back({4, 7, 6});
    CHECK(problem(mesh_of(points, mixed)) ==
          "edge 6 (vertices 7-4) is reflex: vertex 6 of face 6 is 0.45 above the plane of face "
          "1 (tolerance 1.7e-09)");
  }
  SUBCASE("the heights of nearly planar triangles, bit for bit") {
    const auto sample = [](const char* name) {
      return morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/" + name);
    };
    const Mesh sphere = sample("icosphere_320.off");
    CHECK(problem(sphere, 0) ==
          "face 0 is not planar: vertex 0 is 3.5e-17 from its plane (tolerance 0)");
    CHECK(problem(sphere, 1.0676581484615456e-17) ==
          "face 1 is not planar: vertex 12 is 5.6e-17 from its plane (tolerance 3.7e-17)");
    CHECK(problem(sphere, 2.9457025063071409e-17) ==
          "face 5 is not planar: vertex 13 is 1.2e-16 from its plane (tolerance 1e-16)");
    CHECK(problem(sample("icosphere_5120.off"), 5.7946426834533691e-17) ==
          "face 92 is not planar: vertex 174 is 2.2e-16 from its plane (tolerance 2e-16)");
    CHECK(problem(sample("random_hull_200.off"), 1.7144256780108083e-17) ==
          "face 3 is not planar: vertex 0 is 8.3e-17 from its plane (tolerance 5.6e-17)");
    // The fan volumes: an inverted sphere's signed volume is reported.
    Mesh inverted;
    for (const auto& v : sphere.vertices()) inverted.add_vertex(sphere.point(v));
    for (const auto& f : sphere.faces()) {
      std::vector<Mesh::VertexHandle> loop;
      for (const auto& v : f.vertices()) loop.insert(loop.begin(), v);
      inverted.add_face(loop);
    }
    CHECK(problem(inverted) == "the faces are oriented inwards (signed volume -4 < 0)");
  }
}

namespace {

// Quadrilaterals take a shortcut through the geometric checks as triangles do (validate.cpp,
// quad_passes). Each mesh here is checked with and without the shortcuts (the general path
// alone): same message (or none) to the last digit, and geometry_passes, which make_operand
// uses (on the mesh's own face cycles when it checks beside the build), agrees.
std::string check_quad_paths(const Mesh& mesh, const std::string& what,
                             double tolerance = morph::kPlanarityTolerance) {
  CAPTURE(what);
  CAPTURE(tolerance);
  const std::string fast = morph::detail::convex_polyhedron_problem(mesh, tolerance, true);
  CHECK(fast == morph::detail::convex_polyhedron_problem(mesh, tolerance, false));
  morph::ValidationOptions options;
  options.planarity_tolerance = tolerance;
  CHECK(morph::check_convex_polyhedron(mesh, options).problem == fast);
  CHECK(morph::detail::geometry_passes(mesh, tolerance) == fast.empty());
  return fast;
}

// check_quad_paths on the mesh as given, scaled by 2^200 and 2^-200 (exactly), and shifted far
// from the origin (where the same shape rounds to other heights).
std::string check_quad_variants(const Mesh& mesh, const std::string& what,
                                double tolerance = morph::kPlanarityTolerance) {
  const std::string problem = check_quad_paths(mesh, what, tolerance);
  check_quad_paths(morph::test::scaled(mesh, 0x1p200), what + ", 2^200", tolerance);
  check_quad_paths(morph::test::scaled(mesh, 0x1p-200), what + ", 2^-200", tolerance);
  check_quad_paths(morph::test::translated(mesh, Point(1e6, -3e5, 2e6)), what + ", shifted",
                   tolerance);
  check_quad_paths(morph::test::translated(mesh, Point(0x1p40, 0x1p41, -0x1p40)), what + ", far",
                   tolerance);
  return problem;
}

// The smallest tolerance at which the general path passes `mesh` (which passes at 1e-3), found
// by bisection on the bit patterns of the doubles (passing is monotone in the tolerance); 0
// when it passes at 0. Checking both paths at it and at the double below puts the binding
// height (the largest that some face's planarity or convexity test compares) at the edge of
// its test, where one rounding differently would change the verdict.
double boundary(const Mesh& mesh) {
  const auto passes = [&](std::uint64_t bits) {
    double tolerance;
    std::memcpy(&tolerance, &bits, sizeof tolerance);
    return morph::detail::convex_polyhedron_problem(mesh, tolerance, false).empty();
  };
  std::uint64_t lo = 0, hi;  // the bit patterns of positive doubles order as the values
  const double top = 1e-3;
  std::memcpy(&hi, &top, sizeof hi);
  REQUIRE(passes(hi));
  if (passes(lo)) return 0;
  while (hi - lo > 1) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    (passes(mid) ? hi : lo) = mid;
  }
  double tolerance;
  std::memcpy(&tolerance, &hi, sizeof tolerance);
  return tolerance;
}

// check_quad_paths at the boundary of `mesh` and just below it.
void check_at_boundary(const Mesh& mesh, const std::string& what) {
  const double t = boundary(mesh);
  CHECK(check_quad_paths(mesh, what + " at its boundary", t) == "");
  if (t > 0)
    CHECK(check_quad_paths(mesh, what + " below its boundary", std::nextafter(t, 0.0)) != "");
}

// The mesh with every vertex moved by up to `amount` times its distance from the origin in
// each coordinate (a deterministic pseudo-random pattern).
Mesh jittered(const Mesh& mesh, double amount, std::uint64_t seed) {
  Mesh out = mesh;
  std::uint64_t state = seed * 0x9E3779B97F4A7C15ull + 1;
  const auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) * 0x1p-53 * 2 - 1;  // in [-1, 1)
  };
  for (auto v : out.vertices()) {
    const Point p = out.point(v);
    const double r = p.norm() * amount;
    out.set_point(v, p + Point(next() * r, next() * r, next() * r));
  }
  return out;
}

// A house: a box under a roof of two quads meeting at a ridge of height h (convex above 1,
// flat at 1, reflex below), with pentagonal gables. The ridge is off centre (x = 0.9) and the
// back 1.8 wide rather than 2, so that one corner (vertex 5, the farthest from the ridge) has
// the largest height above the other roof quad's plane: its test alone binds. The roof's quads
// start at corner `left` and `right` of their cycles (so that the ridge ends each in turn).
Mesh house(double h, int left = 0, int right = 0) {
  const std::vector<Point> points = {{0, 0, 0},
                                     {2, 0, 0},
                                     {1.8, 2, 0},
                                     {0, 2, 0},
                                     {0, 0, 1},
                                     {2, 0, 1},
                                     {1.8, 2, h + (1 - h) * (0.9 / 1.1)},
                                     {0, 2, 1},
                                     {0.9, 0, h},
                                     {0.9, 2, h}};
  std::vector<int> roof_left = {4, 8, 9, 7}, roof_right = {8, 5, 6, 9};
  std::rotate(roof_left.begin(), roof_left.begin() + left, roof_left.end());
  std::rotate(roof_right.begin(), roof_right.begin() + right, roof_right.end());
  return mesh_of(points, {{0, 3, 2, 1},
                          {0, 1, 5, 8, 4},
                          {2, 3, 7, 9, 6},
                          {0, 4, 7, 3},
                          {1, 2, 6, 5},
                          roof_left,
                          roof_right});
}

}  // namespace

TEST_CASE("validate: quadrilaterals keep the general path's verdicts and messages") {
  SUBCASE("a UV sphere's nearly planar quads, at tolerances around their heights") {
    const Mesh sphere = morph::make_uv_sphere(1.0, 40);
    check_quad_variants(sphere, "uv sphere");
    check_quad_variants(morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/uvsphere_1600.off"),
                        "uvsphere_1600");
    // From far below the quads' rounding-level heights to above them, in steps that land
    // between the heights of different faces (so that the first face named changes).
    std::set<std::string> problems = {check_quad_paths(sphere, "uv sphere", 0)};
    for (double t = 0x1p-60; t < 0x1p-40; t *= 1.19)
      for (const double s : {1 - 0x1p-40, 1.0, 1 + 0x1p-40})
        problems.insert(check_quad_paths(sphere, "uv sphere", t * s));
    CHECK(problems.count("") == 1);  // the sweep ends above every height
    CHECK(problems.size() > 10);     // and names many faces on its way
  }
  SUBCASE("meshes at the tolerance where their verdict turns") {
    for (std::uint64_t seed = 1; seed <= 12; ++seed) {
      const Mesh sphere = jittered(morph::make_uv_sphere(1.0, 6 + static_cast<int>(seed)),
                                   seed % 2 ? 1e-10 : 1e-14, seed);
      const std::string what = "jittered sphere " + std::to_string(seed);
      check_at_boundary(sphere, what);
      check_at_boundary(morph::test::scaled(sphere, 0x1p200), what + ", 2^200");
      check_at_boundary(morph::test::scaled(sphere, 0x1p-200), what + ", 2^-200");
      check_at_boundary(morph::test::translated(sphere, Point(1e6, -3e5, 2e6)), what + ", shifted");
      check_at_boundary(jittered(mesh_of(cube_points(), kCubeQuads), 1e-11, seed),
                        "jittered cube " + std::to_string(seed));
    }
    // Fine spheres jittered enough for a reflex edge (between quads, mostly) to bind.
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
      const Mesh sphere = jittered(morph::make_uv_sphere(1.0, 100), 3e-5, seed);
      const std::string what = "reflex sphere " + std::to_string(seed);
      check_at_boundary(sphere, what);
      check_at_boundary(morph::test::translated(sphere, Point(1e6, -3e5, 2e6)), what + ", shifted");
    }
    check_at_boundary(morph::make_uv_sphere(1.0, 40), "uv sphere");
    check_at_boundary(morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/uvsphere_1600.off"),
                      "uvsphere_1600");
  }
  SUBCASE("a cube's corner lifted just inside and just outside the tolerance") {
    // A unit square with one corner lifted by d has heights +-d / 4 about its Newell plane;
    // the tolerance is 1e-9 times the diagonal (about sqrt(3)).
    const double threshold = 4 * morph::kPlanarityTolerance * std::sqrt(3.0);
    int passed = 0, failed = 0;
    for (int j = -12; j <= 12; ++j)
      for (const double sign : {1.0, -1.0}) {
        // In steps of one ulp of 1 (a step of the lift changes the heights by a quarter of it).
        std::vector<Point> points = cube_points();
        points[7][2] = (1 + sign * threshold) + j * 0x1p-52;
        const std::string problem = check_quad_variants(
            mesh_of(points, kCubeQuads),
            "lifted by " + std::to_string(sign) + " threshold + " + std::to_string(j) + " ulp");
        ++(problem.empty() ? passed : failed);
      }
    CHECK(passed > 0);  // both verdicts within a few ulps of the threshold
    CHECK(failed > 0);
    for (int k = 20; k <= 40; ++k) {
      std::vector<Point> points = cube_points();
      points[7][2] -= std::ldexp(1.0, -k);
      check_quad_variants(mesh_of(points, kCubeQuads), "lowered by 2^-" + std::to_string(k));
    }
  }
  SUBCASE("reflex and nearly flat edges between quads (a roof's ridge)") {
    std::set<std::string> problems;
    for (int k = 18; k <= 44; ++k)
      for (const double sign : {1.0, -1.0})
        problems.insert(
            check_quad_variants(house(1 + sign * std::ldexp(1.0, -k)),
                                "ridge 1 + " + std::to_string(sign) + " 2^-" + std::to_string(k)));
    CHECK(problems.count("") == 1);  // convex, or flat within the tolerance
    CHECK(problems.size() > 1);      // and reflex beyond it
    // A ridge a hair below flat is reflex beyond a tolerance found by the convexity tests of
    // the roof's quads alone, across each corner's edge in turn.
    for (int left = 0; left < 4; ++left)
      for (int right = 0; right < 4; ++right)
        for (const double h : {1 - 0x1p-30, 1 - 0x1p-33 * 3}) {
          const Mesh roof = house(h, left, right);
          const std::string what = "ridge " + std::to_string(h) + " from corners " +
                                   std::to_string(left) + ", " + std::to_string(right);
          check_at_boundary(roof, what);
          check_at_boundary(morph::test::translated(roof, Point(1e6, -3e5, 2e6)),
                            what + " shifted");
        }
    check_quad_variants(house(1), "flat roof");
    check_quad_variants(house(1.5), "convex roof");
    check_quad_variants(house(0.5), "reflex roof");
    CHECK(contains(morph::check_convex_polyhedron(house(0.5)).problem, "is reflex"));
  }
  SUBCASE("non-convex, degenerate and pinched quads") {
    std::vector<Point> dart = cube_points();
    dart[7] = Point(0.4, 0.4, 1);  // the top quad turns non-convex (its sides bend)
    check_quad_variants(mesh_of(dart, kCubeQuads), "dart");
    dart[7] = Point(0.5, 0.5, 1);  // on the top's diagonal 5-6: a straight corner
    check_quad_variants(mesh_of(dart, kCubeQuads), "on the diagonal");
    std::vector<Point> pinched = cube_points();
    pinched[7] = pinched[6];  // two corners of the top at one position
    check_quad_variants(mesh_of(pinched, kCubeQuads), "two corners at one position");
    CHECK(morph::check_convex_polyhedron(mesh_of(pinched, kCubeQuads)).problem ==
          "face 1 has two vertices at the same position");
    std::vector<Point> dented = cube_points();
    dented[7] = Point(0.9, 0.9, 0.9);  // a corner pushed in: reflex edges, bent quads
    check_quad_variants(mesh_of(dented, kCubeQuads), "dented");
    std::vector<Point> flat = cube_points();
    for (auto& p : flat) p[2] = 0;
    check_quad_variants(mesh_of(flat, kCubeQuads), "flat");
    check_quad_variants(mesh_of(cube_points(), reversed(kCubeQuads)), "inverted");
  }
  SUBCASE("quads whose corners' x coordinates all differ, or not") {
    // quad_corners_distinct() passes a quad with four different x coordinates at once and tests
    // the others in full: the cube above takes the second way, a sheared cube (no two corners
    // with one x) the first, and its pinched and dented variants either.
    const auto sheared = [](std::vector<Point> points) {
      for (auto& p : points) p[0] += 0.25 * p[1] + 0.625 * p[2];
      return points;
    };
    CHECK(check_quad_variants(mesh_of(sheared(cube_points()), kCubeQuads), "sheared").empty());
    std::vector<Point> pinched = cube_points();
    pinched[7] = pinched[6];
    CHECK(check_quad_variants(mesh_of(sheared(pinched), kCubeQuads), "sheared, pinched") ==
          "face 1 has two vertices at the same position");
    std::vector<Point> dented = cube_points();
    dented[7] = Point(0.9, 0.9, 0.9);
    check_quad_variants(mesh_of(sheared(dented), kCubeQuads), "sheared, dented");
  }
}

// nondegenerate() plans two triangles, or two quadrilaterals, at once where they follow each
// other (validate.cpp, triangle_planes and quad_planes: one face in each lane), and one at a
// time otherwise. Either way each face's values must be its own: the verdicts and messages are
// those of the general path on every sequence of triangles and quadrilaterals, at the tolerance
// where the verdict turns, and with two corners at one position in either lane of a pair.
TEST_CASE("validate: faces planed two at a time keep the general path's verdicts") {
  SUBCASE("every mix of the cube's quads and their halves, in two alignments of the pairs") {
    for (int split = 0; split < 64; ++split)
      for (const int shift : {0, 1}) {
        std::vector<std::vector<int>> faces;
        for (int q = 0; q < 6; ++q) {
          const std::vector<int>& quad = kCubeQuads[q];
          if (split >> q & 1) {
            faces.push_back({quad[0], quad[1], quad[2]});
            faces.push_back({quad[0], quad[2], quad[3]});
          } else {
            faces.push_back(quad);
          }
        }
        std::rotate(faces.begin(), faces.begin() + shift, faces.end());
        const std::string what =
            "split " + std::to_string(split) + ", shifted by " + std::to_string(shift);
        const Mesh cube = jittered(mesh_of(cube_points(), faces), 1e-11, split + 1);
        check_at_boundary(cube, what);
        // A reflex corner: the edges around it bind in faces of both kinds.
        std::vector<Point> dented = cube_points();
        dented[7] = Point(0.9, 0.9, 0.9);
        CHECK(check_quad_variants(mesh_of(dented, faces), what + ", dented") != "");
      }
  }
  SUBCASE("two corners at one position, in the first or the second face of a pair") {
    for (int v = 0; v < 8; ++v)
      for (int w = 0; w < 8; ++w) {
        if (v == w) continue;
        std::vector<Point> pinched = cube_points();
        pinched[v] = pinched[w];
        const std::string what = "vertex " + std::to_string(v) + " on " + std::to_string(w);
        CHECK(check_quad_variants(mesh_of(pinched, kCubeQuads), what + ", quads") != "");
        CHECK(check_quad_variants(mesh_of(pinched, cube_triangles()), what + ", triangles") != "");
      }
  }
}
