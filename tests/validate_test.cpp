// Verdicts of the operand checks on meshes built here, each good or broken in one known
// way: the expected verdict comes from the construction, not from an earlier run.
#include <doctest/doctest.h>
#include <morph/error.h>
#include <morph/io.h>
#include <morph/structuring_element.h>
#include <morph/validate.h>

#include <cmath>
#include <regex>
#include <string>
#include <vector>

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
