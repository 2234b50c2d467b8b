// The FIMS kernel (minkowski_sum.h) against the independent oracle: CGAL's exact convex
// hull of all vertex sums (support/oracle.h), plus analytic cases.
#include <doctest/doctest.h>
#include <morph/io.h>
#include <morph/minkowski_sum.h>
#include <morph/structuring_element.h>
#include <morph/validate.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/oracle.h"
#include "support/polytopes.h"

namespace {

using namespace morph;
using namespace morph::test;

// Tolerances for operands whose facets are only approximately planar (UV sphere quads,
// pentagons from the golden ratio, rotated quads). The exact hull of their vertex sums
// splits each slightly bent facet, so facets are not compared; the two bodies must
// agree to far below any visible feature, yet far above double rounding.
constexpr double kApproxDistance = 1e-9;  // relative to the sum's bounding-box diagonal
constexpr double kApproxVolume = 1e-9;    // relative volume difference

std::vector<int> element_vertices(const Mesh& m, const Element& e) {
  std::vector<int> out;
  switch (e.kind) {
    case Element::Kind::vertex:
      out.push_back(e.index);
      break;
    case Element::Kind::edge: {
      const auto h = m.halfedge_handle(m.edge_handle(e.index), 0);
      out = {m.from_vertex_handle(h).idx(), m.to_vertex_handle(h).idx()};
      break;
    }
    case Element::Kind::facet:
      for (auto v : m.fv_range(m.face_handle(e.index))) out.push_back(v.idx());
      break;
    case Element::Kind::none:
      break;
  }
  return out;
}

bool valid_element(const Mesh& m, const Element& e) {
  switch (e.kind) {
    case Element::Kind::vertex:
      return e.index >= 0 && e.index < static_cast<int>(m.n_vertices());
    case Element::Kind::edge:
      return e.index >= 0 && e.index < static_cast<int>(m.n_edges());
    case Element::Kind::facet:
      return e.index >= 0 && e.index < static_cast<int>(m.n_faces());
    case Element::Kind::none:
      return false;
  }
  return false;
}

std::set<Position> sums_of(const Mesh& A, const std::vector<int>& va, const Mesh& B,
                           const std::vector<int>& vb) {
  std::set<Position> out;
  for (int i : va) {
    for (int j : vb) {
      const Point s = A.point(A.vertex_handle(i)) + B.point(B.vertex_handle(j));
      out.insert({s[0], s[1], s[2]});
    }
  }
  return out;
}

// The first face whose origin is missing, malformed, or does not produce the face: its
// vertices must be exactly the double sums of the named elements' vertices (all of them
// for a facet + vertex, an edge + edge parallelogram or a vertex + facet corner).
// With `exact_facets` false (the exact sum has sub-resolution features the library
// merges), only the kinds and elements are checked.
std::string origins_problem(const LabelledMesh& S, const Mesh& A, const Mesh& B,
                            bool exact_facets) {
  if (S.origins.size() != S.mesh.n_faces()) {
    return std::to_string(S.origins.size()) + " origins for " + std::to_string(S.mesh.n_faces()) +
           " faces";
  }
  for (auto f : S.mesh.faces()) {
    const FacetOrigin& o = S.origins[f.idx()];
    const std::string name = "face " + std::to_string(f.idx());
    if (!valid_element(A, o.a) || !valid_element(B, o.b))
      return name + ": origin names no element of A or B";
    std::set<Position> face;
    for (auto v : S.mesh.fv_range(f)) {
      const Point& p = S.mesh.point(v);
      face.insert({p[0], p[1], p[2]});
    }
    const std::set<Position> sums =
        sums_of(A, element_vertices(A, o.a), B, element_vertices(B, o.b));
    if (!exact_facets) {
      if (o.kind == FacetKind::edge &&
          (o.a.kind != Element::Kind::edge || o.b.kind != Element::Kind::edge))
        return name + ": edge facet not from two edges";
      continue;
    }
    if (!std::includes(sums.begin(), sums.end(), face.begin(), face.end())) {
      return name + ": a vertex is not a sum of the origin's vertices";
    }
    using K = Element::Kind;
    switch (o.kind) {
      case FacetKind::translated:
        if (o.a.kind != K::facet) return name + ": translated facet whose A element is not a facet";
        if (o.b.kind == K::vertex && face != sums)
          return name + ": not facet a of A moved by vertex b";
        break;
      case FacetKind::corner:
        if (o.b.kind != K::facet || o.a.kind == K::facet)
          return name + ": corner facet not (vertex|edge of A, facet of B)";
        if (o.a.kind == K::vertex && face != sums)
          return name + ": not facet b of B placed at vertex a";
        break;
      case FacetKind::edge:
        if (o.a.kind != K::edge || o.b.kind != K::edge)
          return name + ": edge facet not from two edges";
        if (S.mesh.valence(f) != 4 || face != sums)
          return name + ": edge facet is not the parallelogram of its edges";
        break;
    }
  }
  return {};
}

std::size_t count_kind(const LabelledMesh& S, FacetKind kind) {
  return static_cast<std::size_t>(std::count_if(
      S.origins.begin(), S.origins.end(), [&](const FacetOrigin& o) { return o.kind == kind; }));
}

// A (+) B against the oracle; exact comparison when both operands are exactly planar.
void check_sum(const Mesh& A, const Mesh& B, const std::string& name) {
  INFO("case: ", name);
  const Mesh a_before = A, b_before = B;
  const LabelledMesh S = minkowski_sum(A, B);
  CHECK_MESSAGE(identical(A, a_before), "A was modified");
  CHECK_MESSAGE(identical(B, b_before), "B was modified");
  const Description want = exact_hull_of_sums(A, B);
  const Description got = describe(S.mesh);
  const bool planar_operands = exactly_planar(A) && exactly_planar(B);
  // Features of the exact sum below the feature size are merged by the library: then
  // the result is the exact sum only to within that size, and a merged facet holds
  // vertices of the facets it absorbed besides those of its origin.
  const std::string feature =
      subresolution_feature(want, kLibraryFeatureTolerance * bbox_diagonal(S.mesh));
  const std::string origins = origins_problem(S, A, B, feature.empty());
  CHECK_MESSAGE(origins.empty(), origins);
  if (planar_operands && feature.empty()) {
    const std::string diff = compare_exact(got, want);
    CHECK_MESSAGE(diff.empty(), diff);
  } else {
    // Vertices must still be exact sums rounded once; the bodies agree within a
    // tolerance (kApproxDistance; the feature size when only sub-resolution features
    // differ); facets are not compared.
    INFO("sub-resolution feature of the exact sum: ", feature);
    std::set<Position> all_sums;
    for (auto va : A.vertices()) {
      for (auto vb : B.vertices()) {
        const Point s = A.point(va) + B.point(vb);
        all_sums.insert({s[0], s[1], s[2]});
      }
    }
    const bool all_are_sums =
        std::all_of(got.vertices.begin(), got.vertices.end(),
                    [&](const Position& p) { return all_sums.count(p) == 1; });
    CHECK_MESSAGE(all_are_sums, "an output vertex is not a double sum a_i + b_j");
    const double tol = planar_operands ? kLibraryFeatureTolerance : kApproxDistance;
    const std::string diff = compare_close(got, want, tol * bbox_diagonal(S.mesh), kApproxVolume);
    CHECK_MESSAGE(diff.empty(), diff);
    CHECK(got.facet_count <= want.facet_count);
  }
  // Nothing below the feature size is left (half of it: a margin for the rounding).
  const std::string left =
      subresolution_feature(got, kResultFeatureTolerance * bbox_diagonal(S.mesh));
  CHECK_MESSAGE(left.empty(), "the result has ", left);
  const std::string clean = clean_mesh_problem(
      S.mesh, planar_operands && feature.empty() ? clean_options_for(want) : kRoundedClean);
  CHECK_MESSAGE(clean.empty(), clean);
  // A result is an operand the library itself accepts (pipelines chain on rounded meshes).
  const morph::CheckResult operand = morph::check_convex_polyhedron(S.mesh);
  CHECK_MESSAGE(operand.ok(), "not a valid operand: ", operand.problem);
}

struct Pair {
  std::string name;
  Mesh A;
  Mesh B;
};

std::vector<Pair> random_pairs() {
  std::vector<Pair> pairs;
  for (std::uint64_t s = 1; s <= 10; ++s) {
    const int n1 = 6 + static_cast<int>(s * 7 % 40), n2 = 5 + static_cast<int>(s * 13 % 30);
    pairs.push_back({"sphere hulls seed " + std::to_string(s), random_sphere_polytope(n1, s),
                     random_sphere_polytope(n2, 100 + s, 0.3 + 0.1 * static_cast<double>(s))});
  }
  for (std::uint64_t s = 1; s <= 6; ++s) {
    pairs.push_back({"cube hulls seed " + std::to_string(s), random_cube_polytope(25, 200 + s),
                     random_cube_polytope(12, 300 + s, 0.25)});
  }
  for (std::uint64_t s = 1; s <= 10; ++s) {
    pairs.push_back({"integer hulls seed " + std::to_string(s),
                     random_integer_polytope(14, 400 + s, 3),
                     random_integer_polytope(8, 500 + s, s % 2 ? 1 : 2)});
  }
  for (std::uint64_t s = 1; s <= 4; ++s) {
    const Mesh A = random_integer_polytope(12, 600 + s, 2);
    pairs.push_back({"integer A + A seed " + std::to_string(s), A, A});
    pairs.push_back(
        {"integer A + (A + t) seed " + std::to_string(s), A, translated(A, Point(3, -1, 7))});
    pairs.push_back({"integer A + (-A) seed " + std::to_string(s), A, reflected(A)});
  }
  for (std::uint64_t s = 1; s <= 3; ++s) {
    const Mesh A = random_sphere_polytope(30, 700 + s);
    pairs.push_back({"sphere A + A seed " + std::to_string(s), A, A});
    pairs.push_back({"sphere A + (-A) seed " + std::to_string(s), A, reflected(A)});
    const Mesh G = random_grid_polytope(24, 750 + s);
    pairs.push_back(
        {"grid A + (A + t) seed " + std::to_string(s), G, translated(G, Point(0.5, -0.25, 3.0))});
    // Copies scaled by powers of two (exactly: same_normal's similar cycles) and by 0.3.
    pairs.push_back({"sphere A + 0.5 A seed " + std::to_string(s), A, scaled(A, 0.5)});
    pairs.push_back({"grid A + (0.25 A + t) seed " + std::to_string(s), G,
                     translated(scaled(G, 0.25), Point(0.5, -0.25, 3.0))});
    pairs.push_back({"sphere A + 0.3 A seed " + std::to_string(s), A, scaled(A, 0.3)});
  }
  pairs.push_back(
      {"icosphere A + 0.5 A", make_icosphere(1.0, 2), scaled(make_icosphere(1.0, 2), 0.5)});
  for (std::uint64_t s = 1; s <= 5; ++s) {
    pairs.push_back({"rotated cube (triangles) + sphere hull seed " + std::to_string(s),
                     rotated_cube_triangles(1.0, 800 + s), random_sphere_polytope(15, 850 + s)});
    pairs.push_back({"rotated cube + rotated cube (triangles) seed " + std::to_string(s),
                     rotated_cube_triangles(2.0, 900 + s), rotated_cube_triangles(0.5, 950 + s)});
  }
  pairs.push_back({"tetrahedron + cube", tetrahedron(1.0), cube(2.0)});
  pairs.push_back({"cube + tetrahedron", cube(2.0), tetrahedron(0.5)});
  pairs.push_back({"tetrahedron + octahedron", tetrahedron(1.0), octahedron(1.0)});
  pairs.push_back({"tetrahedron + (-tetrahedron)", tetrahedron(1.0), reflected(tetrahedron(1.0))});
  pairs.push_back({"integer hull + cube", random_integer_polytope(16, 1001, 3), cube(1.0)});
  pairs.push_back(
      {"integer hull + octahedron", random_integer_polytope(16, 1002, 3), octahedron(1.0)});
  return pairs;
}

std::vector<std::filesystem::path> sample_operands() {
  std::vector<std::filesystem::path> out;
  const std::filesystem::path dir = MORPH_SAMPLES_DIR;
  if (!std::filesystem::is_directory(dir)) return out;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() == ".off") out.push_back(entry.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// The oracle itself, against values known independently.

TEST_CASE("fims: oracle self-check on analytic sums") {
  const Description cc = exact_hull_of_sums(cube(1.0), cube(1.0));
  CHECK(cc.vertex_count == 8);
  CHECK(cc.facet_count == 6);
  CHECK(cc.edge_count == 12);
  CHECK(cc.volume == 8.0);
  CHECK(compare_exact(cc, describe(cube(2.0))).empty());

  const Description tt = exact_hull_of_sums(tetrahedron(1.0), tetrahedron(1.0));
  CHECK(compare_exact(tt, describe(tetrahedron(2.0))).empty());
  CHECK(tt.volume == doctest::Approx(64.0 / 3.0).epsilon(1e-15));

  // The hull of a triangulated cube's sums merges the coplanar triangles back.
  const Description rc = exact_hull_of_sums(rotated_cube_triangles(1.0, 5), cube(0.0));
  CHECK(rc.vertex_count == 8);

  // The clean-mesh check rejects what it must.
  CHECK(clean_mesh_problem(cube(1.0)).empty());
  CHECK(clean_mesh_problem(random_integer_polytope(14, 1, 3)).empty());
  CHECK(clean_mesh_problem(reflected(cube(1.0))).empty());           // -cube is an outward cube
  CHECK_FALSE(clean_mesh_problem(scaled(cube(1.0), -1.0)).empty());  // negated only: inward
  {
    // Two coplanar triangles where one quad should be.
    const std::vector<Point> p = {Point(0, 0, 0), Point(1, 0, 0), Point(0, 1, 0), Point(1, 1, 0),
                                  Point(0, 0, 1), Point(1, 0, 1), Point(0, 1, 1), Point(1, 1, 1)};
    const Mesh split = mesh_from_polygons(p, {{0, 2, 3},
                                              {0, 3, 1},
                                              {4, 5, 7, 6},
                                              {0, 1, 5, 4},
                                              {2, 6, 7, 3},
                                              {0, 4, 6, 2},
                                              {1, 3, 7, 5}});
    CHECK(clean_mesh_problem(split).find("coplanar") != std::string::npos);
    // A vertex in the middle of an edge.
    std::vector<Point> q = p;
    q.push_back(Point(0.5, 0, 0));
    const Mesh mid = mesh_from_polygons(
        q,
        {{0, 2, 3, 1, 8}, {4, 5, 7, 6}, {0, 8, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}});
    CHECK(clean_mesh_problem(mid).find("distinct face planes") != std::string::npos);
    // A tetrahedron whose bottom is dented in towards its apex: not convex.
    const Mesh nonconvex = mesh_from_polygons(
        {Point(0, 0, 0), Point(2, 0, 0), Point(0, 2, 0), Point(0, 0, 2), Point(0.5, 0.5, 0.3)},
        {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 2, 4}, {2, 1, 4}, {1, 0, 4}});
    CHECK_FALSE(clean_mesh_problem(nonconvex).empty());
  }
}

// ---------------------------------------------------------------------------------------
// Oracle comparisons

TEST_CASE(
    "fims: random, integer, rotated, self, translated and reflected pairs match the exact hull") {
  const std::vector<Pair> pairs = random_pairs();
  REQUIRE(pairs.size() >= 50);
  for (const Pair& p : pairs) check_sum(p.A, p.B, p.name);
}

TEST_CASE("fims: every pair of small samples matches the exact hull") {
  // The samples are committed with the repository; missing ones are a failure.
  std::vector<std::pair<std::string, Mesh>> operands;
  for (const auto& path : sample_operands()) {
    const Mesh m = read_mesh(path);
    if (m.n_vertices() > 400) continue;              // keep the n^2 pairs quick
    if (!check_convex_polyhedron(m).ok()) continue;  // samples of invalid input
    operands.emplace_back(path.filename().string(), m);
  }
  REQUIRE_MESSAGE(operands.size() >= 3, "expected at least 3 small convex samples/*.off in ",
                  MORPH_SAMPLES_DIR);
  for (const auto& [na, A] : operands) {
    for (const auto& [nb, B] : operands) check_sum(A, B, na + " + " + nb);
  }
}

TEST_CASE("fims: library elements match the exact hull") {
  check_sum(make_icosphere(1.0, 1), random_sphere_polytope(20, 42, 0.5),
            "icosphere(1) + sphere hull");
  check_sum(make_box(1.0, 2.0, 0.5), make_tetrahedron(0.7), "box + tetrahedron");
  check_sum(make_octahedron(1.0), make_icosphere(0.3, 2), "octahedron + icosphere(2)");
  check_sum(random_integer_polytope(15, 77, 3), make_box(0.5, 0.25, 1.0), "integer hull + box");
}

TEST_CASE("fims: approximately planar operands agree with the exact hull within tolerance") {
  check_sum(make_uv_sphere(1.0, 12), cube(0.5), "UV sphere + cube");
  check_sum(make_uv_sphere(1.0, 9), make_tetrahedron(0.5), "UV sphere + tetrahedron");
  check_sum(make_snub_dodecahedron(1.0), tetrahedron(0.3), "snub dodecahedron + tetrahedron");
  check_sum(make_dodecahedron(1.0), make_icosahedron(0.5), "dodecahedron + icosahedron");
  for (std::uint64_t s = 1; s <= 3; ++s) {
    check_sum(rotated_cube_quads(1.0, 1100 + s), rotated_cube_quads(0.7, 1200 + s),
              "rotated quads");
    check_sum(rotated_cube_quads(1.0, 1300 + s), random_sphere_polytope(12, 1400 + s, 0.4),
              "rotated quads + hull");
  }
}

// ---------------------------------------------------------------------------------------
// Analytic cases

TEST_CASE("fims: box plus box is the box of summed edges") {
  const Mesh A = box(Point(-1, -2, -3), Point(1, 2, 3));
  const Mesh B = box(Point(0, -0.5, 0), Point(0.5, 0.25, 4));
  const LabelledMesh S = minkowski_sum(A, B);
  const Description d = describe(S.mesh);
  CHECK(d.vertex_count == 8);
  CHECK(d.facet_count == 6);
  CHECK(d.facet_degrees() == std::vector<std::size_t>(6, 4));
  CHECK(compare_exact(d, describe(box(Point(-1, -2.5, -3), Point(1.5, 2.25, 7)))).empty());
  CHECK(d.volume == doctest::Approx(2.5 * 4.75 * 10).epsilon(1e-14));
  CHECK(count_kind(S, FacetKind::translated) == 6);
}

TEST_CASE("fims: cube plus octahedron is the expanded cube") {
  // Gauss maps: the cube's 6 face normals are octahedron vertex directions (6 translated
  // squares); the octahedron's 8 face normals lie inside cube vertex cones (8 corner
  // triangles); each cube edge arc crosses one octahedron edge arc at its midpoint (12
  // edge rectangles). V = 8 cube vertices x 3 = 24, E = (6*4 + 8*3 + 12*4)/2 = 48.
  for (double r : {1.0, 0.5, 3.0}) {
    CAPTURE(r);
    const LabelledMesh S = minkowski_sum(cube(2.0), octahedron(r));
    const Description d = describe(S.mesh);
    CHECK(d.vertex_count == 24);
    CHECK(d.edge_count == 48);
    CHECK(d.facet_count == 26);
    std::vector<std::size_t> degrees(8, 3);
    degrees.resize(26, 4);
    CHECK(d.facet_degrees() == degrees);
    CHECK(count_kind(S, FacetKind::translated) == 6);
    CHECK(count_kind(S, FacetKind::corner) == 8);
    CHECK(count_kind(S, FacetKind::edge) == 12);
    // Mixed volumes: V(C) + sum over C's facets of h_O(n) area + sum over O's facets of
    // h_C(n) area + V(O) = 8 + 24 r + 12 r^2 + 4/3 r^3.
    CHECK(d.volume ==
          doctest::Approx(8 + 24 * r + 12 * r * r + 4.0 / 3.0 * r * r * r).epsilon(1e-13));
    CHECK(exact_hull_of_sums(cube(2.0), octahedron(r)).volume ==
          doctest::Approx(8 + 24 * r + 12 * r * r + 4.0 / 3.0 * r * r * r).epsilon(1e-13));
  }
}

TEST_CASE("fims: cube plus regular tetrahedron (the paper's example)") {
  // Each tetrahedron edge arc passes through a cube face normal: the 6 cube faces are
  // moved by a tetrahedron edge (hexagons); the 4 tetrahedron faces sit at cube corners
  // (triangles); no arcs cross inside, so no edge facets. V = 4*1 + 4*3 = 16, E = 24.
  // Volume 8 + 24 s + 24 s^2 + 8/3 s^3 for the cube of edge 2 and the tetrahedron s(+-1).
  const double s = 1.0;
  const LabelledMesh S = minkowski_sum(cube(2.0), tetrahedron(s));
  const Description d = describe(S.mesh);
  CHECK(d.vertex_count == 16);
  CHECK(d.edge_count == 24);
  CHECK(d.facet_count == 10);
  CHECK(d.facet_degrees() == std::vector<std::size_t>{3, 3, 3, 3, 6, 6, 6, 6, 6, 6});
  CHECK(count_kind(S, FacetKind::edge) == 0);
  CHECK(count_kind(S, FacetKind::corner) == 4);
  CHECK(count_kind(S, FacetKind::translated) == 6);
  CHECK(d.volume ==
        doctest::Approx(8 + 24 * s + 24 * s * s + 8.0 / 3.0 * s * s * s).epsilon(1e-13));
  CHECK(compare_exact(d, exact_hull_of_sums(cube(2.0), tetrahedron(s))).empty());
  CHECK(origins_problem(S, cube(2.0), tetrahedron(s), true).empty());
}

TEST_CASE("fims: A plus A is 2A with the facet degrees of A") {
  for (std::uint64_t seed : {11u, 12u, 13u}) {
    const Mesh A =
        seed == 11 ? random_integer_polytope(15, seed, 3) : random_sphere_polytope(25, seed);
    const LabelledMesh S = minkowski_sum(A, A);
    const Description d = describe(S.mesh);
    CHECK(compare_exact(d, describe(scaled(A, 2.0))).empty());
    CHECK(d.facet_degrees() == describe(A).facet_degrees());
    CHECK(d.volume == doctest::Approx(8 * describe(A).volume).epsilon(1e-12));
  }
}

// A scaled copy of A has facets and edges parallel to A's only up to rounding: the exact
// sum of the doubles is 1.1 A plus facets and needles of width ~1e-17, which must all merge.
TEST_CASE("fims: A plus a scaled copy of A is the scaled A, and the result chains") {
  for (int level : {1, 2, 3}) {
    INFO("icosphere level ", level);
    const Mesh A = make_icosphere(1.0, level);
    const Mesh B = make_icosphere(0.1, level);
    const LabelledMesh S = minkowski_sum(A, B);
    CHECK(S.mesh.n_vertices() == A.n_vertices());
    CHECK(S.mesh.n_faces() == A.n_faces());
    const std::string close =
        compare_close(describe(S.mesh), describe(scaled(A, 1.1)), 1e-12 * 2.2, 1e-12);
    CHECK_MESSAGE(close.empty(), close);
    CHECK_MESSAGE(clean_mesh_problem(S.mesh, kRoundedClean).empty(),
                  clean_mesh_problem(S.mesh, kRoundedClean));
    CHECK(subresolution_feature(describe(S.mesh), kResultFeatureTolerance * bbox_diagonal(S.mesh))
              .empty());
    // The result is a valid operand again (it used to keep zero-area needles).
    CHECK(check_convex_polyhedron(S.mesh).ok());
    const LabelledMesh S2 = minkowski_sum(S.mesh, B);
    CHECK(S2.mesh.n_faces() == A.n_faces());
  }
}

TEST_CASE("fims: an element away from the origin translates the sum") {
  // Grid coordinates: every sum and translation here is exact, so equality is exact.
  const Mesh A = random_grid_polytope(30, 21);
  const Mesh B = random_grid_polytope(12, 22);
  const Point t(5.0, -3.25, 0.5);
  const Mesh Bt = translated(B, t);  // does not contain the origin
  const Description moved = describe(minkowski_sum(A, Bt).mesh);
  CHECK(compare_exact(moved, describe(translated(minkowski_sum(A, B).mesh, t))).empty());
  CHECK(compare_exact(moved, exact_hull_of_sums(A, Bt)).empty());
  const Mesh far_cube = box(Point(10, 10, 10), Point(11, 12, 13));
  check_sum(A, far_cube, "grid hull + far box");
}

TEST_CASE("fims: output is identical for any thread count") {
  const Mesh big = make_icosphere(1.0, 3);                                      // 1280 triangles
  const Mesh small = transformed(make_icosphere(0.4, 2), random_rotation(31));  // 320 triangles
  REQUIRE(big.n_faces() == 1280);
  REQUIRE(small.n_faces() == 320);
  // Both orders: the facets of B are located first (then A's, then the edge facets; with
  // threads, both side by side), or those of A (then B's and the edge facets in one loop);
  // at two threads and more in chunks shared between the threads.
  for (const bool big_first : {true, false}) {
    CAPTURE(big_first);
    const Mesh& A = big_first ? big : small;
    const Mesh& B = big_first ? small : big;
    const LabelledMesh one = minkowski_sum(A, B, {.threads = 1});
    for (int threads : {2, 0}) {
      CAPTURE(threads);
      const LabelledMesh other = minkowski_sum(A, B, {.threads = threads});
      CHECK(identical(one.mesh, other.mesh));
      REQUIRE(one.origins.size() == other.origins.size());
      bool same_origins = true;
      for (std::size_t f = 0; f < one.origins.size(); ++f) {
        const FacetOrigin& x = one.origins[f];
        const FacetOrigin& y = other.origins[f];
        same_origins = same_origins && x.kind == y.kind && x.a.kind == y.a.kind &&
                       x.a.index == y.a.index && x.b.kind == y.b.kind && x.b.index == y.b.index;
      }
      CHECK(same_origins);
    }
    CHECK(clean_mesh_problem(one.mesh, kRoundedClean).empty());
    CHECK(origins_problem(one, A, B, true).empty());
  }
}

TEST_CASE("fims: the hull fallback gives the same output on every run and thread count") {
  // Far from the origin the sums of two unit spheres round onto a grid of about 1e-10,
  // the assembly finds slivers and rebuilds the result from the exact hull of the points.
  // CGAL's hull triangulates flat parts differently from run to run (its maps are keyed
  // by pointers); the result must not.
  const Mesh A = translated(make_icosphere(1.0, 2), Point(1e6, -3e5, 0.1));
  const Mesh B = make_icosphere(1.0, 2);
  const LabelledMesh one = minkowski_sum(A, B, {.threads = 1});
  int differing = 0;
  for (int run = 0; run < 24; ++run) {
    const LabelledMesh other = minkowski_sum(A, B, {.threads = run % 2 == 0 ? 0 : 1});
    differing += !identical(one.mesh, other.mesh);
  }
  CHECK(differing == 0);
  // Rounded onto that grid, the result is the exact sum only to within the grid (its
  // polygons convex to within the feature size, not exactly: not clean_mesh_problem).
  // Volumes summed in doubles 1e6 from the origin keep only about five digits.
  const std::string diff = compare_close(describe(one.mesh), exact_hull_of_sums(A, B),
                                         kApproxDistance * bbox_diagonal(one.mesh), 1e-4);
  CHECK_MESSAGE(diff.empty(), diff);
}

TEST_CASE(
    "fims: result vertices are numbered in the order of their pairs (vertex of A, vertex of B)") {
  // Grid coordinates: every vertex sum is exact, so each result vertex names its pair
  // (a vertex of a sum of convex bodies is the sum of exactly one pair of vertices).
  for (std::uint64_t s = 1; s <= 3; ++s) {
    CAPTURE(s);
    const Mesh A = random_grid_polytope(30, 40 + s);
    const Mesh B = random_grid_polytope(12, 50 + s);
    const std::vector<Point> pa = positions(A), pb = positions(B);
    std::vector<std::pair<int, int>> pairs;
    for (const Point& p : positions(minkowski_sum(A, B).mesh)) {
      std::vector<std::pair<int, int>> found;
      for (int i = 0; i < static_cast<int>(pa.size()); ++i)
        for (int j = 0; j < static_cast<int>(pb.size()); ++j)
          if (pa[i] + pb[j] == p) found.emplace_back(i, j);
      REQUIRE(found.size() == 1);
      pairs.push_back(found[0]);
    }
    CHECK(std::adjacent_find(pairs.begin(), pairs.end(), std::greater_equal<>()) == pairs.end());
  }
}
