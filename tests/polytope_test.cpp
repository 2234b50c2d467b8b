// Tests of the kernel's operand polytopes (libmorph/src/polytope.cpp): the linear path
// straight from the mesh's halfedges against the general path through the canonical merge
// of facet cycles, and the labels checked against the mesh itself.
#include "../libmorph/src/polytope.h"

#include <doctest/doctest.h>
#include <morph/error.h>
#include <morph/io.h>
#include <morph/validate.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "../libmorph/src/validate_detail.h"
#include "support/polytopes.h"

namespace {

/// f(mesh, file name) for every .off file of the samples.
template <class F>
void for_each_sample(const F& f) {
  for (const auto& entry : std::filesystem::directory_iterator(MORPH_SAMPLES_DIR))
    if (entry.path().extension() == ".off")
      f(morph::read_mesh(entry.path().string()), entry.path().filename().string());
}

using morph::Mesh;
using morph::Point;
using morph::detail::FaceOrder;
using morph::detail::Polytope;

// The first difference between two polytopes (every array, labels and unit normals),
// or "" when they are the same.
std::string difference(const Polytope& a, const Polytope& b) {
  const auto same_points = [](const auto& x, const auto& y) {
    return x.size() == y.size() &&
           std::equal(x.begin(), x.end(), y.begin(), [](const auto& p, const auto& q) {
             return p.x == q.x && p.y == q.y && p.z == q.z;
           });
  };
  if (!same_points(a.points, b.points)) return "points";
  if (a.face_begin != b.face_begin) return "face_begin";
  if (a.corner_vertex != b.corner_vertex) return "corner_vertex";
  if (a.corner_edge != b.corner_edge) return "corner_edge";
  if (!std::equal(a.edges.begin(), a.edges.end(), b.edges.begin(), b.edges.end(),
                  [](const Polytope::Edge& x, const Polytope::Edge& y) {
                    return x.from == y.from && x.to == y.to && x.left == y.left &&
                           x.right == y.right;
                  }))
    return "edges";
  if (a.fan_begin != b.fan_begin || a.fan_face != b.fan_face || a.fan_edge != b.fan_edge ||
      a.fan_vertex != b.fan_vertex)
    return "fans";
  if (a.vertex_source != b.vertex_source) return "vertex_source";
  if (a.face_source != b.face_source) return "face_source";
  if (a.edge_source != b.edge_source) return "edge_source";
  for (int f = 0; f < a.num_faces(); ++f) {
    const auto &n = a.unit_normals[f], &m = b.unit_normals[f];
    if (n.x != m.x || n.y != m.y || n.z != m.z || n.error != m.error) return "normals";
  }
  return "";
}

double diagonal(const Mesh& mesh) {
  Point lo = mesh.point(*mesh.vertices().begin()), hi = lo;
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  return (hi - lo).norm();
}

// What is wrong with the labels of `p` as a polytope of `mesh` (facets reversed when
// `order` says so), or "": every vertex is the mesh vertex it names; every facet's named
// face lies in the facet's plane and faces the same way; every edge's named mesh edge
// starts at one end of the polytope edge and runs along it.
std::string labels_problem(const Polytope& p, const Mesh& mesh, FaceOrder order) {
  const double tolerance = 1e-9 * diagonal(mesh);
  const auto at = [&](int v) { return Point(p.points[v].x, p.points[v].y, p.points[v].z); };
  for (int v = 0; v < p.num_vertices(); ++v) {
    const int s = p.vertex_source[v];
    if (s < 0 || s >= static_cast<int>(mesh.n_vertices()) ||
        mesh.status(mesh.vertex_handle(s)).deleted() || mesh.point(mesh.vertex_handle(s)) != at(v))
      return "vertex " + std::to_string(v) + " is labelled " + std::to_string(s);
  }
  for (int f = 0; f < p.num_faces(); ++f) {
    Point normal(0, 0, 0);
    for (int k = 0; k < p.degree(f); ++k)
      normal += OpenMesh::cross(at(p.corner(f, k)), at(p.corner(f, (k + 1) % p.degree(f))));
    normal.normalize();
    const auto face = mesh.face_handle(p.face_source[f]);
    Point face_normal(0, 0, 0);
    std::vector<Point> corners;
    for (auto v : mesh.fv_range(face)) corners.push_back(mesh.point(v));
    for (std::size_t k = 0; k < corners.size(); ++k)
      face_normal += OpenMesh::cross(corners[k], corners[(k + 1) % corners.size()]);
    if (order == FaceOrder::reversed) face_normal = -face_normal;
    if (!(OpenMesh::dot(normal, face_normal) > 0))
      return "facet " + std::to_string(f) + " is labelled with a face turned the other way";
    for (const Point& q : corners)
      if (!(std::abs(OpenMesh::dot(q - at(p.corner(f, 0)), normal)) <= tolerance))
        return "facet " + std::to_string(f) + " is labelled with a face off its plane";
  }
  for (int e = 0; e < p.num_edges(); ++e) {
    const int s = p.edge_source[e];
    if (s < 0) return "edge " + std::to_string(e) + " has no label";
    const auto h = mesh.halfedge_handle(mesh.edge_handle(s), 0);
    std::set<int> ends = {mesh.from_vertex_handle(h).idx(), mesh.to_vertex_handle(h).idx()};
    const int from = p.vertex_source[p.edges[e].from], to = p.vertex_source[p.edges[e].to];
    if (ends == std::set<int>{from, to}) continue;
    // An edge spanning removed vertices: its label starts at `from` and runs towards `to`.
    if (!ends.count(from))
      return "edge " + std::to_string(e) + " is labelled with an edge away from its start";
    const int other = *ends.begin() == from ? *ends.rbegin() : *ends.begin();
    const Point d = at(p.edges[e].to) - at(p.edges[e].from);
    const Point q = mesh.point(mesh.vertex_handle(other)) - at(p.edges[e].from);
    if (!(OpenMesh::cross(d, q).norm() <= tolerance * d.norm() && OpenMesh::dot(d, q) > 0))
      return "edge " + std::to_string(e) + " is labelled with an edge off its line";
  }
  return "";
}

// The mesh with every face reversed (an inverted operand).
Mesh inverted(const Mesh& mesh) {
  std::vector<std::vector<int>> faces;
  for (auto f : mesh.faces()) {
    std::vector<int> cycle;
    for (auto v : mesh.fv_range(f)) cycle.push_back(v.idx());
    std::reverse(cycle.begin(), cycle.end());
    faces.push_back(cycle);
  }
  return morph::test::mesh_from_polygons(morph::test::positions(mesh), faces);
}

// The mesh with every face split into a fan of triangles (coplanar neighbours).
Mesh triangulated(const Mesh& mesh) {
  std::vector<std::vector<int>> faces;
  for (auto f : mesh.faces()) {
    std::vector<int> cycle;
    for (auto v : mesh.fv_range(f)) cycle.push_back(v.idx());
    for (std::size_t k = 1; k + 1 < cycle.size(); ++k)
      faces.push_back({cycle[0], cycle[k], cycle[k + 1]});
  }
  return morph::test::mesh_from_polygons(morph::test::positions(mesh), faces);
}

// Both paths on `mesh` as given and on its inverse, and the labels.
void check_both_paths(const Mesh& mesh, const std::string& what) {
  CAPTURE(what);
  const Polytope fast = morph::detail::make_polytope(mesh, "A");
  const Polytope general = morph::detail::make_polytope_from_cycles(mesh, "A");
  CHECK(difference(fast, general) == "");
  CHECK(labels_problem(fast, mesh, FaceOrder::as_given) == "");
  const Mesh inverse = inverted(mesh);
  const Polytope fast_inverse = morph::detail::make_polytope(inverse, "A", FaceOrder::reversed);
  const Polytope general_inverse =
      morph::detail::make_polytope_from_cycles(inverse, "A", FaceOrder::reversed);
  CHECK(difference(fast_inverse, general_inverse) == "");
  CHECK(labels_problem(fast_inverse, inverse, FaceOrder::reversed) == "");
  CHECK(difference(morph::detail::make_operand(inverse, "A"), fast_inverse) == "");
  CHECK(fast_inverse.num_faces() == fast.num_faces());
  CHECK(fast_inverse.num_edges() == fast.num_edges());
  CHECK(morph::signed_volume(morph::detail::to_mesh(fast_inverse)) > 0);
}

}  // namespace

TEST_CASE("polytope: the halfedge path and the cycle path agree on the samples") {
  for_each_sample([](const Mesh& mesh, const std::string& name) {
    check_both_paths(mesh, name);
    check_both_paths(morph::test::transformed(mesh, morph::test::random_rotation(11)),
                     name + " rotated");
  });
}

TEST_CASE("polytope: generated operands, with and without coplanar neighbours") {
  check_both_paths(morph::test::cube(2.0), "cube");
  check_both_paths(triangulated(morph::test::cube(2.0)), "triangulated cube");
  check_both_paths(morph::test::rotated_cube_quads(1.0, 3), "rotated cube quads");
  check_both_paths(morph::test::rotated_cube_triangles(1.0, 3), "rotated cube triangles");
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    check_both_paths(morph::test::random_sphere_polytope(60, seed),
                     "sphere " + std::to_string(seed));
    const Mesh integer = morph::test::random_integer_polytope(40, seed);
    check_both_paths(integer, "integer " + std::to_string(seed));
    check_both_paths(triangulated(integer), "triangulated integer " + std::to_string(seed));
  }
}

TEST_CASE("polytope: coplanar triangles are merged into the facets of the polygon mesh") {
  const Mesh integer = morph::test::random_integer_polytope(40, 5);
  const Mesh triangles = triangulated(integer);
  REQUIRE(triangles.n_faces() > integer.n_faces());
  const Polytope merged = morph::detail::make_operand(triangles, "A");
  const Polytope polygons = morph::detail::make_operand(integer, "A");
  CHECK(merged.num_faces() == polygons.num_faces());
  CHECK(merged.num_edges() == polygons.num_edges());
  CHECK(merged.num_vertices() == polygons.num_vertices());
  CHECK(labels_problem(merged, triangles, FaceOrder::as_given) == "");
}

TEST_CASE("polytope: a vertex in the middle of an edge is removed, its edge labelled") {
  // The unit cube with vertex 8 halfway along the edge 0-1, in both faces at that edge.
  std::vector<Point> points;
  for (int i = 0; i < 8; ++i) points.push_back(Point(i & 1, (i >> 1) & 1, (i >> 2) & 1));
  points.push_back(Point(0.5, 0, 0));
  const Mesh mesh = morph::test::mesh_from_polygons(
      points,
      {{0, 2, 3, 1, 8}, {4, 5, 7, 6}, {0, 8, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}});
  REQUIRE(morph::check_convex_polyhedron(mesh).ok());
  const Polytope p = morph::detail::make_operand(mesh, "A");
  CHECK(p.num_vertices() == 8);
  CHECK(p.num_faces() == 6);
  CHECK(p.num_edges() == 12);
  CHECK(std::count(p.vertex_source.begin(), p.vertex_source.end(), 8) == 0);
  CHECK(labels_problem(p, mesh, FaceOrder::as_given) == "");
  check_both_paths(mesh, "cube with an edge midpoint");
}

TEST_CASE("polytope: labels name the live elements of a mesh with deleted ones") {
  // A deleted vertex first, so that every live index is off by one from a dense count.
  Mesh mesh;
  const auto gone = mesh.add_vertex(Point(5, 5, 5));
  std::vector<Mesh::VertexHandle> v;
  for (int i = 0; i < 8; ++i)
    v.push_back(mesh.add_vertex(Point(i & 1, (i >> 1) & 1, (i >> 2) & 1)));
  for (const auto& q : std::vector<std::vector<int>>{
           {0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}})
    mesh.add_face({v[q[0]], v[q[1]], v[q[2]], v[q[3]]});
  mesh.delete_vertex(gone);
  REQUIRE(morph::check_convex_polyhedron(mesh).ok());
  const Polytope p = morph::detail::make_operand(mesh, "A");
  CHECK(p.num_vertices() == 8);
  CHECK(p.num_faces() == 6);
  CHECK(labels_problem(p, mesh, FaceOrder::as_given) == "");
}

TEST_CASE("polytope: make_operand keeps the messages of prepare_convex_polyhedron") {
  const Mesh open = morph::test::mesh_from_polygons(morph::test::positions(morph::test::cube(2.0)),
                                                    {{0, 1, 2}, {0, 2, 3}});
  std::string expected;
  try {
    morph::prepare_convex_polyhedron(open, "A");
  } catch (const morph::invalid_mesh& error) {
    expected = error.what();
  }
  REQUIRE(!expected.empty());
  try {
    morph::detail::make_operand(open, "A");
    FAIL("an open mesh was accepted");
  } catch (const morph::invalid_mesh& error) {
    CHECK(std::string(error.what()) == expected);
  }
}

TEST_CASE("polytope: make_operand, which builds while it checks, keeps the check's verdict") {
  // Meshes whose halfedges the speculative build reads before the check rejects them (or,
  // inverted, accepts them reversed; or, open, the build stops at): the check's error or fix
  // must win, with one thread or two.
  const Mesh cube = morph::test::cube(2.0);
  const std::vector<Point> corners = morph::test::positions(cube);
  std::vector<std::vector<int>> quads, triangles, reversed;
  for (auto f : cube.faces()) {
    std::vector<int> q;
    for (auto v : f.vertices()) q.push_back(v.idx());
    quads.push_back(q);
    triangles.push_back({q[0], q[1], q[2]});
    triangles.push_back({q[0], q[2], q[3]});
  }
  for (const auto& t : triangles) reversed.push_back({t[2], t[1], t[0]});
  const std::vector<std::vector<int>> open(triangles.begin(), triangles.end() - 2);  // a hole
  std::vector<Point> dented = corners, bent = corners, flat = corners;
  dented[0] *= 0.5;               // a reflex corner
  bent[0] *= 1.01;                // non-planar quads
  for (auto& q : flat) q[2] = 0;  // encloses no volume
  const std::vector<Mesh> meshes = {morph::test::mesh_from_polygons(dented, triangles),
                                    morph::test::mesh_from_polygons(bent, quads),
                                    morph::test::mesh_from_polygons(flat, triangles),
                                    morph::test::mesh_from_polygons(dented, reversed),
                                    morph::test::mesh_from_polygons(corners, reversed),
                                    morph::test::mesh_from_polygons(corners, open)};
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    CAPTURE(i);
    std::string expected;
    try {
      morph::prepare_convex_polyhedron(meshes[i], "A");
    } catch (const std::exception& error) {
      expected = error.what();
    }
    CHECK((expected == "") == (i == 4));
    for (int threads : {1, 2}) {
      CAPTURE(threads);
      tbb::task_arena arena(threads);
      arena.execute([&] {
        try {
          const Polytope p = morph::detail::make_operand(meshes[i], "A");
          CHECK(expected == "");  // the inverted cube, built reversed
          CHECK(difference(p, morph::detail::make_polytope(meshes[i], "A", FaceOrder::reversed)) ==
                "");
        } catch (const std::exception& error) {
          CHECK(std::string(error.what()) == expected);
        }
      });
    }
  }
}

namespace {

// make_operand, which checks and builds a mesh that passes as it is in one pass over its
// halfedges (with the check's topology read off the build's walks), must give what the
// check followed by the build gives: the check's message, or else the build's polytope
// (of the reversed mesh when the check flips it) or error.
void check_operand_agrees(const Mesh& mesh, const std::string& what) {
  CAPTURE(what);
  std::string expected;
  Polytope reference;
  try {
    const bool flipped = !morph::prepare_convex_polyhedron(mesh, "A").notes.empty();
    reference = morph::detail::make_polytope(mesh, "A",
                                             flipped ? FaceOrder::reversed : FaceOrder::as_given);
  } catch (const std::exception& error) {
    expected = error.what();
  }
  try {
    const Polytope p = morph::detail::make_operand(mesh, "A");
    CHECK(expected == "");
    CHECK(difference(p, reference) == "");
  } catch (const std::exception& error) {
    CHECK(std::string(error.what()) == expected);
  }
}

// The unit cube [0,1]^3 (corner i at (i&1, i>>1&1, i>>2&1)) in quads, and in triangles.
const std::vector<std::vector<int>> kQuads = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                              {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

std::vector<std::vector<int>> split_quads() {
  std::vector<std::vector<int>> triangles;
  for (const auto& q : kQuads) {
    triangles.push_back({q[0], q[1], q[2]});
    triangles.push_back({q[0], q[2], q[3]});
  }
  return triangles;
}

std::vector<Point> unit_cube_points() {
  std::vector<Point> points;
  for (int i = 0; i < 8; ++i) points.push_back(Point(i & 1, (i >> 1) & 1, (i >> 2) & 1));
  return points;
}

}  // namespace

TEST_CASE("polytope: make_operand's one-pass check gives the check's verdicts") {
  const std::vector<Point> cube = unit_cube_points();
  SUBCASE("topology: disconnected, genus 1, open, isolated vertex, deleted face, empty") {
    std::vector<Point> two = cube;
    std::vector<std::vector<int>> faces = kQuads;
    for (const auto& p : cube) two.push_back(p + Point(3, 0, 0));
    for (auto f : kQuads) {
      for (int& i : f) i += 8;
      faces.push_back(f);
    }
    check_operand_agrees(morph::test::mesh_from_polygons(two, faces), "two cubes");
    std::vector<Point> ring;  // 4 x 4 quads on a torus of radii 3 and 1
    std::vector<std::vector<int>> torus;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const double u = M_PI / 2 * i, v = M_PI / 2 * j;
        ring.emplace_back((3 + std::cos(v)) * std::cos(u), (3 + std::cos(v)) * std::sin(u),
                          std::sin(v));
        torus.push_back({4 * i + j, 4 * ((i + 1) % 4) + j, 4 * ((i + 1) % 4) + (j + 1) % 4,
                         4 * i + (j + 1) % 4});
      }
    check_operand_agrees(morph::test::mesh_from_polygons(ring, torus), "torus");
    const std::vector<std::vector<int>> open(kQuads.begin(), kQuads.end() - 1);
    check_operand_agrees(morph::test::mesh_from_polygons(cube, open), "open box");
    Mesh lonely = morph::test::mesh_from_polygons(cube, kQuads);
    lonely.add_vertex(Point(5, 5, 5));
    check_operand_agrees(lonely, "isolated vertex");
    Mesh deleted = morph::test::mesh_from_polygons(cube, kQuads);
    deleted.delete_face(*deleted.faces().begin(), false);
    check_operand_agrees(deleted, "deleted face");
    check_operand_agrees(Mesh(), "empty");
    // Two tetrahedra sharing a vertex: OpenMesh refuses the face that would close the
    // second fan, leaving it open.
    Mesh bow;
    std::vector<Mesh::VertexHandle> v;
    for (const Point& p : std::vector<Point>{
             {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}})
      v.push_back(bow.add_vertex(p));
    for (const auto& t : std::vector<std::vector<int>>{{0, 2, 1},
                                                       {0, 4, 5},
                                                       {0, 1, 3},
                                                       {0, 6, 4},
                                                       {0, 3, 2},
                                                       {0, 5, 6},
                                                       {1, 2, 3},
                                                       {4, 6, 5}})
      bow.add_face(v[t[0]], v[t[1]], v[t[2]]);
    check_operand_agrees(bow, "bow tie");
  }
  SUBCASE("topology: connectivity proven by smaller neighbours, or searched") {
    // An octahedron, its vertex at +x, -x, +y, -y, +z, -z in the order `axis` gives: with -x
    // second, vertex 1 has no neighbour of smaller index (the search decides); with +y second,
    // every vertex but 0 has one (connected without a search).
    const auto octahedron = [](const std::vector<int>& axis) {
      std::vector<Point> points(6);
      for (int a = 0; a < 6; ++a) {
        Point q(0, 0, 0);
        q[a / 2] = a % 2 == 0 ? 1 : -1;
        points[axis[a]] = q;
      }
      std::vector<std::vector<int>> faces;
      for (int octant = 0; octant < 8; ++octant) {
        const int x = axis[octant & 1], y = axis[2 + (octant >> 1 & 1)],
                  z = axis[4 + (octant >> 2 & 1)];
        // Outward: (x, y, z) turns counter-clockwise seen from the octant when it has an even
        // number of negative axes.
        if (__builtin_popcount(octant) % 2 == 0)
          faces.push_back({x, y, z});
        else
          faces.push_back({x, z, y});
      }
      return morph::test::mesh_from_polygons(points, faces);
    };
    check_operand_agrees(octahedron({0, 1, 2, 3, 4, 5}), "octahedron, -x second");
    check_operand_agrees(octahedron({0, 2, 1, 3, 4, 5}), "octahedron, +y second");
    const Polytope searched = morph::detail::make_operand(octahedron({0, 1, 2, 3, 4, 5}), "A");
    const Polytope proven = morph::detail::make_operand(octahedron({0, 2, 1, 3, 4, 5}), "A");
    CHECK(searched.num_faces() == 8);
    CHECK(proven.num_faces() == 8);
    // A tetrahedron beside a torus: V - E + F = 2 but not connected (no numbering proves it).
    std::vector<Point> points = {{10, 0, 0}, {11, 0, 0}, {10, 1, 0}, {10, 0, 1}};
    std::vector<std::vector<int>> faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const double u = M_PI / 2 * i, v = M_PI / 2 * j;
        points.emplace_back((3 + std::cos(v)) * std::cos(u), (3 + std::cos(v)) * std::sin(u),
                            std::sin(v));
        faces.push_back({4 + 4 * i + j, 4 + 4 * ((i + 1) % 4) + j,
                         4 + 4 * ((i + 1) % 4) + (j + 1) % 4, 4 + 4 * i + (j + 1) % 4});
      }
    const Mesh apart = morph::test::mesh_from_polygons(points, faces);
    CHECK(static_cast<int>(apart.n_vertices()) - static_cast<int>(apart.n_edges()) +
              static_cast<int>(apart.n_faces()) ==
          2);
    check_operand_agrees(apart, "tetrahedron and torus");
    std::string message;
    try {
      morph::detail::make_operand(apart, "A");
    } catch (const std::exception& error) {
      message = error.what();
    }
    CHECK(message.find("not connected") != std::string::npos);
  }
  SUBCASE("geometry: flat, inverted, non-finite, out of range") {
    std::vector<Point> flat = cube;
    for (auto& p : flat) p[2] = 0;
    check_operand_agrees(morph::test::mesh_from_polygons(flat, split_quads()), "flat");
    std::vector<std::vector<int>> inside_out;
    for (const auto& t : split_quads()) inside_out.push_back({t[2], t[1], t[0]});
    check_operand_agrees(morph::test::mesh_from_polygons(cube, inside_out), "inverted");
    std::vector<Point> nan = cube;
    nan[3][1] = std::nan("");
    check_operand_agrees(morph::test::mesh_from_polygons(nan, kQuads), "not finite");
    for (const double s : {1e-81, 1e81, 0x1p-200, 0x1p200})
      check_operand_agrees(morph::test::scaled(morph::test::mesh_from_polygons(cube, kQuads), s),
                           "scaled " + std::to_string(s));
  }
  SUBCASE("near the tolerance: bent quads and triangles, dents and ridges") {
    // Vertex 7 (a corner of three quads) moved along z by +-2^-k: the quads bend out of
    // plane (rejected beyond the tolerance), the triangles' edges turn reflex or convex;
    // the range spans the tolerance (1e-9 of the diagonal) both ways.
    for (int k = 20; k <= 40; ++k)
      for (const double sign : {1.0, -1.0}) {
        std::vector<Point> bent = cube;
        bent[7][2] += sign * std::ldexp(1.0, -k);
        const std::string what = "2^-" + std::to_string(k) + (sign > 0 ? " out" : " in");
        check_operand_agrees(morph::test::mesh_from_polygons(bent, kQuads), "quads " + what);
        check_operand_agrees(morph::test::mesh_from_polygons(bent, split_quads()),
                             "triangles " + what);
        // Far from the origin the same bends round to other heights.
        check_operand_agrees(
            morph::test::translated(morph::test::mesh_from_polygons(bent, split_quads()),
                                    Point(1e6, -3e5, 2e6)),
            "shifted triangles " + what);
      }
  }
  SUBCASE("a mesh large enough to check beside the build, with one thread or two") {
    const Mesh sphere = morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/icosphere_1280.off");
    REQUIRE(sphere.n_faces() >= 1000);
    for (int threads : {1, 2}) {
      CAPTURE(threads);
      tbb::task_arena arena(threads);
      arena.execute([&] {
        check_operand_agrees(sphere, "sphere");
        for (const double s : {0.9, 1 - 1e-12, 1 + 1e-12, 1.1}) {
          Mesh bent = sphere;
          bent.set_point(Mesh::VertexHandle(0), sphere.point(Mesh::VertexHandle(0)) * s);
          check_operand_agrees(bent, "vertex 0 scaled by " + std::to_string(s));
        }
      });
    }
  }
  SUBCASE("random polytopes, scaled and shifted") {
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
      const Mesh sphere = morph::test::random_sphere_polytope(80, seed);
      check_operand_agrees(sphere, "sphere");
      check_operand_agrees(morph::test::scaled(sphere, 0x1p-200), "sphere 2^-200");
      check_operand_agrees(morph::test::scaled(sphere, 0x1p200), "sphere 2^200");
      check_operand_agrees(morph::test::translated(sphere, Point(1e9, 0, -1e9)), "far sphere");
      check_operand_agrees(morph::test::random_integer_polytope(40, seed), "integer");
    }
  }
}

namespace {

// The unit cube in triangles with vertex 0 moved by eps along -z: its bottom quad 0-2-3-1,
// split along 0-3, bends outwards along 0-3 (a strictly convex ridge) for eps > 0, inwards (a
// valley) for eps < 0; the side faces stay in their planes.
Mesh bent_cube(double eps) {
  std::vector<Point> points;
  for (int i = 0; i < 8; ++i) points.push_back(Point(i & 1, (i >> 1) & 1, (i >> 2) & 1));
  points[0][2] = -eps;
  std::vector<std::vector<int>> triangles;
  for (const auto& q : std::vector<std::vector<int>>{
           {0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}}) {
    triangles.push_back({q[0], q[1], q[2]});
    triangles.push_back({q[0], q[2], q[3]});
  }
  return morph::test::mesh_from_polygons(points, triangles);
}

}  // namespace

TEST_CASE("polytope: two triangles a hair from coplanar stay apart when convex, merge when not") {
  // The unit cube in triangles; its bottom quad 0-2-3-1 (z = 0) is split along 0-3. Moving
  // vertex 0 by eps along -z keeps its side faces in their planes and bends the bottom
  // along 0-3: outwards (eps > 0) a strictly convex ridge, so the bottom stays two facets;
  // inwards (eps < 0) a valley, merged into one facet (convex within the tolerance). The
  // larger bend is decided in double, the smaller one needs the exact fallback.
  for (const double eps : {0x1p-45, 0x1p-60, -0x1p-45, -0x1p-60}) {
    CAPTURE(eps);
    const Mesh mesh = bent_cube(eps);
    REQUIRE(morph::check_convex_polyhedron(mesh).ok());
    const Polytope p = morph::detail::make_operand(mesh, "A");
    CHECK(p.num_faces() == (eps > 0 ? 7 : 6));
    CHECK(p.num_vertices() == 8);
    check_both_paths(mesh, "bent cube");
  }
}

namespace {

// The box [0, 2] x [0, 1] x [-1, 0] with its top split into two quadrilaterals along x = 1, that
// edge (vertices 5 and 8) raised by eps (at z = 0, so that a tiny eps is kept): the front and
// back stay planar pentagons.
Mesh bent_box(double eps) {
  const std::vector<Point> points = {
      Point(0, 0, -1),  Point(2, 0, -1), Point(2, 1, -1), Point(0, 1, -1),  Point(0, 0, 0),
      Point(1, 0, eps), Point(2, 0, 0),  Point(0, 1, 0),  Point(1, 1, eps), Point(2, 1, 0)};
  return morph::test::mesh_from_polygons(points, {{0, 3, 2, 1},
                                                  {0, 1, 6, 5, 4},
                                                  {3, 7, 8, 9, 2},
                                                  {0, 4, 7, 3},
                                                  {1, 2, 9, 6},
                                                  {4, 5, 8, 7},
                                                  {5, 6, 9, 8}});
}

}  // namespace

TEST_CASE(
    "polytope: two quadrilaterals a hair from coplanar stay apart when convex, merge when not") {
  // finish_from_halfedges tests a quadrilateral's edges and turns on the unit normals, two
  // corners at once, and leaves what they do not decide to is_canonical and check_gauss_map: a
  // ridge (eps > 0) stays two facets, a valley (eps < 0, convex within the tolerance) is merged
  // and its two vertices removed, whichever stage decides.
  for (const double eps : {0x1p-20, 0x1p-45, 0x1p-60, 0.0, -0x1p-45, -0x1p-60}) {
    CAPTURE(eps);
    const Mesh mesh = bent_box(eps);
    REQUIRE(morph::check_convex_polyhedron(mesh).ok());
    const Polytope p = morph::detail::make_operand(mesh, "A");
    CHECK(p.num_faces() == (eps > 0 ? 7 : 6));
    CHECK(p.num_vertices() == (eps > 0 ? 10 : 8));
    check_both_paths(mesh, "bent box");
  }
}

namespace {

// make_operand's check proves every edge of a triangle mesh strictly convex from the heights of
// its reflex test (validate.cpp, StrictBelow), and the build then skips is_canonical()'s test of
// the edges: the proof must hold exactly whenever it is given, and never be given for a flat
// or reflex edge. Whether geometry_passes gives it, on the mesh's own face cycles.
struct FastGeometry {
  bool passes, complete, convex;
};
FastGeometry fast_geometry(const Mesh& mesh) {
  std::vector<int> begin{0}, vertex, across;
  for (auto f : mesh.faces()) {
    const auto h0 = mesh.halfedge_handle(f);
    auto h = h0;
    do {
      vertex.push_back(mesh.to_vertex_handle(h).idx());
      across.push_back(mesh.face_handle(mesh.opposite_halfedge_handle(h)).idx());
      h = mesh.next_halfedge_handle(h);
    } while (h != h0);
    begin.push_back(static_cast<int>(vertex.size()));
  }
  std::vector<morph::detail::UnitNormal> unit(mesh.n_faces());
  FastGeometry g{false, false, false};
  g.passes = morph::detail::geometry_passes(mesh, {begin.data(), vertex.data(), across.data()},
                                            unit.data(), g.complete, g.convex);
  return g;
}

bool edges_proven(const Mesh& mesh) {
  const FastGeometry g = fast_geometry(mesh);
  return g.passes && g.complete && g.convex;
}

// geometry_passes' verdict with the unit normals (make_operand's sequential check, with the
// proof of the edges and its shortcuts).
bool geometry_check_passes(const Mesh& mesh) { return fast_geometry(mesh).passes; }

// Whether every edge of a triangle mesh is strictly convex, decided exactly as is_canonical()
// defines it: det(N_left, N_right, to - from) > 0 for the exact normals of the two triangles.
bool exactly_strictly_convex(const Mesh& mesh) {
  using morph::detail::ExactN;
  using morph::detail::V3;
  const auto exact = [&](Mesh::VertexHandle v) {
    const Point& q = mesh.point(v);
    return V3<ExactN>{ExactN(q[0]), ExactN(q[1]), ExactN(q[2])};
  };
  const auto normal = [&](Mesh::FaceHandle f) {
    std::vector<V3<ExactN>> c;
    for (auto v : mesh.fv_range(f)) c.push_back(exact(v));
    REQUIRE(c.size() == 3);
    return morph::detail::cross(c[1] - c[0], c[2] - c[0]);
  };
  for (auto h : mesh.halfedges()) {
    const V3<ExactN> d = exact(mesh.to_vertex_handle(h)) - exact(mesh.from_vertex_handle(h));
    const auto left = mesh.face_handle(h),
               right = mesh.face_handle(mesh.opposite_halfedge_handle(h));
    if (CGAL::sign(morph::detail::det(normal(left), normal(right), d)) != CGAL::POSITIVE)
      return false;
  }
  return true;
}

enum class Proof { given, not_given, either };

void check_edge_proof(const Mesh& mesh, const std::string& what, Proof expected) {
  CAPTURE(what);
  const bool proven = edges_proven(mesh);
  if (expected != Proof::either) CHECK(proven == (expected == Proof::given));
  if (proven) CHECK(exactly_strictly_convex(mesh));
  check_both_paths(mesh, what);
}

}  // namespace

TEST_CASE("polytope: the operand check proves edges strictly convex only when they are") {
  const Mesh sphere = morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/icosphere_1280.off");
  check_edge_proof(sphere, "icosphere", Proof::given);
  // (Scaled far from 1, the check leaves the unit normals to compute_normals: no proof.)
  check_edge_proof(morph::test::scaled(sphere, 0x1p-200), "icosphere 2^-200", Proof::either);
  check_edge_proof(morph::test::scaled(sphere, 0x1p200), "icosphere 2^200", Proof::either);
  check_edge_proof(morph::test::transformed(sphere, morph::test::random_rotation(3)),
                   "icosphere rotated", Proof::given);
  // Far from the origin the heights round more coarsely (the bound grows with the coordinates).
  for (const double far : {1e6, 1e9, 1e12}) {
    CAPTURE(far);
    const Mesh moved = morph::test::translated(sphere, Point(far, 0, -far));
    if (edges_proven(moved)) CHECK(exactly_strictly_convex(moved));
  }
  // Coplanar triangles (a flat edge) and the bent cube's valley: never proven.
  check_edge_proof(triangulated(morph::test::cube(2.0)), "triangulated cube", Proof::not_given);
  // (The ridge of eps = 2^-60 is strictly convex, too shallow for the heights to tell.)
  for (const double eps : {-0x1p-45, -0x1p-60, 0x1p-60}) {
    CAPTURE(eps);
    check_edge_proof(bent_cube(eps), "bent cube", eps < 0 ? Proof::not_given : Proof::either);
  }
  // A quadrilateral anywhere: left to is_canonical.
  check_edge_proof(morph::test::cube(2.0), "cube", Proof::not_given);
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const Mesh random = morph::test::random_sphere_polytope(60, seed);
    const bool proven = edges_proven(random);
    if (proven) CHECK(exactly_strictly_convex(random));
    check_both_paths(random, "sphere " + std::to_string(seed));
  }
}

TEST_CASE("polytope: the check's shortcut past proven edges keeps its verdict near the tolerance") {
  // While every edge so far is proven strictly convex, a triangle skips the reflex test of an
  // edge to an earlier triangle (which proved it). Each vertex moved to c + t (p - c), c the
  // centroid of its neighbours and t = +-2^-k, lies a hair above or below them: its edges turn
  // slightly convex or reflex, across the tolerance both ways (on irregular triangles too), and
  // geometry_passes' verdict must be the full check's.
  std::vector<std::pair<Mesh, std::string>> meshes;
  meshes.emplace_back(morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/icosphere_80.off"),
                      "icosphere");
  for (std::uint64_t seed = 1; seed <= 2; ++seed)
    meshes.emplace_back(morph::test::random_sphere_polytope(30, seed),
                        "sphere " + std::to_string(seed));
  int rejected = 0, accepted = 0;
  for (const auto& [mesh, name] : meshes) {
    for (auto f : mesh.faces()) REQUIRE(mesh.valence(f) == 3);
    REQUIRE(edges_proven(mesh));
    for (auto v : mesh.vertices())
      for (int k = 8; k <= 40; ++k)
        for (const double sign : {1.0, -1.0, 1.4, -1.4}) {
          Point c(0, 0, 0);
          int n = 0;
          for (auto w : mesh.vv_range(v)) c += mesh.point(w), ++n;
          c /= n;
          Mesh moved = mesh;
          moved.set_point(v, c + (mesh.point(v) - c) * (sign * std::ldexp(1.0, -k)));
          CAPTURE(name);
          CAPTURE(v.idx());
          CAPTURE(k);
          CAPTURE(sign);
          const bool expected = morph::check_convex_polyhedron(moved).ok();
          CHECK(geometry_check_passes(moved) == expected);
          (expected ? accepted : rejected) += 1;
        }
  }
  // One reflex edge, told by one side only: the base of a pyramid folded along its diagonal A-C
  // by lowering B (outwards) by delta; the far corner D lies five times as far from A-C as B, so
  // the test from triangle ACB sees D 5 delta above its plane, the test from ADC sees B delta
  // above: with delta below the tolerance (about 4.4e-9 here) and 5 delta above it, only ACB's
  // test rejects the mesh, whichever of the two triangles comes first.
  for (const double delta : {0.4e-9, 1e-9, 2e-9, 3e-9, 6e-9}) {
    const std::vector<Point> points = {
        {0, 0, 0}, {1, 0, -delta}, {1, 1, 0}, {-2, 3, 0}, {0, 1.2, 1}};
    const std::vector<int> acb = {0, 2, 1}, adc = {0, 3, 2};
    const std::vector<std::vector<int>> sides = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
    for (const bool acb_first : {false, true}) {
      std::vector<std::vector<int>> faces = {acb_first ? acb : adc, acb_first ? adc : acb};
      faces.insert(faces.end(), sides.begin(), sides.end());
      const Mesh pyramid = morph::test::mesh_from_polygons(points, faces);
      CAPTURE(delta);
      CAPTURE(acb_first);
      const bool expected = morph::check_convex_polyhedron(pyramid).ok();
      CHECK(geometry_check_passes(pyramid) == expected);
      (expected ? accepted : rejected) += 1;
    }
  }
  CHECK(rejected > 0);  // both verdicts occur: the comparison is not vacuous
  CHECK(accepted > 0);
}

TEST_CASE("polytope: the check skips a triangle's own planarity heights only when it may") {
  // A triangle skips the planarity test of its own corners when StrictBelow's bound on their
  // heights (zero exactly) is within the tolerance. Far from the origin the heights round more
  // coarsely than the tolerance of a small mesh, and the test rejects it as not planar: the
  // bound grows with the coordinates, so the skip must not hide that, nor anything else.
  const Mesh sphere = morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/icosphere_80.off");
  int rejected = 0, accepted = 0, not_planar = 0;
  for (const double scale : {1.0, 1e-3}) {
    for (int k = 0; k <= 52; k += 4) {
      const double far = k == 0 ? 0.0 : std::ldexp(1.0, k);
      const Mesh moved =
          morph::test::translated(morph::test::scaled(sphere, scale), Point(far, -far / 3, far));
      CAPTURE(scale);
      CAPTURE(k);
      const std::string problem = morph::check_convex_polyhedron(moved).problem;
      CHECK(geometry_check_passes(moved) == problem.empty());
      (problem.empty() ? accepted : rejected) += 1;
      if (problem.find("is not planar") != std::string::npos) not_planar += 1;
    }
  }
  CHECK(accepted > 0);  // both verdicts occur, the rejection by the planarity test among them
  CHECK(not_planar > 0);
  CHECK(rejected >= not_planar);
}

namespace {

// Whether unit normal u lies within u.error of the direction of the exact normal n, decided
// exactly: |u - n/|n||^2 <= e^2 <=> 2 u.n >= s |n| with s = |u|^2 + 1 - e^2 (u, e doubles).
bool within_error(const morph::detail::UnitNormal& u,
                  const morph::detail::V3<morph::detail::ExactN>& n) {
  using morph::detail::ExactN;
  if (!std::isfinite(u.error)) return true;
  const ExactN x(u.x), y(u.y), z(u.z), e(u.error);
  const ExactN un = x * n.x + y * n.y + z * n.z;
  const ExactN s = x * x + y * y + z * z + ExactN(1) - e * e;
  const ExactN nn = n.x * n.x + n.y * n.y + n.z * n.z;
  const ExactN lhs = ExactN(4) * un * un, rhs = s * s * nn;
  const int su = CGAL::sign(un), ss = CGAL::sign(s);
  if (ss <= 0) return su >= 0 || CGAL::sign(lhs - rhs) <= 0;
  return su > 0 && CGAL::sign(lhs - rhs) >= 0;
}

void check_unit_normals(const Mesh& mesh, const std::string& what) {
  CAPTURE(what);
  const Polytope p = morph::detail::make_polytope(mesh, "A");
  for (int f = 0; f < p.num_faces(); ++f) {
    CAPTURE(f);
    const auto& u = p.unit_normals[f];
    CHECK(within_error(u, p.exact_normal(f)));
    CHECK(u.error < 1e-12);  // the bound is tight enough to decide well-shaped facets
  }
}

}  // namespace

TEST_CASE("polytope: unit normals lie within their error bounds of the exact directions") {
  for_each_sample([&](const Mesh& mesh, const std::string& name) {
    check_unit_normals(mesh, name);
    check_unit_normals(morph::test::transformed(mesh, morph::test::random_rotation(5)),
                       name + " rotated");
    check_unit_normals(morph::test::scaled(mesh, 0x1p-200), name + " tiny");
    check_unit_normals(morph::test::scaled(mesh, 0x1p200), name + " huge");
  });
  // Far from the origin the Newell sum cancels a lot: the bound must follow.
  const Mesh sphere = morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/icosphere_1280.off");
  check_unit_normals(morph::test::translated(sphere, Point(1e6, -3e5, 7)), "far sphere");
}

TEST_CASE("polytope: a within_error oracle that can fail") {
  const morph::detail::V3<morph::detail::ExactN> n{1, 0, 0};
  CHECK(within_error({1, 0, 0, 0}, n));
  CHECK(within_error({1, 1e-10, 0, 1.1e-10}, n));
  CHECK_FALSE(within_error({1, 1e-10, 0, 0.9e-10}, n));
  CHECK_FALSE(within_error({-1, 0, 0, 1.9}, n));
}

namespace {

// make_operand's checked path takes its unit normals from the operand check's planes: they must
// be compute_normals()'s (the same values whichever path builds the polytope), each within its
// bound of the exact direction.
void check_operand_normals(const Mesh& mesh, const std::string& what) {
  CAPTURE(what);
  tbb::task_arena one(1);  // the checked path in sequence: the check's normals
  Polytope p;
  one.execute([&] { p = morph::detail::make_operand(mesh, "A"); });
  const Polytope general = morph::detail::make_polytope(mesh, "A");
  CHECK(difference(p, general) == "");
  for (int f = 0; f < p.num_faces(); ++f) {
    CAPTURE(f);
    CHECK(within_error(p.unit_normals[f], p.exact_normal(f)));
  }
}

}  // namespace

TEST_CASE("polytope: make_operand's unit normals from the check are compute_normals'") {
  for_each_sample([&](const Mesh& mesh, const std::string& name) {
    check_operand_normals(mesh, name);
    check_operand_normals(morph::test::transformed(mesh, morph::test::random_rotation(7)),
                          name + " rotated");
    // Tiny and huge: Newell sums outside centroid_unit_normal()'s range (the check then
    // leaves the normals to compute_normals()).
    check_operand_normals(morph::test::scaled(mesh, 0x1p-200), name + " tiny");
    check_operand_normals(morph::test::scaled(mesh, 0x1p200), name + " huge");
    check_operand_normals(morph::test::translated(mesh, Point(1e6, -3e5, 7)), name + " far");
  });
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    check_operand_normals(morph::test::random_sphere_polytope(300, seed),
                          "sphere " + std::to_string(seed));
    check_operand_normals(morph::test::rotated_cube_quads(2.0, seed),
                          "quads " + std::to_string(seed));
  }
  // Slivers: a triangle and a quadrilateral barely above the check's zero area (1e-14 D^2),
  // where the bound is wide, each also scaled by 2^+-200 and shifted far.
  for (const double thin : {3e-14, 1e-13, 1e-9}) {
    const std::vector<Point> tet = {{0, 0, 0}, {1, 0, 0}, {0.5, thin, 0}, {0.4, 0.3, 1}};
    const Mesh sliver =
        morph::test::mesh_from_polygons(tet, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}});
    const std::vector<Point> wedge = {
        {0, 0, 0}, {1, 0, 0}, {1, thin, 0}, {0, thin, 0}, {0.5, 0.2, 1}};
    const Mesh flat_quad = morph::test::mesh_from_polygons(
        wedge, {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}});
    for (const Mesh* m : {&sliver, &flat_quad}) {
      const std::string what = (m == &sliver ? "sliver " : "thin quad ") + std::to_string(thin);
      check_operand_normals(*m, what);
      check_operand_normals(morph::test::scaled(*m, 0x1p-200), what + " tiny");
      check_operand_normals(morph::test::scaled(*m, 0x1p200), what + " huge");
      // (Not the thin quadrilateral, whose sides are needles that a shift's rounding makes
      // non-planar; nor so far that it rounds the sliver's width much.)
      const double far = thin < 1e-10 ? 1 : 1e3;
      if (m == &sliver)
        check_operand_normals(morph::test::translated(*m, Point(far, -far, far)), what + " far");
    }
  }
}

namespace {

// The exact sign of det(N_left, N_right, to - from) of edge e (double points).
int exact_edge_convexity(const Polytope& p, int e) {
  const auto& edge = p.edges[e];
  return CGAL::sign(det(p.exact_normal(edge.left), p.exact_normal(edge.right),
                        morph::detail::exact_difference(p.points[edge.to], p.points[edge.from])));
}

// check_gauss_map skips the turns through three triangles once every edge is strictly convex:
// here every such turn of `mesh`'s polytope, with its two edges, is evaluated exactly.
void check_triangle_turns(const Mesh& mesh, const std::string& what) {
  CAPTURE(what);
  const Polytope p = morph::detail::make_operand(mesh, "A");
  int turns = 0;
  for (int v = 0; v < p.num_vertices(); ++v) {
    const int b = p.fan_begin[v], n = p.fan_begin[v + 1] - b;
    for (int i = 0; i < n; ++i) {
      const int fa = p.fan_face[b + i], fb = p.fan_face[b + (i + 1) % n],
                fc = p.fan_face[b + (i + 2) % n];
      if (p.degree(fa) != 3 || p.degree(fb) != 3 || p.degree(fc) != 3) continue;
      // Slot s is the edge between fan_face[s] and fan_face[s + 1].
      CHECK(exact_edge_convexity(p, p.fan_edge[b + i]) > 0);
      CHECK(exact_edge_convexity(p, p.fan_edge[b + (i + 1) % n]) > 0);
      CHECK(CGAL::sign(det(p.exact_normal(fa), p.exact_normal(fb), p.exact_normal(fc))) > 0);
      ++turns;
    }
  }
  CHECK(turns > 0);
}

}  // namespace

TEST_CASE("polytope: a turn through three triangles is the product of its two edges' signs") {
  // The identity behind the skip, exactly: for triangles (v, u0, u1), (v, u1, u2), (v, u2, u3)
  // with d_i = u_i - v, det(d0 x d1, d1 x d2, d2 x d3) = det(d0, d1, d2) det(d1, d2, d3), and
  // the edge v-u1 (between the first two; its left facet holds v -> u1) has
  // det(N_left, N_right, u1 - v) = -det(d0, d1, d2) |d1|^2. Points nearly degenerate, scaled
  // by 2^+-200 and far from the origin.
  using morph::detail::ExactN;
  using morph::detail::V3;
  std::uint64_t state = 12345;
  const auto next = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1p-53 - 0.5;
  };
  int negative = 0, positive = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const double scale = trial % 4 == 0 ? 0x1p-200 : trial % 4 == 1 ? 0x1p200 : 1.0;
    const double shift = trial % 4 == 2 ? 1e9 : 0.0;
    const double flat = trial % 8 < 4 ? 1e-13 : 1.0;  // the u_i nearly coplanar with v
    V3<double> q[5];
    for (int k = 0; k < 5; ++k) {
      const double angle = 1.2 * k + 0.3 * next();
      q[k] = {(std::cos(angle) + shift) * scale, (std::sin(angle) + shift) * scale,
              (k == 0 ? 0.0 : flat * next() + shift) * scale};
    }
    q[0] = {shift * scale, shift * scale, shift * scale};  // v
    V3<ExactN> d[4];
    for (int k = 0; k < 4; ++k) d[k] = morph::detail::exact_difference(q[k + 1], q[0]);
    const V3<ExactN> na = cross(d[0], d[1]), nb = cross(d[1], d[2]), nc = cross(d[2], d[3]);
    const ExactN turn = det(na, nb, nc);
    CHECK(CGAL::sign(turn - det(d[0], d[1], d[2]) * det(d[1], d[2], d[3])) == CGAL::ZERO);
    // Triangle (v, u1, u2) holds v -> u1: it is the edge's left facet, (v, u0, u1) its right.
    CHECK(CGAL::sign(det(nb, na, d[1]) + det(d[0], d[1], d[2]) * dot(d[1], d[1])) == CGAL::ZERO);
    (CGAL::sign(turn) < 0 ? negative : positive) += 1;
  }
  CHECK(negative > 0);  // the random fans turn both ways: the identity is not vacuous
  CHECK(positive > 0);
}

TEST_CASE("polytope: every turn through three triangles of an operand is strictly convex") {
  for (const char* name : {"icosphere_80.off", "icosphere_1280.off", "random_hull_200.off",
                           "snub_dodecahedron.off", "uvsphere_1600.off"}) {
    const Mesh mesh = morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/" + name);
    check_triangle_turns(mesh, name);
    check_triangle_turns(morph::test::scaled(mesh, 0x1p-200), std::string(name) + " tiny");
    check_triangle_turns(morph::test::scaled(mesh, 0x1p200), std::string(name) + " huge");
    check_triangle_turns(morph::test::translated(mesh, Point(1e6, -3e5, 7)),
                         std::string(name) + " far");
  }
  for (std::uint64_t seed = 1; seed <= 3; ++seed)
    check_triangle_turns(morph::test::random_sphere_polytope(200, seed),
                         "sphere " + std::to_string(seed));
}

TEST_CASE("polytope: make_operands gives the same operands and errors with one thread or two") {
  // With two threads a large operand's check runs beside its halfedge walks (on face cycles
  // of its own), and the thread done with the smaller operand takes it: the polytopes, and the
  // error (A's when both are bad), must be those of make_operand(A) then make_operand(B).
  const auto sample = [](const char* name) {
    return morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/" + name);
  };
  const Mesh small = sample("icosphere_320.off"), large = sample("icosphere_1280.off");
  const Mesh uv = sample("uvsphere_1600.off");
  REQUIRE(large.n_faces() >= 1000);
  Mesh dented = large, bent = uv;
  dented.set_point(Mesh::VertexHandle(0), large.point(Mesh::VertexHandle(0)) * 0.9);
  bent.set_point(Mesh::VertexHandle(5), uv.point(Mesh::VertexHandle(5)) * (1 + 1e-6));
  std::vector<std::vector<int>> faces;
  for (auto f : large.faces()) {
    std::vector<int> cycle;
    for (auto v : f.vertices()) cycle.push_back(v.idx());
    faces.push_back(cycle);
  }
  const std::vector<std::vector<int>> holed(faces.begin() + 1, faces.end());
  const Mesh open = morph::test::mesh_from_polygons(morph::test::positions(large), holed);
  const Mesh inside_out = inverted(large);
  const std::vector<std::pair<const Mesh*, const Mesh*>> pairs = {
      {&small, &large},   {&uv, &large},          {&large, &uv},   {&small, &dented},
      {&dented, &bent},   {&bent, &small},        {&open, &large}, {&small, &open},
      {&uv, &inside_out}, {&inside_out, &dented}, {&dented, &open}};
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    CAPTURE(i);
    const Mesh &A = *pairs[i].first, &B = *pairs[i].second;
    std::string expected;
    Polytope a, b;
    try {
      a = morph::detail::make_operand(A, "A");
      b = morph::detail::make_operand(B, "B");
    } catch (const std::exception& error) {
      expected = error.what();
    }
    for (int threads : {1, 2}) {
      CAPTURE(threads);
      tbb::task_arena arena(threads);
      arena.execute([&] {
        for (int repeat = 0; repeat < 3; ++repeat) {  // the threads' timing varies
          try {
            const morph::detail::Operands op = morph::detail::make_operands(A, B);
            CHECK(expected == "");
            CHECK(difference(op.a, a) == "");
            CHECK(difference(op.b, b) == "");
          } catch (const std::exception& error) {
            CHECK(std::string(error.what()) == expected);
          }
        }
      });
    }
  }
}

// make_operand's check takes the bounding box from copy_points, which scans the even and the odd
// vertices apart and computes the box again in index order when the two halves' extremes are
// zeros of opposite signs (equal, but not the same bits). Cubes with -0.0 and +0.0 coordinates at
// the vertices that decide each half's minimum (vertices 0 and 1), in either order, and a cube
// whose maxima are zeros: the verdicts, polytopes and unit normals must be the check's and
// compute_normals' whichever path they take.
TEST_CASE("polytope: make_operand's check on cubes whose box corners are signed zeros") {
  for (const double first : {-0.0, 0.0}) {
    std::vector<Point> points = unit_cube_points();
    const double second = -first;
    for (int i = 0; i < 8; ++i)
      for (int k = 0; k < 3; ++k)
        if (points[i][k] == 0) points[i][k] = i % 2 == 0 ? first : second;
    const std::string what = std::signbit(first) ? "-0 first" : "+0 first";
    for (const auto& faces : {kQuads, split_quads()}) {
      const Mesh mesh = morph::test::mesh_from_polygons(points, faces);
      check_operand_agrees(mesh, what);
      check_operand_normals(mesh, what);
      // Reflected through the origin (the maxima are the zeros), with the facets reversed to
      // stay outward.
      std::vector<Point> reflected = points;
      for (Point& q : reflected) q = Point(-q[0], -q[1], -q[2]);
      std::vector<std::vector<int>> reversed = faces;
      for (auto& f : reversed) std::reverse(f.begin(), f.end());
      const Mesh mirror = morph::test::mesh_from_polygons(reflected, reversed);
      check_operand_agrees(mirror, what + " reflected");
      check_operand_normals(mirror, what + " reflected");
    }
  }
}
