// The exact half-space intersection behind erosion (libmorph/src/halfspace_intersection.h):
// its main route (an exact incremental hull on the planes, with interval filters) must
// give exactly the result of the exact route (CGAL's hull of exact dual points), on inputs
// chosen so that doubles get the combinatorics wrong: nearly coincident planes, planes
// cutting a vertex by less than an ulp, many planes through one vertex, duplicate planes,
// rational offsets. The rounded result must be the exact one rounded to nearest.
#include "halfspace_intersection.h"

#include <doctest/doctest.h>
#include <morph/io.h>
#include <morph/structuring_element.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "fims.h"
#include "huge_pages.h"
#include "parallel.h"
#include "support/polytopes.h"

namespace {

using namespace morph::detail;

/// The half-space <n, x> <= d for a dyadic d (denominator 1), source 0.
HalfSpace dyadic_halfspace(const V3<ExactN>& n, const ExactN& d) {
  HalfSpace h;
  h.normal() = n;
  h.offset() = d;
  h.source = 0;
  return h;
}

HalfSpace plane(double nx, double ny, double nz, const Exact& offset, int source) {
  return make_halfspace({ExactN(nx), ExactN(ny), ExactN(nz)}, offset, source);
}

/// The six planes of the cube [-r, r]^3.
HalfSpaces cube_planes(double r) {
  HalfSpaces hs;
  const double axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const auto& a : axes)
    hs.push_back(plane(a[0], a[1], a[2], Exact(r), static_cast<int>(hs.size())));
  return hs;
}

/// A point that is not a double: (1/3, 1/5, 1/7).
V3<Exact> rational_apex() {
  return {Exact(1) / Exact(3), Exact(1) / Exact(5), Exact(1) / Exact(7)};
}

/// The cube [-2, 2]^3 and k planes tilted around the z axis, all exactly through
/// rational_apex() (a cone's apex).
HalfSpaces planes_through_apex(int k) {
  const V3<Exact> apex = rational_apex();
  HalfSpaces hs = cube_planes(2.0);
  for (int i = 0; i < k; ++i) {
    const double t = 2 * M_PI * i / k;
    const V3<double> n{std::cos(t), std::sin(t), 0.75};
    hs.push_back(
        make_halfspace(to_exact_n(n), dot(to_exact(n), apex), static_cast<int>(hs.size())));
  }
  return hs;
}

/// First difference between two results (exact positions, facet cycles, labels), or "".
std::string difference(const MaybePolytope& got, const MaybePolytope& want) {
  if (got.reason != want.reason) return "different emptiness";
  if (!got.polytope || !want.polytope)
    return got.polytope || want.polytope ? "one result missing" : "";
  const Polytope &a = *got.polytope, &b = *want.polytope;
  if (a.num_vertices() != b.num_vertices()) return "vertex counts differ";
  for (int v = 0; v < a.num_vertices(); ++v) {
    const V3<Exact> p = a.exact_point(v), q = b.exact_point(v);
    if (p.x != q.x || p.y != q.y || p.z != q.z) return "vertex " + std::to_string(v) + " differs";
  }
  if (a.face_begin != b.face_begin || a.corner_vertex != b.corner_vertex) return "facets differ";
  if (a.face_source != b.face_source) return "facet labels differ";
  return "";
}

/// Whether `r.rounded` is `r.polytope` with every coordinate rounded to nearest by mpfr.
bool rounded_from_exact(const MaybePolytope& r) {
  if (!r.polytope) return r.rounded.points.empty();
  const Polytope& p = *r.polytope;
  if (r.rounded.points.size() != p.points.size()) return false;
  for (int v = 0; v < p.num_vertices(); ++v) {
    const V3<Exact> e = p.exact_point(v);
    const V3<double>& q = r.rounded.points[v];
    if (q.x != round_to_nearest(e.x) || q.y != round_to_nearest(e.y) ||
        q.z != round_to_nearest(e.z))
      return false;
  }
  return r.rounded.face_begin == p.face_begin && r.rounded.corner_vertex == p.corner_vertex &&
         r.rounded.face_source == p.face_source;
}

/// The intersection by the default (incremental) route, checked against the exact route;
/// the rounded-only result is the same.
MaybePolytope checked(const HalfSpaces& hs, const V3<double>& hint = {0, 0, 0}) {
  MaybePolytope fast = intersect_halfspaces(hs, hint);
  const MaybePolytope exact = intersect_halfspaces(hs, hint, {.incremental = false});
  const MaybePolytope rounded = intersect_halfspaces(hs, hint, {.polytope = false});
  CHECK(exact.route == (exact.polytope ? HullRoute::exact : HullRoute::none));
  CHECK(difference(fast, exact) == "");
  CHECK(rounded_from_exact(fast));
  CHECK(!rounded.polytope);
  CHECK(std::equal(rounded.rounded.points.begin(), rounded.rounded.points.end(),
                   fast.rounded.points.begin(), fast.rounded.points.end(),
                   [](const V3<double>& p, const V3<double>& q) {
                     return p.x == q.x && p.y == q.y && p.z == q.z;
                   }));
  CHECK(rounded.rounded.corner_vertex == fast.rounded.corner_vertex);
  return fast;
}

const morph::Mesh& sample(const std::string& name) {
  static std::map<std::string, morph::Mesh> cache;
  auto it = cache.find(name);
  if (it == cache.end())
    it = cache.emplace(name, morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/" + name)).first;
  return it->second;
}

/// Whether facet f's unit normal lies within its error bound of the direction of its exact
/// normal (that direction in doubles, each component scaled by a power of two first and
/// converted within an ulp, then normalised: within 1e-15 of the exact one).
bool unit_normal_holds(const Polytope& p, int f) {
  const UnitNormal& u = p.unit_normals[f];
  if (!std::isfinite(u.error)) return true;  // (a normal that tells no direction)
  const V3<ExactN>& n = p.exact_normal(f);
  const double largest =
      std::max({std::abs(n.x.to_double()), std::abs(n.y.to_double()), std::abs(n.z.to_double())});
  if (!(largest > 0)) return false;
  const ExactN scale(std::ldexp(1.0, -std::ilogb(largest)));
  const V3<double> m{(n.x * scale).to_double(), (n.y * scale).to_double(),
                     (n.z * scale).to_double()};
  const double length = std::sqrt(dot(m, m));
  const V3<double> d{u.x - m.x / length, u.y - m.y / length, u.z - m.z / length};
  return std::sqrt(dot(d, d)) <= u.error + 1e-15;
}

/// First difference between two polytopes in any field (positions, exact points, normals,
/// connectivity, labels), or "". Unit normals are enclosures: two that differ must each hold
/// (unit_normal_holds); an eroded polytope takes its own from its half-spaces' double-double
/// normals, a copy of it from the vertices. `projective`: exact points (X, W) that are the
/// same point, X / W, count as the same (a vertex of four planes or more may come from
/// another three of them, with another scale).
std::string polytope_difference(const Polytope& a, const Polytope& b, bool projective = false) {
  if (a.num_vertices() != b.num_vertices()) return "vertex counts differ";
  for (int v = 0; v < a.num_vertices(); ++v) {
    const V3<double>&p = a.points[v], &q = b.points[v];
    if (p.x != q.x || p.y != q.y || p.z != q.z) return "point " + std::to_string(v) + " differs";
    if (a.exact_points.empty() != b.exact_points.empty()) return "exactness differs";
    if (a.exact_points.empty()) continue;
    const V3<ExactN>&x = a.exact_points.X(v), &y = b.exact_points.X(v);
    const ExactN &w = a.exact_points.W(v), &z = b.exact_points.W(v);
    const bool same = projective ? x.x * z == y.x * w && x.y * z == y.y * w && x.z * z == y.z * w
                                 : x.x == y.x && x.y == y.y && x.z == y.z && w == z;
    if (!same) return "exact point " + std::to_string(v) + " differs";
  }
  if (a.given_normals.size() != b.given_normals.size()) return "given normal counts differ";
  for (std::size_t f = 0; f < a.given_normals.size(); ++f) {
    const V3<ExactN>&m = a.given_normals[f], &n = b.given_normals[f];
    if (m.x != n.x || m.y != n.y || m.z != n.z) return "normal " + std::to_string(f) + " differs";
  }
  if (a.face_begin != b.face_begin || a.corner_vertex != b.corner_vertex) return "facets differ";
  if (a.corner_edge != b.corner_edge) return "corner edges differ";
  if (a.num_edges() != b.num_edges()) return "edge counts differ";
  for (int e = 0; e < a.num_edges(); ++e) {
    const Polytope::Edge &x = a.edges[e], &y = b.edges[e];
    if (x.from != y.from || x.to != y.to || x.left != y.left || x.right != y.right)
      return "edge " + std::to_string(e) + " differs";
  }
  if (a.fan_begin != b.fan_begin || a.fan_face != b.fan_face || a.fan_edge != b.fan_edge ||
      a.fan_vertex != b.fan_vertex)
    return "fans differ";
  for (int f = 0; f < a.num_faces(); ++f) {
    const UnitNormal &m = a.unit_normals[f], &n = b.unit_normals[f];
    const bool same = m.x == n.x && m.y == n.y && m.z == n.z && m.error == n.error;
    if (!same && !(unit_normal_holds(a, f) && unit_normal_holds(b, f)))
      return "unit normal " + std::to_string(f) + " differs";
  }
  if (a.face_source != b.face_source || a.vertex_source != b.vertex_source ||
      a.edge_source != b.edge_source || a.sum_pairs != b.sum_pairs)
    return "labels differ";
  return "";
}

/// The eroded polytope built straight from the verified intersection is make_polytope's
/// (general build, merge pass, checks), field by field.
void check_direct_polytope(const Polytope& A, const Polytope& B, const MaybePolytope& direct) {
  const MaybePolytope general = erode_polytope(A, B, {.direct_polytope = false});
  REQUIRE(direct.reason == general.reason);
  if (direct.polytope) CHECK(polytope_difference(*direct.polytope, *general.polytope) == "");
}

/// Two repairs and checks acted alike: the same counts of each action (not of the tests that
/// decided them).
void check_same_actions(const RepairCounts& a, const RepairCounts& b) {
  CHECK(a.flips == b.flips);
  CHECK(a.removals == b.removals);
  CHECK(a.lifts == b.lifts);
  CHECK(a.insertions == b.insertions);
  CHECK(a.cuts == b.cuts);
  CHECK(a.insert_steps == b.insert_steps);
  CHECK(a.check_planes == b.check_planes);
  CHECK(a.check_steps == b.check_steps);
  CHECK(a.regions == b.regions);
  CHECK(a.handed_over == b.handed_over);
}

/// A (-) B by erode_polytope's guess (A's vertices), by the incremental hull alone and by
/// the exact route: exactly the same result, and its polytope built directly is
/// make_polytope's. Returns the first.
MaybePolytope eroded_three_ways(const Polytope& A, const Polytope& B) {
  const MaybePolytope guessed = erode_polytope(A, B);
  check_direct_polytope(A, B, guessed);
  const MaybePolytope hull = erode_polytope(A, B, {.guess = false});
  const MaybePolytope exact = erode_polytope(A, B, {.incremental = false});
  CHECK(hull.route != HullRoute::expected);
  CHECK(difference(guessed, hull) == "");
  CHECK(difference(guessed, exact) == "");
  CHECK(rounded_from_exact(guessed));
  return guessed;
}

}  // namespace

TEST_CASE("halfspace_intersection: a cube is found by the incremental hull") {
  const MaybePolytope r = checked(cube_planes(1.0));
  REQUIRE(r.polytope);
  CHECK(r.route == HullRoute::incremental);
  CHECK(r.polytope->num_faces() == 6);
  CHECK(r.polytope->num_vertices() == 8);
}

// A corner of the cube cut off by 2^-60: in doubles the cutting plane's dual point lies on
// the hull, so a hull in doubles would miss the facet (6 facets). The incremental hull
// decides it exactly, without a fallback.
TEST_CASE("halfspace_intersection: a cut below double resolution is found exactly") {
  HalfSpaces hs = cube_planes(1.0);
  hs.push_back(plane(1, 1, 1, Exact(3) - Exact(std::ldexp(1.0, -60)), 6));
  const MaybePolytope r = checked(hs);
  REQUIRE(r.polytope);
  CHECK(r.route == HullRoute::incremental);
  CHECK(r.polytope->num_faces() == 7);
  CHECK(r.polytope->num_vertices() == 10);
}

// Vertices of degree 4 (the octahedron), also with a rational (non-dyadic) offset, and
// a square pyramid whose apex has degree 4.
TEST_CASE("halfspace_intersection: planes through one vertex are grouped exactly") {
  for (const Exact offset : {Exact(1), Exact(1) / Exact(3)}) {
    HalfSpaces hs;
    for (int s = 0; s < 8; ++s)
      hs.push_back(plane(s & 1 ? -1 : 1, s & 2 ? -1 : 1, s & 4 ? -1 : 1, offset, s));
    const MaybePolytope r = checked(hs);
    REQUIRE(r.polytope);
    CHECK(r.polytope->num_faces() == 8);
    CHECK(r.polytope->num_vertices() == 6);
  }
  HalfSpaces pyramid = {plane(0, 0, -1, Exact(1), 0), plane(1, 0, 1, Exact(1), 1),
                        plane(-1, 0, 1, Exact(1), 2), plane(0, 1, 1, Exact(1), 3),
                        plane(0, -1, 1, Exact(1), 4)};
  const MaybePolytope r = checked(pyramid);
  REQUIRE(r.polytope);
  CHECK(r.polytope->num_faces() == 5);
  CHECK(r.polytope->num_vertices() == 5);
}

// Many planes exactly through one rational point (not a double): in doubles their dual
// points are not coplanar, exactly they are. The apex must come out as one exact vertex.
TEST_CASE("halfspace_intersection: many planes through a rational apex") {
  const V3<Exact> apex = rational_apex();
  for (int k : {5, 12, 40}) {
    const HalfSpaces hs = planes_through_apex(k);
    const MaybePolytope r = checked(hs);
    REQUIRE(r.polytope);
    int found = 0;
    for (int v = 0; v < r.polytope->num_vertices(); ++v) {
      const V3<Exact> p = r.polytope->exact_point(v);
      found += p.x == apex.x && p.y == apex.y && p.z == apex.z;
    }
    CHECK(found == 1);
  }
}

// Nearly coincident planes: tangent planes of the unit sphere around the north pole,
// slightly tilted and moved by less than an ulp of their offsets, so that rounding the
// offsets changes the combinatorics (a hull in doubles gets these wrong). Every one must
// agree with the exact route, without a fallback.
TEST_CASE("halfspace_intersection: nearly coincident planes") {
  for (int seed = 0; seed < 12; ++seed) {
    HalfSpaces hs = cube_planes(2.0);
    hs[4] = plane(0, 0, 1, Exact(4), 4);  // room above the cap
    for (int i = 0; i < 30; ++i) {
      const double t = 2 * M_PI * ((i * 7 + seed * 3) % 30) / 30.0;
      const double tilt = std::ldexp(1.0 + (i % 5) / 8.0, -24 - (i + seed) % 4);
      const Exact move = Exact(std::ldexp(static_cast<double>((i * 13 + seed) % 7) - 3.0, -62));
      hs.push_back(plane(tilt * std::cos(t), tilt * std::sin(t), 1, Exact(1) + move,
                         static_cast<int>(hs.size())));
    }
    const MaybePolytope r = checked(hs);
    REQUIRE(r.polytope);
    CHECK(r.route == HullRoute::incremental);
  }
}

// The same plane twice (scaled by 3, with a later index): the facet keeps the smaller
// index, whichever route finds it.
TEST_CASE("halfspace_intersection: a duplicate plane labels its facet by the first index") {
  HalfSpaces hs = cube_planes(1.0);
  hs.push_back(plane(3, 0, 0, Exact(3), 6));
  hs.insert(hs.begin(), plane(0, 0, 3, Exact(3), -7));  // duplicate of +z, first
  for (int i = 0; i < static_cast<int>(hs.size()); ++i) hs[i].source = i;
  const MaybePolytope r = checked(hs);
  REQUIRE(r.polytope);
  CHECK(r.polytope->num_faces() == 6);
  std::vector<int> labels = r.polytope->face_source;
  std::sort(labels.begin(), labels.end());
  CHECK(labels == std::vector<int>{0, 1, 2, 3, 4, 6});  // +z is half-space 0, not 5; +x is 1, not 7
}

TEST_CASE("halfspace_intersection: empty and flat intersections") {
  HalfSpaces hs = cube_planes(1.0);
  hs.push_back(plane(1, 0, 0, Exact(-2), 6));
  CHECK(intersect_halfspaces(hs, {0, 0, 0}).reason == morph::EmptyReason::empty);
  hs.back() = plane(1, 0, 0, Exact(-1), 6);
  CHECK(intersect_halfspaces(hs, {0, 0, 0}).reason == morph::EmptyReason::flat);
  // A hint outside: the exact centre is found, then the fast route runs about it.
  const MaybePolytope r = checked(cube_planes(1.0), {5, 5, 5});
  REQUIRE(r.polytope);
  CHECK(r.polytope->num_vertices() == 8);
}

// An opening rounds sums of an erosion's exact vertices X / W and double points b as
// round_quotient(X + b W, W): it must give mpfr's rounding of the rational sum, also for
// sums that cancel to (nearly) zero, ties, subnormals and a poor or wrong estimate.
TEST_CASE("halfspace_intersection: exact vertices plus doubles round as their rational sums") {
  const auto rounds_exactly = [](const ExactN& X, const ExactN& W, double estimate) {
    const double want = round_to_nearest(Exact(X) / Exact(W));
    const double got = round_quotient(X, W, Interval(estimate));
    return std::memcmp(&got, &want, sizeof got) == 0;  // also tells 0 from -0
  };
  const MaybePolytope r = checked(planes_through_apex(12));
  REQUIRE(r.polytope);
  const Polytope& p = *r.polytope;
  REQUIRE(!p.exact_points.empty());
  for (int v = 0; v < p.num_vertices(); ++v) {
    const ExactN& W = p.exact_points.W(v);
    const ExactN coordinates[3] = {p.exact_points.X(v).x, p.exact_points.X(v).y,
                                   p.exact_points.X(v).z};
    const double rounded[3] = {p.points[v].x, p.points[v].y, p.points[v].z};
    for (int i = 0; i < 3; ++i) {
      const double x = rounded[i];
      for (const double b : {0.0, 1.0, -0.25, 1e300, 0x1p-1070, -x, -x + 0x1p-60,
                             -x * (1 + 0x1p-52), std::nextafter(-x, 0.0)}) {
        const ExactN X = coordinates[i] + ExactN(b) * W;
        CHECK(rounds_exactly(X, W, x + b));
        CHECK(rounds_exactly(X, W, 0.0));  // a wrong estimate
        CHECK(rounds_exactly(X, W, -1e200));
        // As an opening's sums give it when e and b cancel: e + b widened by an ulp of e,
        // from which round_quotient starts at the quotient of X's and W's doubles.
        const double s = x + b, spread = (std::abs(x) + std::abs(s)) * 0x1p-52;
        const double want = round_to_nearest(Exact(X) / Exact(W));
        const double got = round_quotient(X, W, Interval(s - spread, s + spread));
        CHECK(std::memcmp(&got, &want, sizeof got) == 0);
      }
    }
  }
  // Ties go to even, both ways; exact zero is +0.
  for (const double x : {1.0, 3.0, -5.0, 0x1p-1000}) {
    const double half_ulp = (std::nextafter(x, HUGE_VAL) - x) / 2;
    CHECK(rounds_exactly(ExactN(x) + ExactN(half_ulp), ExactN(1), x));
    CHECK(rounds_exactly((ExactN(x) - ExactN(half_ulp)) * ExactN(3), ExactN(3), x));
  }
  CHECK(rounds_exactly(ExactN(0.0), ExactN(7.0), 0.0));
}

// Known points (planes through one point) and an expected result only save work: the
// intersection is the same, exactly, and a wrong guess is caught by the check.
TEST_CASE("halfspace_intersection: known points and an expected result give the same result") {
  const V3<Exact> apex = rational_apex();
  HalfSpaces hs = planes_through_apex(12);
  const MaybePolytope plain = checked(hs);
  REQUIRE(plain.polytope);
  // The apex as X / W = (35, 21, 15) / 105, on the twelve tilted planes.
  KnownPoints known;
  known.X = {{ExactN(35), ExactN(21), ExactN(15)}};
  known.W = {ExactN(105)};
  {
    RoundingGuard guard;
    known.Xi = {{Interval(35), Interval(21), Interval(15)}};
    known.Wi = {Interval(105)};
  }
  known.begin.assign(7, 0);
  for (int i = 0; i < 12; ++i) {
    known.point.push_back(0);
    known.begin.push_back(static_cast<int>(known.point.size()));
  }
  const MaybePolytope with_known = intersect_halfspaces(hs, {0, 0, 0}, {}, known);
  CHECK(with_known.route == HullRoute::incremental);
  CHECK(difference(with_known, plain) == "");
  CHECK(rounded_from_exact(with_known));
  // The result's own fans as the guess: taken and checked; as a guess for more planes
  // (one cuts the apex off), the check finds the plane it left out cutting it, and the
  // repair inserts it (or, with split off, where a polygon must be one vertex, the hull
  // computes the result): the same result.
  const Polytope& p = *plain.polytope;
  ExpectedVertices expected;
  expected.begin = p.fan_begin;
  for (int f : p.fan_face) expected.facets.push_back(p.face_source[f]);
  const MaybePolytope guessed = intersect_halfspaces(hs, {0, 0, 0}, {}, known, expected);
  CHECK(guessed.route == HullRoute::expected);
  CHECK(difference(guessed, plain) == "");
  HalfSpaces cut = hs;
  cut.push_back(plane(0, 0, 1, apex.z - Exact(1) / Exact(100), static_cast<int>(cut.size())));
  const MaybePolytope wrong = intersect_halfspaces(cut, {0, 0, 0}, {}, {}, expected);
  CHECK(wrong.route == HullRoute::repaired);
  CHECK(difference(wrong, checked(cut)) == "");
  expected.split = false;
  const MaybePolytope unsplit = intersect_halfspaces(cut, {0, 0, 0}, {}, {}, expected);
  CHECK(unsplit.route == HullRoute::incremental);
  CHECK(difference(unsplit, checked(cut)) == "");
}

// A guess whose triangles do not close into a surface (a vertex's polygon left out, one
// given twice, one turned round) is given up when its triangles are joined across their
// polygons' sides (each side a -> b with a < b searched once, joining its reverse too; or,
// with the edges given, two sides of one edge whose planes are not reversed): the hull
// computes the result, the same.
TEST_CASE("halfspace_intersection: a guess that is not a closed surface is given up") {
  const HalfSpaces hs = planes_through_apex(12);
  const MaybePolytope plain = checked(hs);
  REQUIRE(plain.polytope);
  const Polytope& p = *plain.polytope;
  const int nv = p.num_vertices();
  REQUIRE(nv >= 4);
  const auto fan = [&](int v) {
    std::vector<int> f;
    for (int j = p.fan_begin[v]; j < p.fan_begin[v + 1]; ++j)
      f.push_back(p.face_source[p.fan_face[j]]);
    return f;
  };
  const auto guess_of = [&](const std::vector<std::vector<int>>& fans) {
    ExpectedVertices e;
    e.begin.push_back(0);
    for (const auto& f : fans) {
      e.facets.insert(e.facets.end(), f.begin(), f.end());
      e.begin.push_back(static_cast<int>(e.facets.size()));
    }
    return e;
  };
  std::vector<std::vector<int>> fans;
  for (int v = 0; v < nv; ++v) fans.push_back(fan(v));
  const MaybePolytope whole = intersect_halfspaces(hs, {0, 0, 0}, {}, {}, guess_of(fans));
  CHECK(whole.route == HullRoute::expected);
  CHECK(difference(whole, plain) == "");
  std::vector<std::vector<std::vector<int>>> broken;
  broken.emplace_back(fans.begin(), fans.end() - 1);  // open
  broken.push_back(fans);
  broken.back().push_back(fans[0]);  // edges used twice
  broken.push_back(fans);
  std::reverse(broken.back()[1].begin(), broken.back()[1].end());  // turned round
  for (std::size_t k = 0; k < broken.size(); ++k) {
    CAPTURE(k);
    const MaybePolytope got = intersect_halfspaces(hs, {0, 0, 0}, {}, {}, guess_of(broken[k]));
    CHECK(got.route != HullRoute::expected);
    CHECK(got.route != HullRoute::repaired);
    CHECK(difference(got, plain) == "");
  }
  // The same fans joined by their edges (erode_polytope's way): taken whole; a fan turned
  // round (its sides' edges with it), or an edge out of range, given up.
  const auto with_edges = [&](ExpectedVertices e, int turned) {
    for (int v = 0; v < nv; ++v) {
      std::vector<int> edge(p.fan_edge.begin() + p.fan_begin[v],
                            p.fan_edge.begin() + p.fan_begin[v + 1]);
      // Side i of a fan turned round lies between its facets k - 1 - i and k - 2 - i.
      if (v == turned) {
        const int k = static_cast<int>(edge.size());
        std::vector<int> r(k);
        for (int i = 0; i < k; ++i) r[i] = edge[(2 * k - 2 - i) % k];
        edge = r;
      }
      e.edge.insert(e.edge.end(), edge.begin(), edge.end());
    }
    e.edges = p.num_edges();
    return e;
  };
  const MaybePolytope joined =
      intersect_halfspaces(hs, {0, 0, 0}, {}, {}, with_edges(guess_of(fans), -1));
  CHECK(joined.route == HullRoute::expected);
  CHECK(difference(joined, plain) == "");
  ExpectedVertices out_of_range = with_edges(guess_of(fans), -1);
  out_of_range.edge[0] = out_of_range.edges;
  ExpectedVertices turned = with_edges(guess_of(broken[2]), 1);
  for (const ExpectedVertices& e : {out_of_range, turned}) {
    const MaybePolytope got = intersect_halfspaces(hs, {0, 0, 0}, {}, {}, e);
    CHECK(got.route != HullRoute::expected);
    CHECK(got.route != HullRoute::repaired);
    CHECK(difference(got, plain) == "");
  }
}

// A closing erodes S = A (+) B by B: the guess (A, with S's translated facets) is taken
// when A's facets are planar, rejected for the UV sphere's nearly planar quads, and either
// way the result is the one erode_polytope's hull gives (which knows nothing of the sum).
TEST_CASE("halfspace_intersection: a closing's expected result") {
  const auto sample = [](const std::string& name) {
    return morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/" + name);
  };
  const Polytope B = make_operand(morph::test::scaled(sample("icosphere_80.off"), 0.25), "B");
  for (const char* name : {"icosphere_320.off", "cube.off", "uvsphere_1600.off"}) {
    INFO(name);
    const Polytope A = make_operand(sample(name), "A");
    const Polytope S = sum_polytope(A, B, fims_facets(A, B));
    const MaybePolytope closed = erode_sum(S, A, B);
    const MaybePolytope hull = erode_polytope(S, B, {.guess = false});
    CHECK(difference(closed, hull) == "");
    CHECK(rounded_from_exact(closed));
    CHECK((closed.route == HullRoute::expected) == (std::string(name) != "uvsphere_1600.off"));
  }
}

/// "" when two erosion inputs are the same exactly: half-spaces (normals, offsets, labels, in
/// order), hint, known points and guess.
std::string input_difference(const ErosionInput& got, const ErosionInput& want) {
  const auto same3 = [](const V3<ExactN>& a, const V3<ExactN>& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
  };
  // got's enclosure within want's (the closing encloses A's own vertices by their doubles,
  // tighter than Mpzf::to_interval may be), and around the exact value (checked below).
  const auto same_interval = [](const Interval& a, const Interval& b) {
    return a.inf() >= b.inf() && a.sup() <= b.sup();
  };
  if (got.halfspaces.size() != want.halfspaces.size()) return "half-space counts differ";
  for (std::size_t k = 0; k < got.halfspaces.size(); ++k) {
    const HalfSpace &g = got.halfspaces[k], &w = want.halfspaces[k];
    if (!same3(g.exact_normal(), w.exact_normal()))
      return "normal " + std::to_string(k) + " differs";
    if (g.exact_offset() != w.exact_offset() || g.denominator() != w.denominator())
      return "offset " + std::to_string(k) + " differs";
    if (g.source != w.source || g.element != w.element)
      return "labels of " + std::to_string(k) + " differ";
  }
  if (got.hint.x != want.hint.x || got.hint.y != want.hint.y || got.hint.z != want.hint.z)
    return "hints differ";
  const KnownPoints &p = got.known, &q = want.known;
  if (p.begin != q.begin || p.point != q.point) return "known incidences differ";
  if (p.size() != q.size()) return "known point counts differ";
  // (Either may hold its points as Mpzf or as double-doubles: compared by value.)
  for (int k = 0; k < p.size(); ++k) {
    const V3<ExactN> X = p.exact_X(k);
    const ExactN W = p.exact_W(k);
    if (!same3(X, q.exact_X(k)) || W != q.exact_W(k)) return "known point " + std::to_string(k);
    const auto encloses = [](const Interval& i, const ExactN& x) {
      return Exact(i.inf()) <= Exact(x) && Exact(x) <= Exact(i.sup());
    };
    if (!encloses(p.Xi[k].x, X.x) || !encloses(p.Xi[k].y, X.y) || !encloses(p.Xi[k].z, X.z) ||
        !encloses(p.Wi[k], W))
      return "known point " + std::to_string(k) + " outside its enclosure";
    if (!same_interval(p.Xi[k].x, q.Xi[k].x) || !same_interval(p.Xi[k].y, q.Xi[k].y) ||
        !same_interval(p.Xi[k].z, q.Xi[k].z) || !same_interval(p.Wi[k], q.Wi[k]))
      return "enclosure of known point " + std::to_string(k);
  }
  if (got.expected.begin != want.expected.begin || got.expected.facets != want.expected.facets ||
      got.expected.split != want.expected.split)
    return "guesses differ";
  return "";
}

// A closing's half-spaces come from A, B and the sum's facets (closing_input) without S:
// the very half-spaces, known points, guess and hint that erode_sum makes from S, so the
// same result. Elements off the origin, scaled by 2^+-200 or far from the origin, parallel
// facets and edges summed into polygons (integer polytopes, a cube by a cube, an unturned
// icosphere); nearly planar facets (the UV sphere's, a rotated cube's quads) go through S.
TEST_CASE("halfspace_intersection: a closing from the sum's facets, without the sum") {
  const auto sample = [](const std::string& name) {
    return morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/" + name);
  };
  using morph::test::scaled;
  using morph::test::translated;
  const morph::Mesh ball = scaled(sample("icosphere_80.off"), 0.25);
  // Turned, so that none of its facets or edges is parallel to the icospheres'.
  const morph::Mesh turned = morph::test::transformed(ball, morph::test::random_rotation(2));
  struct Case {
    std::string name;
    morph::Mesh a, b;
    int direct;  // whether closing_input takes it: 1 yes, 0 no (parallel or nearly planar
                 // facets), -1 either
  };
  std::vector<Case> cases = {
      {"icosphere_320 by a ball", sample("icosphere_320.off"), turned, 1},
      {"icosphere_320 by a ball off the origin", sample("icosphere_320.off"),
       translated(turned, {3, -2, 1.5}), 1},
      {"icosphere_320 by an unturned ball", sample("icosphere_320.off"), ball, 1},
      {"random_hull_200 by a rotated cube", sample("random_hull_200.off"),
       morph::test::rotated_cube_triangles(0.3, 5), 1},
      {"grid polytopes", morph::test::random_grid_polytope(60, 3),
       translated(scaled(morph::test::random_grid_polytope(20, 4), 0.25), {0.5, 0.25, -2}), 1},
      {"grid polytopes by 2^200", scaled(morph::test::random_grid_polytope(40, 5), 0x1p200),
       scaled(morph::test::random_grid_polytope(12, 6), 0x1p198), 1},
      {"grid polytopes by 2^-200", scaled(morph::test::random_grid_polytope(40, 7), 0x1p-200),
       scaled(morph::test::random_grid_polytope(12, 8), 0x1p-202), 1},
      {"far from the origin", translated(sample("icosphere_1280.off"), {3e4, -1e5, 7}),
       translated(turned, {-2e3, 3, 5e3}), 1},
      {"cylinder by a ball", sample("cylinder_16.off"), translated(ball, {0.1, 0.2, -0.3}), 1},
      {"cube by a cube", sample("cube.off"), translated(morph::test::cube(0.5), {2, 2, 2}), 1},
      {"integer polytopes", morph::test::random_integer_polytope(30, 11),
       morph::test::random_integer_polytope(12, 12, 1), 1},
      {"uvsphere_1600 by a ball", sample("uvsphere_1600.off"), turned, 0},
      {"icosphere_320 by rotated quads", sample("icosphere_320.off"),
       morph::test::rotated_cube_quads(0.3, 7), 0},
  };
  // Integer polytopes: parallel facets and edges, polygons, elements off the origin.
  for (std::uint64_t seed = 20; seed < 26; ++seed)
    cases.push_back({"integer polytopes, seed " + std::to_string(seed),
                     morph::test::random_integer_polytope(24, seed),
                     translated(morph::test::random_integer_polytope(10, seed + 100, 2),
                                {double(seed % 3), -1, 5}),
                     1});
  for (const Case& c : cases) {
    INFO(c.name);
    const Polytope A = make_operand(c.a, "A"), B = make_operand(c.b, "B");
    const SumFacets sum = fims_facets(A, B);
    const Polytope S = sum_polytope(A, B, sum);
    const ErosionInput want = erode_sum_input(S, A, B);
    const std::optional<ErosionInput> got = closing_input(sum, A, B);
    if (c.direct >= 0) CHECK(got.has_value() == (c.direct == 1));
    if (got && c.name.starts_with("icosphere_320 by a")) {
      // Its triangles' planes are fixed-point, left lazy (made from their words when read,
      // by input_difference below): none made yet.
      int lazy = 0;
      for (const HalfSpace& h : got->halfspaces) {
        if (!h.lazy) continue;
        ++lazy;
        CHECK(!h.has_exact_values());
        CHECK((h.has_normal_dd && h.has_offset_dd));
      }
      CHECK(lazy > 0);
    }
    if (got) CHECK(input_difference(*got, want) == "");
    // (S has no merged facets here: close_polytope takes S itself where closing_input
    // declines.)
    REQUIRE(S.num_faces() == sum.num_faces());
    // (Where closing_input declines, close_polytope splits A's vertices of S's guess: the
    // check's repair then takes off what vanishes and puts in what cuts, not the hull.)
    ErosionInput split = erode_sum_input(S, A, B);
    split.expected.split = !got;
    const MaybePolytope via_sum = close_polytope(A, B).eroded,
                        via_s = intersect_halfspaces(split.halfspaces, split.hint, {}, split.known,
                                                     split.expected);
    CHECK(difference(via_sum, via_s) == "");
    CHECK(via_sum.route == via_s.route);
    if (!got) CHECK(via_sum.route != HullRoute::incremental);
    if (c.name.starts_with("uvsphere")) CHECK(via_sum.route == HullRoute::repaired);
    CHECK(difference(via_sum, erode_sum(S, A, B)) == "");
    CHECK(rounded_from_exact(via_sum));
    CHECK(via_sum.rounded.face_element == via_s.rounded.face_element);
    if (!got) continue;
    // The check's walks over S's facets that are not A's start at their known points and
    // read incidences from them: the same result as by arithmetic alone (no known points,
    // so no guess: the incremental hull).
    const MaybePolytope plain = intersect_halfspaces(got->halfspaces, got->hint, {}, {}, {});
    CHECK(plain.route == HullRoute::incremental);
    CHECK(difference(plain, via_sum) == "");
    CHECK(plain.rounded.face_element == via_sum.rounded.face_element);
  }
}

// An erosion by a small element is A with its facets moved in: each vertex of A whose
// facets are moved by different vertices of B opens up into several vertices, which the
// guess finds by flipping the triangulation of the vertex's polygon of planes. It is taken
// (no hull), and the result is the hull's and the exact route's.
TEST_CASE("halfspace_intersection: an erosion by a small element is guessed from A") {
  const Polytope B = make_operand(morph::test::scaled(sample("icosphere_80.off"), 1.0 / 32), "B");
  const Polytope C = make_operand(morph::test::rotated_cube_triangles(1.0 / 16, 7), "C");
  for (const char* name : {"icosphere_320.off", "icosphere_1280.off", "dodecahedron.off",
                           "snub_dodecahedron.off", "truncated_octahedron.off", "cylinder_16.off",
                           "random_hull_200.off", "uvsphere_1600.off", "cube.off"}) {
    CAPTURE(std::string(name));
    const Polytope A = make_operand(sample(name), "A");
    for (const Polytope* element : {&B, &C}) {
      const MaybePolytope r = eroded_three_ways(A, *element);
      REQUIRE(r.polytope);
      CHECK(r.route == HullRoute::expected);
      CHECK(r.polytope->num_faces() == A.num_faces());
      // The spheres' vertices of degree 5 or more opened up (their facets are moved by
      // different vertices of the element).
      CHECK(r.polytope->num_vertices() >= A.num_vertices());
      if (std::string(name).find("sphere") != std::string::npos)
        CHECK(r.polytope->num_vertices() > A.num_vertices());
    }
  }
}

// An erosion's half-spaces of quadrilaterals (a UV sphere's, not exactly planar; a cube's,
// whose parallel facets tie B's vertices) against exact evaluation: the normal is A's exact
// Newell normal, the offset max_k <n, p_k> - max_j <n, b_j> over A's corners and all of B's
// vertices, and every known point of the facet lies exactly on its plane. Scaled by 2^+-200
// and shifted far from the origin; each erosion then equal by the three routes.
TEST_CASE("halfspace_intersection: an erosion's quadrilateral half-spaces are exact") {
  const morph::Mesh& uv = sample("uvsphere_1600.off");
  const morph::Mesh snub = morph::test::scaled(sample("snub_dodecahedron.off"), 0.25);
  struct Case {
    const char* what;
    morph::Mesh A, B;
  };
  const Case cases[] = {
      {"uvsphere by a snub dodecahedron", uv, snub},
      {"uvsphere by a cube", uv, morph::test::cube(0.25)},
      {"uvsphere scaled by 2^200", morph::test::scaled(uv, 0x1p200),
       morph::test::scaled(snub, 0x1p200)},
      {"uvsphere scaled by 2^-200", morph::test::scaled(uv, 0x1p-200),
       morph::test::scaled(snub, 0x1p-200)},
      {"uvsphere far from the origin", morph::test::translated(uv, {1e6, -3e5, 7e5}), snub},
      {"cube by a cube", morph::test::cube(2), morph::test::cube(0.5)},
      {"rotated cube by a rotated cube", morph::test::rotated_cube_quads(2, 5),
       morph::test::rotated_cube_quads(0.5, 9)},
  };
  for (const Case& c : cases) {
    CAPTURE(std::string(c.what));
    const Polytope A = make_operand(c.A, "A"), B = make_operand(c.B, "B");
    const ErosionInput in = erode_sum_input(A, A, B);
    REQUIRE(static_cast<int>(in.halfspaces.size()) == A.num_faces());
    int quads = 0;
    for (int f = 0; f < A.num_faces(); ++f) {
      if (A.degree(f) != 4) continue;
      ++quads;
      const HalfSpace& h = in.halfspaces[f];
      const V3<ExactN>& n = A.exact_normal(f);
      const V3<ExactN>& hn = h.exact_normal();
      CHECK((hn.x == n.x && hn.y == n.y && hn.z == n.z));
      std::optional<ExactN> top_a, top_b;
      for (int k = 0; k < 4; ++k) {
        const ExactN d = dot(n, to_exact_n(A.points[A.corner(f, k)]));
        if (!top_a || d > *top_a) top_a = d;
      }
      for (const auto& b : B.points) {
        const ExactN d = dot(n, to_exact_n(b));
        if (!top_b || d > *top_b) top_b = d;
      }
      CHECK(h.denominator() == ExactN(1));
      CHECK(h.exact_offset() == *top_a - *top_b);
      for (int j = in.known.begin[f]; j < in.known.begin[f + 1]; ++j) {
        const int k = in.known.point[j];
        CHECK(dot(n, in.known.exact_X(k)) == h.exact_offset() * in.known.exact_W(k));
      }
    }
    CHECK(quads > 0);
    const MaybePolytope r = eroded_three_ways(A, B);
    REQUIRE(r.polytope);
  }
}

// An erosion of double points keeps its known points v - b as double-doubles (exact:
// two_sum), each vertex there taking that copy as its precise and its exact value. The same
// input with the points as Mpzf gives the same polytope, exact point by exact point, by the
// same route (the guess, repaired), its rounding the exact one; also scaled by 2^+-200 (the precise
// stage's range holds the copies) and far from the origin (lo non-zero: the points are not
// doubles).
TEST_CASE("halfspace_intersection: known points as double-doubles erode as Mpzf ones") {
  const morph::Mesh& uv = sample("uvsphere_1600.off");
  const morph::Mesh snub = morph::test::scaled(sample("snub_dodecahedron.off"), 0.25);
  const morph::Mesh ico = morph::make_icosphere(1.0, 3);
  const morph::Mesh small = morph::make_icosphere(0.25, 1);
  struct Case {
    const char* what;
    morph::Mesh A, B;
  };
  const Case cases[] = {
      {"uvsphere by a snub dodecahedron", uv, snub},
      {"icosphere by a small icosphere", ico, small},
      {"icosphere scaled by 2^200", morph::test::scaled(ico, 0x1p200),
       morph::test::scaled(small, 0x1p200)},
      {"icosphere scaled by 2^-200", morph::test::scaled(ico, 0x1p-200),
       morph::test::scaled(small, 0x1p-200)},
      {"uvsphere far from the origin", morph::test::translated(uv, {1e6, -3e5, 7e5}), snub},
  };
  for (const Case& c : cases) {
    CAPTURE(std::string(c.what));
    const Polytope A = make_operand(c.A, "A"), B = make_operand(c.B, "B");
    const ErosionInput in = erode_sum_input(A, A, B);
    REQUIRE(in.known.size() > 0);
    CHECK(static_cast<int>(in.known.dd.size()) == in.known.size());
    CHECK(in.known.X.empty());
    KnownPoints mpzf = in.known;
    mpzf.dd.clear();
    int not_doubles = 0;
    for (int k = 0; k < in.known.size(); ++k) {
      mpzf.X.push_back(in.known.exact_X(k));
      mpzf.W.push_back(ExactN(1));
      const V3<DD>& d = in.known.dd[k];
      not_doubles += d.x.lo != 0 || d.y.lo != 0 || d.z.lo != 0;
    }
    if (std::string(c.what) == "uvsphere far from the origin") CHECK(not_doubles > 0);
    IntersectOptions options;
    options.polytope = true;
    const ExpectedVertices guess{A.fan_begin, A.fan_face};  // erode_polytope's
    const MaybePolytope got =
        intersect_halfspaces(in.halfspaces, in.hint, options, in.known, guess);
    const MaybePolytope want = intersect_halfspaces(in.halfspaces, in.hint, options, mpzf, guess);
    REQUIRE(got.polytope);
    CHECK(difference(got, want) == "");
    CHECK(got.route == want.route);
    CHECK(got.route == HullRoute::repaired);
    CHECK(rounded_from_exact(got));
  }
}

// An eroded polytope reads its facets' exact normals from the erosion's half-spaces (kept
// by the polytope, made exact on first read), from any thread, also once its operands are
// gone: the same normals as the general build's copies, each the same reference each time.
TEST_CASE("halfspace_intersection: an eroded polytope's normals are its half-spaces'") {
  const auto eroded = [](bool direct) {
    const Polytope A = make_operand(morph::make_icosphere(1.0, 3), "A");
    const Polytope B = make_operand(morph::make_icosphere(0.25, 1), "B");
    return erode_polytope(A, B, {.direct_polytope = direct});
  };
  const MaybePolytope lazy = eroded(true), copied = eroded(false);
  REQUIRE(lazy.polytope);
  REQUIRE(copied.polytope);
  const Polytope &p = *lazy.polytope, &q = *copied.polytope;
  REQUIRE(p.given_normals.size() == static_cast<std::size_t>(p.num_faces()));
  REQUIRE(q.given_normals.size() == p.given_normals.size());
  std::vector<const V3<ExactN>*> first(p.num_faces());
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int f = t; f < p.num_faces(); f += 4) first[f] = &p.given_normals[f];
    });
  for (std::thread& t : threads) t.join();
  int differ = 0;
  for (int f = 0; f < p.num_faces(); ++f) {
    const V3<ExactN>&m = p.given_normals[f], &n = q.given_normals[f];
    differ += &m != first[f] || m.x != n.x || m.y != n.y || m.z != n.z;
  }
  CHECK(differ == 0);
  CHECK(polytope_difference(p, q) == "");
}

// An eroded polytope's unit normals come from its half-spaces' precise normals (their
// double-double copies, or their exact normals where there is none: a UV sphere's facets
// near its poles), and its vertices' enclosures from their precise coordinates: as tight as
// a double operand's. From the vertices' meets (nearly parallel planes) they were about 2e-5
// and 5e-11 wide at icosphere level 6 by its rotated copy, and the dilation of an opening
// then went past its double filters nearly everywhere.
TEST_CASE("halfspace_intersection: an eroded polytope's unit normals and enclosures are tight") {
  const morph::Mesh ico = morph::make_icosphere(1.0, 3);
  struct Case {
    morph::Mesh a, b;
  };
  for (const Case& c :
       {Case{ico, morph::test::scaled(
                      morph::test::transformed(ico, morph::test::random_rotation(3)), 0.25)},
        Case{ico, morph::make_icosphere(0.25, 1)},
        Case{morph::make_uv_sphere(1.0, 24), morph::make_snub_dodecahedron(0.25)}}) {
    const Polytope A = make_operand(c.a, "A"), B = make_operand(c.b, "B");
    const MaybePolytope e = erode_polytope(A, B);
    REQUIRE(e.polytope);
    const Polytope& E = *e.polytope;
    REQUIRE(!E.exact_points.empty());
    int tight = 0;
    for (int f = 0; f < E.num_faces(); ++f) {
      CHECK(unit_normal_holds(E, f));
      tight += E.unit_normals[f].error < 1e-14;
    }
    CHECK(tight == E.num_faces());
    int narrow = 0;
    for (int v = 0; v < E.num_vertices(); ++v) {
      const V3<Interval>& box = E.exact_points.enclosure[v];
      const V3<ExactN>& X = E.exact_points.X(v);
      const ExactN& W = E.exact_points.W(v);
      const auto inside = [&](const Interval& i, const ExactN& x) {
        return ExactN(i.inf()) * W <= x && x <= ExactN(i.sup()) * W;
      };
      CHECK((inside(box.x, X.x) && inside(box.y, X.y) && inside(box.z, X.z)));
      // Widths in units of the vertex's largest coordinate's ulp.
      const double unit =
          std::max({std::abs(box.x.inf()), std::abs(box.y.inf()), std::abs(box.z.inf())}) * 0x1p-52;
      const auto ulps = [&](const Interval& i) { return (i.sup() - i.inf()) / unit; };
      narrow += ulps(box.x) <= 8 && ulps(box.y) <= 8 && ulps(box.z) <= 8;
    }
    CHECK(narrow >= E.num_vertices() * 9 / 10);
  }
}

// An erosion's triangles of double points in a small frame leave their exact normal and
// offset lazy (made from fixed-point words on first read): zero until then, and then the
// exact values, (q - p) x (r - p) and <n, p> - max_j <n, b_j>, also when several threads
// ask for them at once (one makes them, the others wait); the erosion reads them only where
// a filter cannot decide (and for a polytope), with the same result as an eager copy's.
TEST_CASE("halfspace_intersection: an erosion's lazy exact planes are the exact values") {
  const morph::Mesh b =
      morph::test::transformed(sample("icosphere_80.off"), morph::test::random_rotation(5));
  // (The last is scaled near the double-double copies' range: some offsets may leave it,
  // and are then made eagerly, with the same values.)
  struct Case {
    morph::Mesh a;
    double scale;
    bool lazy;
  };
  for (const Case& c :
       {Case{sample("icosphere_320.off"), 1.0 / 8, true},
        Case{sample("uvsphere_1600.off"), 1.0 / 32, true},
        Case{morph::test::scaled(sample("icosphere_320.off"), 0x1p200), 0x1p197, false}}) {
    const morph::Mesh& a = c.a;
    const double scale = c.scale;
    const Polytope A = make_operand(a, "A");
    const Polytope B = make_operand(morph::test::scaled(b, scale), "B");
    const ErosionInput in = erode_sum_input(A, A, B);
    REQUIRE(static_cast<int>(in.halfspaces.size()) == A.num_faces());
    // The expected values, in Mpzf.
    std::vector<V3<ExactN>> normal(A.num_faces());
    std::vector<ExactN> offset(A.num_faces());
    int lazy = 0;
    for (int f = 0; f < A.num_faces(); ++f) {
      const HalfSpace& h = in.halfspaces[f];
      if (A.degree(f) != 3) continue;
      const V3<double>&p = A.points[A.corner(f, 0)], &q = A.points[A.corner(f, 1)],
            &r = A.points[A.corner(f, 2)];
      normal[f] = cross(to_exact_n(q) - to_exact_n(p), to_exact_n(r) - to_exact_n(p));
      std::optional<ExactN> top_b;
      for (const auto& v : B.points) {
        const ExactN d = dot(normal[f], to_exact_n(v));
        if (!top_b || d > *top_b) top_b = d;
      }
      offset[f] = dot(normal[f], to_exact_n(p)) - *top_b;
      if (!h.lazy) continue;
      ++lazy;
      CHECK(h.has_normal_dd);
      CHECK(h.has_offset_dd);
      CHECK(h.denominator() == ExactN(1));
      // Not made yet (the input stage reads it only for B's edges and facets along n).
      if (!h.made.state.load()) CHECK(!h.has_exact_values());
    }
    if (c.lazy) CHECK(lazy > 0);
    // Copies, so that nothing is made yet where the input did not make it: four threads
    // read them all at once, in different orders.
    const HalfSpaces hs = in.halfspaces;
    constexpr int kThreads = 4;
    std::vector<std::vector<char>> same(kThreads, std::vector<char>(hs.size(), 0));
    {
      std::vector<std::thread> threads;
      for (int t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
          const int n = static_cast<int>(hs.size());
          for (int k = 0; k < n; ++k) {
            const int f = t % 2 == 0 ? k : n - 1 - k;
            const V3<ExactN>& m = hs[f].exact_normal();
            same[t][f] =
                A.degree(f) != 3 || (m.x == normal[f].x && m.y == normal[f].y &&
                                     m.z == normal[f].z && hs[f].exact_offset() == offset[f]);
          }
        });
      for (std::thread& t : threads) t.join();
    }
    for (int t = 0; t < kThreads; ++t)
      CHECK(std::count(same[t].begin(), same[t].end(), 1) == static_cast<long>(hs.size()));
    // The intersection of lazy half-spaces (an opening's polytope reads every normal) is the
    // one of their eager copies.
    HalfSpaces eager = in.halfspaces;
    for (HalfSpace& h : eager) {
      h.exact_normal();
      h.lazy = false;
    }
    for (const bool guess : {true, false}) {
      IntersectOptions options;
      options.guess = guess;
      const MaybePolytope x =
          intersect_halfspaces(in.halfspaces, in.hint, options, in.known, in.expected);
      const MaybePolytope y = intersect_halfspaces(eager, in.hint, options, in.known, in.expected);
      REQUIRE(x.polytope);
      REQUIRE(y.polytope);
      REQUIRE(x.rounded.points.size() == y.rounded.points.size());
      for (std::size_t k = 0; k < x.rounded.points.size(); ++k) {
        const V3<double>&u = x.rounded.points[k], &v = y.rounded.points[k];
        CHECK((u.x == v.x && u.y == v.y && u.z == v.z));
      }
      CHECK(x.rounded.corner_vertex == y.rounded.corner_vertex);
      for (int f = 0; f < x.polytope->num_faces(); ++f) {
        const V3<ExactN>&u = x.polytope->exact_normal(f), &v = y.polytope->exact_normal(f);
        CHECK((u.x == v.x && u.y == v.y && u.z == v.z));
      }
    }
  }
}

// The element of the random erosion and opening tests: an integer polytope (parallel
// facets) every third seed, else a random polytope of 11 to 22 vertices.
namespace {
morph::Mesh random_element(std::uint64_t seed) {
  return seed % 3 == 0
             ? morph::test::random_integer_polytope(8, seed, 2)
             : morph::test::random_sphere_polytope(10 + static_cast<int>(seed), seed + 50);
}
}  // namespace

// Random polytopes and elements of several sizes: whether the guess is taken or not (a
// facet of A vanishes, an edge collapses), the result is the hull's and the exact route's.
TEST_CASE("halfspace_intersection: erosions of random polytopes, guessed or not") {
  int guessed = 0, repaired = 0, rejected = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    for (const double size : {0.02, 0.1, 0.4}) {
      CAPTURE(seed);
      CAPTURE(size);
      const Polytope A = make_operand(morph::test::random_sphere_polytope(60, seed), "A");
      const morph::Mesh B = random_element(seed);
      const MaybePolytope r = eroded_three_ways(A, make_operand(morph::test::scaled(B, size), "B"));
      (r.route == HullRoute::expected   ? guessed
       : r.route == HullRoute::repaired ? repaired
                                        : rejected)++;
    }
  }
  MESSAGE(guessed << " erosions guessed, " << repaired << " repaired, " << rejected
                  << " computed by the hull");
  CHECK(guessed > 0);
  CHECK(repaired > 0);
}

// Guesses that are wrong: a sliver facet of A (a corner of the cube cut by 2^-10) vanishes
// under an octahedron (it moves the cube's facets and the sliver's by its radius, which cuts
// the corner's vertex off the sliver's plane), and a large element collapses the edges of a sphere.
// The check rejects the guess as it is; flips repair it (the sliver's plane, of three
// neighbours, is removed), and the result is the hull's.
TEST_CASE("halfspace_intersection: an erosion's wrong guess is rejected") {
  std::vector<morph::Point> corners;
  for (int s = 0; s < 8; ++s) {
    const morph::Point c{s & 1 ? 1.0 : -1.0, s & 2 ? 1.0 : -1.0, s & 4 ? 1.0 : -1.0};
    if (s != 7) {
      corners.push_back(c);
      continue;
    }
    const double cut = 1 - 0x1p-10;
    corners.push_back({cut, 1, 1});
    corners.push_back({1, cut, 1});
    corners.push_back({1, 1, cut});
  }
  const Polytope A = make_operand(morph::test::convex_hull_mesh(corners), "A");
  REQUIRE(A.num_faces() >= 7);
  const MaybePolytope sliver =
      eroded_three_ways(A, make_operand(morph::test::octahedron(0.25), "B"));
  REQUIRE(sliver.polytope);
  CHECK(sliver.route == HullRoute::repaired);
  CHECK(sliver.polytope->num_vertices() == 8);  // a cube: the sliver is gone
  // A sliver 2^-20 thin (the thinnest the operand checks take), scaled by 2^+-200 and far
  // from the origin: repaired alike.
  {
    std::vector<morph::Point> thin(corners.begin(), corners.end() - 3);
    const double cut = 1 - 0x1p-20;
    thin.push_back({cut, 1, 1});
    thin.push_back({1, cut, 1});
    thin.push_back({1, 1, cut});
    const morph::Mesh a = morph::test::convex_hull_mesh(thin), b = morph::test::octahedron(0.25);
    const std::pair<morph::Mesh, morph::Mesh> cases[] = {
        {a, b},
        {morph::test::scaled(a, 0x1p200), morph::test::scaled(b, 0x1p200)},
        {morph::test::scaled(a, 0x1p-200), morph::test::scaled(b, 0x1p-200)},
        {morph::test::translated(a, {1e6, -3e5, 7e5}), b},
    };
    for (const auto& [ma, mb] : cases) {
      const MaybePolytope r = eroded_three_ways(make_operand(ma, "A"), make_operand(mb, "B"));
      REQUIRE(r.polytope);
      CHECK(r.route == HullRoute::repaired);
      CHECK(r.polytope->num_vertices() == 8);
    }
  }
  // A cone's apex of degree 256 opens up into many vertices: the flips give up after 4 per
  // corner (the hull is then cheaper); either way the result is the hull's.
  std::vector<morph::Point> cone{{0, 0, 1}};
  for (int i = 0; i < 256; ++i) {
    const double t = 2 * M_PI * i / 256;
    cone.push_back({std::cos(t), std::sin(t), -1});
  }
  const MaybePolytope apex = eroded_three_ways(
      make_operand(morph::test::convex_hull_mesh(cone), "A"),
      make_operand(morph::test::scaled(sample("icosphere_320.off"), 1.0 / 16), "B"));
  REQUIRE(apex.polytope);
  const Polytope S = make_operand(sample("icosphere_320.off"), "A");
  const MaybePolytope big = eroded_three_ways(
      S, make_operand(morph::test::scaled(morph::test::transformed(sample("icosphere_80.off"),
                                                                   morph::test::random_rotation(3)),
                                          0.6),
                      "B"));
  REQUIRE(big.polytope);
  CHECK(big.route == HullRoute::repaired);
}

// The guess's flips decide exactly: an element 2^-40 times A's size (the vertices it opens up
// lie within rounding of each other, so the filters fail and exact signs decide), operands
// scaled by 2^+-200, and A shifted far from the origin.
TEST_CASE("halfspace_intersection: an erosion's guess on tiny, huge and far operands") {
  const morph::Mesh& a = sample("icosphere_320.off");
  const morph::Mesh b =
      morph::test::transformed(sample("icosphere_80.off"), morph::test::random_rotation(11));
  struct Case {
    const char* what;
    morph::Mesh A, B;
  };
  const Case cases[] = {
      {"element 2^-40", a, morph::test::scaled(b, 0x1p-40)},
      {"scaled by 2^200", morph::test::scaled(a, 0x1p200), morph::test::scaled(b, 0x1p195)},
      {"scaled by 2^-200", morph::test::scaled(a, 0x1p-200), morph::test::scaled(b, 0x1p-205)},
      {"far from the origin", morph::test::translated(a, {1e6, -3e5, 7e5}),
       morph::test::scaled(b, 1.0 / 32)},
  };
  for (const Case& c : cases) {
    CAPTURE(std::string(c.what));
    const Polytope A = make_operand(c.A, "A");
    const MaybePolytope r = eroded_three_ways(A, make_operand(c.B, "B"));
    REQUIRE(r.polytope);
    CHECK(r.route == HullRoute::expected);
    CHECK(r.polytope->num_faces() == A.num_faces());
  }
}

// Vertices of high degree (a UV sphere's poles, a cone's apex): where facets vanish near them
// (the UV sphere's thin facets at the poles) the guess is wrong and repaired by flips (edges
// flipped, vanished planes removed), and a right one is taken as it is (a small element; one
// 2^-40 times A's size, whose opened-up vertices lie within rounding of each other, so exact
// signs decide): scaled by 2^+-200 and far from the origin, each result the hull's and the
// exact route's.
TEST_CASE("halfspace_intersection: an erosion's guess near vertices of high degree") {
  const morph::Mesh& uv = sample("uvsphere_1600.off");
  const morph::Mesh snub = morph::test::scaled(sample("snub_dodecahedron.off"), 0.25);
  std::vector<morph::Point> cone_points{{0, 0, 1}};
  for (int i = 0; i < 48; ++i) {
    const double t = 2 * M_PI * i / 48;
    cone_points.push_back({std::cos(t), std::sin(t), -1});
  }
  const morph::Mesh cone = morph::test::convex_hull_mesh(cone_points);
  const morph::Mesh ball =
      morph::test::transformed(sample("icosphere_80.off"), morph::test::random_rotation(5));
  struct Case {
    const char* what;
    morph::Mesh A, B;
    bool vanish;  // facets of A vanish: the guess is repaired
  };
  const Case cases[] = {
      {"uvsphere by a snub dodecahedron", uv, snub, true},
      {"uvsphere scaled by 2^200", morph::test::scaled(uv, 0x1p200),
       morph::test::scaled(snub, 0x1p200), true},
      {"uvsphere scaled by 2^-200", morph::test::scaled(uv, 0x1p-200),
       morph::test::scaled(snub, 0x1p-200), true},
      {"uvsphere far from the origin", morph::test::translated(uv, {1e6, -3e5, 7e5}), snub, true},
      {"uvsphere by a small ball", uv, morph::test::scaled(ball, 1.0 / 64), false},
      {"uvsphere by a ball 2^-40", uv, morph::test::scaled(ball, 0x1p-40), false},
      {"cone by a ball 2^-40", cone, morph::test::scaled(ball, 0x1p-40), false},
      {"cone scaled by 2^200", morph::test::scaled(cone, 0x1p200),
       morph::test::scaled(ball, 0x1p190), false},
      {"cone scaled by 2^-200", morph::test::scaled(cone, 0x1p-200),
       morph::test::scaled(ball, 0x1p-210), false},
      {"cone far from the origin", morph::test::translated(cone, {1e6, -3e5, 7e5}),
       morph::test::scaled(ball, 1.0 / 64), false},
  };
  for (const Case& c : cases) {
    CAPTURE(std::string(c.what));
    const Polytope A = make_operand(c.A, "A");
    const MaybePolytope r = eroded_three_ways(A, make_operand(c.B, "B"));
    REQUIRE(r.polytope);
    CHECK(r.route == (c.vanish ? HullRoute::repaired : HullRoute::expected));
    CHECK((r.polytope->num_faces() < A.num_faces()) == c.vanish);
  }
}
// Where the repair's flips get stuck: a UV sphere's rows of quadrilaterals near a pole that
// vanish together (each has four neighbours; the flip across the row would make an inverted
// triangle of three nearly collinear dual points, and no neighbour has three). Such an
// edge's folded end lies beneath the triangle of the other three planes, and the repair
// takes it off at once, its neighbours' polygon made a fan (IntersectOptions::
// remove_beneath). Without that, it lifts such planes off the surface when every edge is
// stuck, flips on, and inserts them again where they cut the surface (here 4 lifts with one
// inserted back for the cube, 11 with one for the snub dodecahedron); before either, it gave
// up and the incremental hull ran. The result is the hull's and the exact route's.
TEST_CASE("halfspace_intersection: an erosion's repair lifts planes its flips cannot reach") {
  struct Case {
    int n;
    morph::Mesh B;
  };
  const Case cases[] = {
      {38, morph::test::cube(0.3)},
      {66, morph::test::scaled(sample("snub_dodecahedron.off"), 0.25)},
      // The pole's polygon of 98 planes stops flipping (kFlipsPerCorner; the guess was
      // given up there) and the repair goes on.
      {98, morph::test::cube(0.3)},
  };
  for (const Case& c : cases) {
    CAPTURE(c.n);
    const Polytope A = make_operand(morph::make_uv_sphere(1.0, c.n), "A");
    const Polytope B = make_operand(c.B, "B");
    const MaybePolytope r = eroded_three_ways(A, B);
    REQUIRE(r.polytope);
    CHECK(r.route == HullRoute::repaired);
    CHECK(r.polytope->num_faces() < A.num_faces());
    RepairCounts counts, lifting;
    CHECK(difference(erode_polytope(A, B, {.counts = &counts}), r) == "");
    CHECK(counts.fan_removals > 0);
    CHECK(counts.flips > 0);
    // Without the fans, the repair lifts planes and puts back some that bound the result.
    CHECK(difference(erode_polytope(A, B, {.counts = &lifting, .remove_beneath = false}), r) == "");
    CHECK(lifting.fan_removals == 0);
    CHECK(lifting.lifts > 0);
    CHECK(lifting.insertions > 0);
    CHECK(lifting.cuts > 0);
    // The fans take off planes that flips, lifts and insertions took off before, and all that
    // vanish are removed for good.
    CHECK(counts.flips < lifting.flips);
    CHECK(counts.lifts < lifting.lifts);
  }
}

// The walks to a plane's normal cone (walk_to_cone) stay short: an insertion starts at a
// triangle of a former neighbour, or where the last one ended (7.7 steps an insertion here;
// 20.5 following a removed start's stale links, whose slots may have been taken anywhere;
// climbs from triangle 0, often the opposite pole, took 163 at n = 320), and the check's
// planes off the candidate at the previous plane's vertex or at the triangle over their dual
// points (7.3). Counts, not times: the same on any machine. (Lifts, hence insertions, are
// rare since the repair removes the folded ends of stuck edges: here without that.)
TEST_CASE("halfspace_intersection: planes put back walk a few triangles to their cones") {
  const Polytope A = make_operand(morph::make_uv_sphere(1.0, 120), "A");
  const Polytope B = make_operand(morph::test::cube(0.3), "B");
  RepairCounts counts;
  const MaybePolytope r = erode_polytope(A, B, {.counts = &counts, .remove_beneath = false});
  REQUIRE(r.polytope);
  CHECK(r.route == HullRoute::repaired);
  CHECK(difference(r, erode_polytope(A, B, {.guess = false})) == "");
  CHECK(counts.flips > 0);
  CHECK(counts.removals > 0);
  CHECK(counts.lifts > 0);
  REQUIRE(counts.insertions > 0);
  CAPTURE(counts.insertions);
  CAPTURE(counts.insert_steps);
  CHECK(counts.insert_steps < 16 * counts.insertions);
  REQUIRE(counts.check_planes > 0);
  CAPTURE(counts.check_planes);
  CAPTURE(counts.check_steps);
  CHECK(counts.check_steps < 16 * counts.check_planes);
}

// A large guess's repair on several threads runs first in six regions, in parallel (each
// worker acts where all it touches is its own, and leaves the edges across the borders to
// passes over the whole surface): the same polytope, field by field, as one pass over the
// whole surface, on one thread or two, with the same actions whatever the threads. Here
// the regions are forced on small surfaces and on one thread (repair_regions_from 1,
// repair_regions_on_one_thread); a UV sphere's poles gather the work into two of them.
TEST_CASE("halfspace_intersection: a repair in regions gives the whole surface's result") {
  struct Case {
    morph::Mesh A, B;
  };
  const Case cases[] = {
      {morph::make_uv_sphere(1.0, 120), morph::test::cube(0.3)},
      {morph::make_uv_sphere(1.0, 66), morph::test::scaled(sample("snub_dodecahedron.off"), 0.25)},
      {morph::make_icosphere(1.0, 4), morph::make_icosphere(0.25, 1)},
  };
  for (const Case& c : cases) {
    const Polytope A = make_operand(c.A, "A");
    const Polytope B = make_operand(c.B, "B");
    CAPTURE(A.num_faces());
    RepairCounts whole;
    const MaybePolytope expected =
        erode_polytope(A, B, {.counts = &whole, .repair_regions_from = 0});
    REQUIRE(expected.polytope);
    CHECK(expected.route == HullRoute::repaired);
    CHECK(whole.regions == 0);
    CHECK(difference(expected, erode_polytope(A, B, {.incremental = false})) == "");
    RepairCounts first;
    for (const int threads : {1, 2}) {
      CAPTURE(threads);
      RepairCounts counts;
      const MaybePolytope r = morph::detail::run_with_threads(threads, [&] {
        return erode_polytope(
            A, B,
            {.counts = &counts, .repair_regions_from = 1, .repair_regions_on_one_thread = true});
      });
      REQUIRE(r.polytope);
      CHECK(r.route == HullRoute::repaired);
      CHECK(difference(r, expected) == "");
      CHECK(polytope_difference(*r.polytope, *expected.polytope, /*projective=*/true) == "");
      CHECK(counts.regions == 6);
      CHECK(counts.handed_over > 0);
      CHECK(counts.flips > 0);
      if (threads == 1) {
        first = counts;
        continue;
      }
      check_same_actions(counts, first);
      CHECK(counts.dual_decided == first.dual_decided);
    }
  }
}

// The allocator of the largest arrays (huge_pages.h): blocks from operator new below
// kHugeBlock, mapped with huge-page advice above it; a vector growing across the threshold
// keeps its values, and copies, moves and shrinks free what they should (the sanitizer
// build checks the frees).
TEST_CASE("halfspace_intersection: the huge-page allocator holds what it is given") {
  using Vector = std::vector<std::uint64_t, morph::detail::HugePageAllocator<std::uint64_t>>;
  const std::size_t n = 3 * morph::detail::kHugeBlock / sizeof(std::uint64_t);
  Vector v;
  for (std::size_t i = 0; i < n; ++i) v.push_back(i * 2654435761u);
  REQUIRE(v.size() == n);
  CHECK(v.capacity() * sizeof(std::uint64_t) >= morph::detail::kHugeBlock);
  Vector copy = v;
  bool same = true;
  for (std::size_t i = 0; i < n; ++i) same = same && copy[i] == i * 2654435761u;
  CHECK(same);
  Vector moved = std::move(copy);
  CHECK(moved.size() == n);
  moved.resize(16);
  moved.shrink_to_fit();
  CHECK(moved.size() == 16);
  CHECK(moved[15] == std::uint64_t{15} * 2654435761u);
  Vector small(100, 7);
  CHECK(small[99] == 7);
}

// The repair's and the check's first filter, on the planes' dual points (32 bytes a plane),
// decides as the planes' own filters and exact values do: the same flips, removals, lifts,
// insertions and walks with it and without, and the same result. It decides nearly all
// tests on an icosphere, and leaves to the planes those of four planes through one point or
// nearly so (a UV sphere's nearly planar quadrilaterals, its poles), and orientations of
// three normals in one plane through o (the icosphere's facets along its mirror planes,
// which the fans of removed planes meet: 568 of 16,060 tests here, 328 of 22,633 with
// lifts).
TEST_CASE("halfspace_intersection: the dual points' filter decides as the planes do") {
  struct Case {
    morph::Mesh A, B;
    bool well_conditioned;
  };
  const Case cases[] = {
      {morph::make_uv_sphere(1.0, 120), morph::test::cube(0.3), false},
      {morph::make_uv_sphere(1.0, 66), morph::test::scaled(sample("snub_dodecahedron.off"), 0.25),
       false},
      {morph::make_icosphere(1.0, 4), morph::make_icosphere(0.25, 1), true},
  };
  for (const Case& c : cases) {
    const Polytope A = make_operand(c.A, "A");
    const Polytope B = make_operand(c.B, "B");
    CAPTURE(A.num_faces());
    RepairCounts with, without, lifting, lifting_without;
    const MaybePolytope r = erode_polytope(A, B, {.counts = &with});
    REQUIRE(r.polytope);
    CHECK(r.route == HullRoute::repaired);
    CHECK(difference(erode_polytope(A, B, {.counts = &without, .dual_filter = false}), r) == "");
    CHECK(with.flips > 0);
    check_same_actions(with, without);
    CHECK(without.dual_decided + without.dual_undecided == 0);
    // The repair that lifts (no fans) likewise.
    CHECK(difference(erode_polytope(A, B, {.counts = &lifting, .remove_beneath = false}), r) == "");
    CHECK(
        difference(
            erode_polytope(
                A, B, {.counts = &lifting_without, .dual_filter = false, .remove_beneath = false}),
            r) == "");
    check_same_actions(lifting, lifting_without);
    CAPTURE(with.dual_decided);
    CAPTURE(with.dual_undecided);
    CAPTURE(lifting.dual_decided);
    CAPTURE(lifting.dual_undecided);
    CHECK(with.dual_decided > 10 * with.dual_undecided);
    CHECK(lifting.dual_decided > 10 * lifting.dual_undecided);
    if (c.well_conditioned) {
      CHECK(lifting.dual_decided > 50 * lifting.dual_undecided);
      CHECK(with.dual_decided > 25 * with.dual_undecided);  // (the fans' mirror-plane triples)
    } else {
      CHECK(with.dual_undecided > 0);
    }
  }
}

namespace {

/// The exact value of a dyadic ExactN as a rational.
double rounded_exactly(const ExactN& x) { return round_to_nearest(Exact(x)); }
bool same_double(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// The half-space <n, x> <= <n, p> (its plane through p), its normal scaled by 2^scale.
HalfSpace plane_through(const V3<double>& n, const V3<ExactN>& p, int scale) {
  const V3<ExactN> m =
      to_exact_n({std::ldexp(n.x, scale), std::ldexp(n.y, scale), std::ldexp(n.z, scale)});
  return dyadic_halfspace(m, dot(m, p));
}

/// Three half-spaces through p with normals a, b, c ordered so their det is positive.
HalfSpaces three_through(V3<double> a, V3<double> b, const V3<double>& c, const V3<ExactN>& p,
                         int scale) {
  if (CGAL::sign(det(to_exact_n(a), to_exact_n(b), to_exact_n(c))) < 0) std::swap(a, b);
  return {plane_through(a, p, scale), plane_through(b, p, scale), plane_through(c, p, scale)};
}

/// A point whose coordinates are rounding midpoints (ties), or within 2^-k ulp of one.
struct NearTie {
  V3<ExactN> p;
  int k;  // 1: exact ties; 0: doubles; more: 2^-k ulp off the midpoints
};

/// Near ties of doubles of very different sizes, scaled by 2^s.
std::vector<NearTie> adversarial_points() {
  std::vector<NearTie> points;
  const double bases[] = {1.0, 3.0, -5.0, 0.1, 12345.678, -0x1p40 - 1, 1e-3};
  for (int s : {0, -200, 200}) {
    for (int k : {1, 0, 10, 30, 45, 52, 60, 80}) {  // 1: an exact tie; 0: a double
      V3<ExactN> p;
      ExactN* c[3] = {&p.x, &p.y, &p.z};
      for (int i = 0; i < 3; ++i) {
        const double x = std::ldexp(bases[(k + 2 * i + s / 100 + 7) % 7], s);
        const double ulp = std::nextafter(x, HUGE_VAL) - x;
        ExactN v = ExactN(x);
        if (k >= 1) v = v + ExactN(ulp / 2);                            // the midpoint
        if (k > 1) v = v + ExactN(std::ldexp(ulp, -k) * (i ? 1 : -1));  // just off it
        *c[i] = v;
      }
      points.push_back({p, k});
    }
  }
  return points;
}

}  // namespace

// The precise (double-double) stage rounds a vertex's coordinates only when its enclosure
// lies strictly between two rounding midpoints: on exact ties and points within 2^-60 ulp
// of one it must decline, and what it decides must be the exact rounding (ties to even),
// also for nearly parallel planes, normals scaled by 2^+-200 and points far from the origin.
TEST_CASE("halfspace_intersection: the precise stage rounds vertices as the exact rounding") {
  const std::vector<V3<double>> normals = {
      {1, 0.25, -0.5}, {-0.3, 1, 0.1}, {0.2, -0.7, 1}, {0.6, 0.8, 0}, {0.577, 0.577, 0.578}};
  int decided = 0, total = 0, far_from_ties = 0, far_decided = 0;
  for (const auto& [p, k] : adversarial_points()) {
    for (int scale : {0, -200, 200}) {
      for (double tilt : {0.0, 0x1p-20, 0x1p-45}) {  // the third normal nearly the first
        for (std::size_t a = 0; a + 2 < normals.size(); ++a) {
          const V3<double> n0 = normals[a], n1 = normals[a + 1];
          const V3<double> n2 =
              tilt == 0 ? normals[a + 2] : V3<double>{n0.x + tilt, n0.y - tilt, n0.z + tilt / 3};
          for (const bool given : {false, true}) {
            // given: each offset also as a double-double copy (HalfSpace::offset_dd, as an
            // erosion makes it), which the filters and the precise stage then take.
            HalfSpaces hs = three_through(n0, n1, n2, p, scale);
            for (HalfSpace& h : hs) {
              double error;
              const DD d = to_dd(h.exact_offset(), error);
              h.has_offset_dd = given && error <= 0x1p-102 * std::abs(d.hi);
              if (h.has_offset_dd) h.offset_dd = d;
            }
            const PreciseProbe probe = probe_precise(hs);
            const ExactN* c[3] = {&p.x, &p.y, &p.z};
            const double got[3] = {probe.rounded.x, probe.rounded.y, probe.rounded.z};
            for (int i = 0; i < 3; ++i) {
              ++total;
              // Within 2^-52 ulp of a tie (2^-104 relative): always inside the enclosure.
              if (k == 1 || k >= 52) CHECK(!probe.decided[i]);
              if (!probe.decided[i]) continue;
              ++decided;
              CHECK(same_double(got[i], rounded_exactly(*c[i])));
            }
            // Far from a tie relative to the vertex's size (its largest coordinate): the
            // error bound is about 2^-95 of that for these well-conditioned normals.
            const double largest = std::max(
                {std::abs(p.x.to_double()), std::abs(p.y.to_double()), std::abs(p.z.to_double())});
            for (int i = 0; i < 3; ++i) {
              const double x = c[i]->to_double(),
                           ulp = std::nextafter(std::abs(x), HUGE_VAL) - std::abs(x);
              const double distance = k == 0 ? ulp / 2 : std::ldexp(ulp, -k);
              if (tilt == 0 && k != 1 && distance >= 0x1p-80 * largest)
                far_from_ties++, far_decided += probe.decided[i];
            }
          }
        }
      }
    }
  }
  // Well-conditioned vertices far (in ulps) from a tie are decided without exact arithmetic.
  CHECK(far_decided == far_from_ties);
  CHECK(far_from_ties > 50);
  CHECK(decided > far_decided);  // some nearly parallel ones too
  // Known points X / W (erosion vertices) take the same stage: ties and near-ties with odd
  // W decline, the rest rounds as the exact rounding; beyond the range it declines.
  for (const auto& [p, k] : adversarial_points()) {
    for (const double w : {1.0, 3.0, 0x1p-300, 0x1p300 * 5}) {
      const ExactN W(w);
      const PreciseProbe probe = probe_precise_point({p.x * W, p.y * W, p.z * W}, W);
      const ExactN* c[3] = {&p.x, &p.y, &p.z};
      const double got[3] = {probe.rounded.x, probe.rounded.y, probe.rounded.z};
      for (int i = 0; i < 3; ++i)
        if (probe.decided[i]) CHECK(same_double(got[i], rounded_exactly(*c[i])));
    }
  }
  const ExactN huge = ExactN(0x1p600) * ExactN(0x1p600);
  CHECK(!probe_precise_point({huge, ExactN(1), ExactN(-1)}, ExactN(1)).decided[0]);
  CHECK(!probe_precise_point({ExactN(1), ExactN(1), ExactN(1)}, huge).decided[0]);
}

// The precise vertex of three planes by a Newton step from doubles (newton_meet: X / W itself
// with an a-posteriori bound from its residual): well-conditioned triples take it, triples
// nearly dependent (the third normal 2^-45 from the first) fall back to the double-double
// Cramer's rule, and either way ties are never decided and what is decided is the exact
// rounding: near-midpoint points of very different sizes, normals scaled by 2^+-200,
// growing ill-conditioning, and vertices beyond the range (|x| > 2^400) or with zero
// coordinates.
TEST_CASE("halfspace_intersection: the Newton precise vertex rounds as the exact rounding") {
  const V3<double> n0{1, 0.25, -0.5}, n1{-0.3, 1, 0.1}, n2{0.2, -0.7, 1};
  int newton = 0, fallback = 0, decided = 0;
  for (const auto& [p, k] : adversarial_points()) {
    for (int scale : {0, -200, 200}) {
      for (int tilt : {0, 8, 16, 24, 45}) {
        const double t = std::ldexp(1.0, -tilt);
        const V3<double> third = tilt == 0 ? n2 : V3<double>{n0.x + t, n0.y - t, n0.z + t / 3};
        const PreciseProbe probe = probe_precise(three_through(n0, n1, third, p, scale));
        if (tilt == 0) CHECK(probe.newton);
        if (tilt == 45) CHECK(!probe.newton);
        newton += probe.newton;
        fallback += !probe.newton;
        const ExactN* c[3] = {&p.x, &p.y, &p.z};
        const double got[3] = {probe.rounded.x, probe.rounded.y, probe.rounded.z};
        for (int i = 0; i < 3; ++i) {
          if (k == 1 || k >= 60) CHECK(!probe.decided[i]);
          if (!probe.decided[i]) continue;
          ++decided;
          CHECK(same_double(got[i], rounded_exactly(*c[i])));
        }
      }
    }
  }
  CHECK(newton > 100);
  CHECK(fallback > 100);
  CHECK(decided > 100);
  // Zero coordinates (left to the exact rounding) and the range's ends: 2^400 and beyond.
  for (const double big : {0.0, 0x1p399 * 1.5, 0x1p401}) {
    const V3<ExactN> p{ExactN(big), ExactN(0.75), ExactN(0)};
    const PreciseProbe probe = probe_precise(three_through(n0, n1, n2, p, 0));
    CHECK(probe.newton == (big < 0x1p400));
    CHECK(!probe.decided[2]);
    if (probe.decided[0]) CHECK(same_double(probe.rounded.x, big));
    if (probe.decided[1]) CHECK(same_double(probe.rounded.y, 0.75));
  }
}

// Precise coordinates with W = 1 exactly (the Newton vertex's; also an opening's sums from
// them) round by X.hi when X.lo and the error stay strictly inside the half gaps to X.hi's
// neighbours: next to powers of two of either sign (the gaps differ by 2), lo on, just
// inside and just outside each half gap, with errors that reach across or not.
TEST_CASE("halfspace_intersection: precise coordinates with W = 1 round exactly") {
  int decided = 0, declined = 0;
  for (int e : {0, 1, -1, 52, 200, -200}) {
    for (double sign : {1.0, -1.0}) {
      for (int odd : {0, 1}) {
        const double m = std::ldexp(1.0, e), x = sign * (odd ? std::nextafter(m, HUGE_VAL) : m);
        const double ax = std::abs(x);
        const double away = std::nextafter(ax, HUGE_VAL) - ax,
                     toward = ax - std::nextafter(ax, 0.0);
        for (double half : {away / 2, -toward / 2}) {
          for (int k : {0, 20, 60}) {  // lo 2^-k of the gap inside the midpoint (0: on it)
            const double lo = sign * (half - (half > 0 ? 1 : -1) * (k ? std::ldexp(away, -k) : 0));
            for (int f : {10, 30, 70, 200}) {  // the error, 2^-f of the gap
              const double error = std::ldexp(away, -f);
              double got;
              const bool ok = round_precise_sum({x, lo}, error, {1, 0}, 0, 0.0, got);
              const ExactN v = ExactN(x) + ExactN(lo);
              const bool reaches = k == 0 || f <= k;  // the error reaches the midpoint
              if (reaches) CHECK(!ok);
              if (!ok) {
                ++declined;
                continue;
              }
              ++decided;
              CHECK(same_double(got, rounded_exactly(v)));
              CHECK(same_double(got, x));
            }
          }
        }
      }
    }
  }
  CHECK(decided > 100);
  CHECK(declined > 100);
}

// Next to a power of two the gap to the neighbour towards zero is half the gap away from
// it (the rounding steps to both neighbours by the bits of r): points on and just off the
// midpoints on either side, of either sign, and just off the power itself, decided only as
// the exact rounding, exact midpoints never.
TEST_CASE("halfspace_intersection: the precise stage rounds next to powers of two exactly") {
  int decided = 0;
  for (int e : {0, 1, -1, 52, 200, -200}) {
    for (double sign : {1.0, -1.0}) {
      const double x = sign * std::ldexp(1.0, e), m = std::abs(x);
      const double away = std::nextafter(m, HUGE_VAL) - m, toward = m - std::nextafter(m, 0.0);
      for (double gap : {away, -toward}) {
        for (int k : {1, 3, 20, 40, 70}) {  // 1: the midpoint itself
          const double off = std::ldexp(gap, -k);
          const ExactN mid = ExactN(x) + ExactN(sign * gap / 2);
          const std::vector<ExactN> values =
              k == 1 ? std::vector<ExactN>{mid}
                     : std::vector<ExactN>{ExactN(x) + ExactN(sign * off),  // near x itself
                                           mid + ExactN(sign * off), mid - ExactN(sign * off)};
          for (const ExactN& v : values) {
            for (double w : {1.0, 3.0, 0x1p-300}) {
              const ExactN W(w), X = v * W;
              const PreciseProbe probe = probe_precise_point({X, X, X}, W);
              // (W = 1: X is exact in double-double, rounded by one addition; see below.)
              if (k == 1 && w != 1.0) CHECK(!probe.decided[0]);
              if (!probe.decided[0]) continue;
              ++decided;
              CHECK(same_double(probe.rounded.x, rounded_exactly(v)));
            }
          }
        }
      }
    }
  }
  CHECK(decided > 100);
}

// A known point X / 1 whose X is exact in double-double (an erosion's v - b of doubles, often
// one bit beyond a double: a rounding tie) rounds by hi + lo, ties to even: decided at ties,
// where the precise rounding never decides (above), and as the exact rounding; X beyond
// double-double takes the precise rounding.
TEST_CASE("halfspace_intersection: known points exact in double-double round ties to even") {
  int ties = 0;
  for (int e : {0, -2, 30, -300}) {
    for (double sign : {1.0, -1.0}) {
      for (int odd : {0, 1}) {  // x's last bit: the tie goes to x, or away from it
        const double m = std::ldexp(1.0, e), x = sign * (odd ? std::nextafter(m, HUGE_VAL) : m);
        const double gap = std::nextafter(std::abs(x), HUGE_VAL) - std::abs(x);
        const ExactN mid = ExactN(x) + ExactN(sign * gap / 2);
        const ExactN near = mid + ExactN(sign * std::ldexp(gap, -40));    // in double-double
        const ExactN beyond = mid - ExactN(sign * std::ldexp(gap, -90));  // beyond it
        INFO(e, " ", sign, " ", odd);
        const PreciseProbe tie = probe_precise_point({mid, near, -mid}, ExactN(1));
        CHECK(tie.decided == std::array<bool, 3>{true, true, true});
        CHECK(same_double(tie.rounded.x, rounded_exactly(mid)));
        CHECK(same_double(tie.rounded.x, odd ? x + sign * gap : x));
        CHECK(same_double(tie.rounded.y, rounded_exactly(near)));
        CHECK(same_double(tie.rounded.z, -tie.rounded.x));
        // A coordinate beyond double-double: the precise rounding, never at the tie.
        const PreciseProbe other = probe_precise_point({mid, near, beyond}, ExactN(1));
        CHECK(!other.decided[0]);
        if (other.decided[1]) CHECK(same_double(other.rounded.y, rounded_exactly(near)));
        if (other.decided[2]) CHECK(same_double(other.rounded.z, rounded_exactly(beyond)));
        ++ties;
      }
    }
  }
  CHECK(ties == 16);
  // Differences of doubles a - b, a's ulp twice b's: ties for odd b.
  for (double a : {0.7, -0.44, 3.25}) {
    for (double b : {0.25 / 3, -0.1 / 7, 0x1.0000000000001p-3}) {
      const V3<ExactN> X = exact_difference(V3<double>{a, b, a}, V3<double>{b, a, -b});
      const PreciseProbe probe = probe_precise_point(X, ExactN(1));
      const ExactN* c[3] = {&X.x, &X.y, &X.z};
      const double got[3] = {probe.rounded.x, probe.rounded.y, probe.rounded.z};
      for (int i = 0; i < 3; ++i) {
        CHECK(probe.decided[i]);
        CHECK(same_double(got[i], rounded_exactly(*c[i])));
      }
    }
  }
}

namespace {

// Seven planes around an adversarial point p: three through p (scaled by 2^scale), a fourth
// through p moved by 2^-bits of the magnitude of <n, p> (sign: its direction), and three
// through q (scaled by 2^q_scale), p moved along the fourth plane's normal by 2^-bits of p's
// size (the sign of <n, p - q> is -sign).
HalfSpaces moved_fourth(const V3<ExactN>& p, int scale, int q_scale, int bits, int sign,
                        V3<ExactN>& q) {
  HalfSpaces hs = three_through({1, 0.25, -0.5}, {-0.3, 1, 0.1}, {0.2, -0.7, 1}, p, scale);
  HalfSpace h = plane_through({0.3, 0.3, 0.9 + 0x1p-30}, p, scale);
  const V3<ExactN>& n = h.exact_normal();
  const double size = std::abs(n.x.to_double() * p.x.to_double()) +
                      std::abs(n.y.to_double() * p.y.to_double()) +
                      std::abs(n.z.to_double() * p.z.to_double());
  h.offset() = h.exact_offset() + ExactN(std::ldexp(sign * size, -bits));
  hs.push_back(h);
  const double big =
      std::max({std::abs(p.x.to_double()), std::abs(p.y.to_double()), std::abs(p.z.to_double())});
  const ExactN t(std::ldexp(sign * big, -bits));
  q = {p.x + t * ExactN(0.3), p.y + t * ExactN(0.3), p.z + t * ExactN(0.9 + 0x1p-30)};
  for (const HalfSpace& g :
       three_through({0.9, -0.2, 0.3}, {0.1, 0.8, -0.4}, {-0.5, 0.2, 0.9}, q, q_scale))
    hs.push_back(g);
  return hs;
}

}  // namespace

// The precise stage's determinant of three normals (the repair's and the guess's
// orientation tests, after intervals): nearly coplanar normals, n_2 = n_0 + n_1 moved by
// 2^-k, decided as the exact sign down to 2^-80 relative, of either sign, and exactly
// coplanar ones never; scaled normals alike.
TEST_CASE("halfspace_intersection: the precise determinant sign is exact") {
  const V3<ExactN> n0 = to_exact_n({1, 0.25, -0.5}), n1 = to_exact_n({-0.3, 1, 0.1}),
                   e = to_exact_n({0.2, -0.7, 1});
  int decided = 0;
  for (int scale : {0, -200, 200}) {
    const ExactN f(std::ldexp(1.0, scale));
    for (int k : {20, 50, 60, 80, 0}) {  // 0: exactly coplanar
      for (double sign : {1.0, -1.0}) {
        const ExactN t(k == 0 ? 0.0 : sign * std::ldexp(1.0, -k));
        const V3<ExactN> n2{n0.x + n1.x + t * e.x, n0.y + n1.y + t * e.y, n0.z + n1.z + t * e.z};
        HalfSpaces hs;
        for (const V3<ExactN>& n : {n0, n1, n2})
          hs.push_back(dyadic_halfspace({n.x * f, n.y * f, n.z * f}, ExactN(1)));
        const int want = CGAL::sign(det(n0, n1, n2));
        const PreciseProbe probe = probe_precise(hs);
        if (k == 0) {
          CHECK(want == 0);
          CHECK(probe.det == 2);
          continue;
        }
        CHECK(probe.det == want);
        decided += probe.det == want;
      }
    }
  }
  CHECK(decided == 24);
}

// A plane beyond the precise stage's range (its offset above 2^400 times its largest normal
// component) has no precise copy (PrecisePlane::valid(), read from its normal, which is left
// zero): its vertices and determinants go to the exact tests; one within the range has one.
TEST_CASE("halfspace_intersection: planes out of the precise range skip the precise stage") {
  const V3<ExactN> n0 = to_exact_n({1, 0.25, -0.5}), n1 = to_exact_n({-0.3, 1, 0.1}),
                   n2 = to_exact_n({0.2, -0.7, 1});
  const int want = CGAL::sign(det(n0, n1, n2));
  REQUIRE(want > 0);
  for (int e : {300, 500}) {
    HalfSpaces hs;
    for (const V3<ExactN>& n : {n0, n1, n2}) hs.push_back(dyadic_halfspace(n, ExactN(1)));
    hs[1].offset() = ExactN(std::ldexp(1.0, e));
    const PreciseProbe probe = probe_precise(hs);
    if (e == 300) {
      CHECK(probe.det == want);
      CHECK(probe.decided[0]);
    } else {
      CHECK(probe.det == 2);
      CHECK(!probe.decided[0]);
      CHECK(!probe.decided[1]);
      CHECK(!probe.decided[2]);
    }
  }
}

// The precise stage of side and compare_along: exact zeros (a fourth plane through the
// vertex, two vertices on one plane parallel to the fourth) stay undecided, and every
// sign it decides is the exact sign, down to moves of 2^-90 relative.
TEST_CASE("halfspace_intersection: the precise side and compare signs are exact") {
  int decided = 0;
  for (const auto& [p, k] : adversarial_points()) {
    for (int scale : {0, -200, 200}) {
      for (int bits : {20, 60, 90, 120}) {
        for (int sign : {1, -1}) {
          V3<ExactN> q;
          HalfSpaces hs = moved_fourth(p, scale, -scale, bits, sign, q);
          const HalfSpace h = hs[3];
          const PreciseProbe probe = probe_precise(hs);
          const V3<ExactN>& n = h.exact_normal();
          const int want_side = CGAL::sign(dot(n, p) - h.exact_offset());
          const int want_compare = CGAL::sign(dot(n, p) - dot(n, q));
          if (probe.side != 2) CHECK(probe.side == want_side);
          if (probe.compare != 2) CHECK(probe.compare == want_compare);
          decided += (probe.side != 2) + (probe.compare != 2);
          if (bits <= 60) CHECK(probe.side != 2);
          if (bits <= 60) CHECK(probe.compare != 2);
          // Exact zeros: the fourth plane through p; v = u on other planes.
          hs[3] = plane_through({0.3, 0.3, 0.9 + 0x1p-30}, p, scale);
          for (int i = 0; i < 3; ++i)
            hs[4 + i] =
                three_through({0.9, -0.2, 0.3}, {0.1, 0.8, -0.4}, {-0.5, 0.2, 0.9}, p, -scale)[i];
          const PreciseProbe zero = probe_precise(hs);
          CHECK(zero.side == 2);
          CHECK(zero.compare == 2);
        }
      }
    }
  }
  CHECK(decided > 0);
}

// The double filter (the vertices' first test, an a-priori error bound on doubles) decides
// only true signs: W > 0, <n, X> - d W for a fourth plane moved off the meet by 2^-bits of
// its size, and <n, Xu> Wv - <n, Xv> Wu for a second vertex moved along n alike, on the
// precise test's adversarial points (offsets not doubles), with normals scaled so that
// products underflow (2^-350) or planes leave the filter's range (2^61); far from zero it
// decides, near zero it leaves the sign to the intervals and the exact stages below.
TEST_CASE("halfspace_intersection: the double filter's signs are exact") {
  int decided = 0, undecided = 0, expected = 0;
  const auto exact_meet = [](const HalfSpaces& hs, int first, V3<ExactN>& X, ExactN& W) {
    const HalfSpace &a = hs[first], &b = hs[first + 1], &c = hs[first + 2];
    const V3<ExactN>&na = a.exact_normal(), &nb = b.exact_normal(), &nc = c.exact_normal();
    const ExactN &da = a.exact_offset(), &db = b.exact_offset(), &dc = c.exact_offset();
    W = det(na, nb, nc);
    const V3<ExactN> bc = cross(nb, nc), ca = cross(nc, na), ab = cross(na, nb);
    X = {da * bc.x + db * ca.x + dc * ab.x, da * bc.y + db * ca.y + dc * ab.y,
         da * bc.z + db * ca.z + dc * ab.z};
  };
  for (const auto& [p, k] : adversarial_points()) {
    for (int scale : {0, -350, 50, 61}) {
      for (int bits : {4, 12, 20, 40, 60, 90}) {
        for (int sign : {1, -1}) {
          V3<ExactN> q;
          const HalfSpaces hs = moved_fourth(p, scale, scale, bits, sign, q);
          const HalfSpace& h = hs[3];
          V3<ExactN> Xu, Xv;
          ExactN Wu, Wv;
          exact_meet(hs, 0, Xu, Wu);
          exact_meet(hs, 4, Xv, Wv);
          const DoubleProbe probe = probe_double(hs);
          if (probe.w == 1) CHECK(CGAL::sign(Wu) > 0);
          const V3<ExactN>& n = h.exact_normal();
          if (probe.side != 2) CHECK(probe.side == CGAL::sign(dot(n, Xu) - h.exact_offset() * Wu));
          if (probe.compare != 2)
            CHECK(probe.compare == CGAL::sign(dot(n, Xu) * Wv - dot(n, Xv) * Wu));
          decided += (probe.side != 2) + (probe.compare != 2);
          undecided += (probe.side == 2) + (probe.compare == 2);
          if (scale == 61) CHECK(probe.w == 2);  // out of range: left to the intervals
          // In range, far from degenerate: decided (p of moderate size, no underflow).
          const double small = std::min(
              {std::abs(p.x.to_double()), std::abs(p.y.to_double()), std::abs(p.z.to_double())});
          const double big = std::max(
              {std::abs(p.x.to_double()), std::abs(p.y.to_double()), std::abs(p.z.to_double())});
          if (scale == 0 && small > 1e-4 && big < 1e6 && bits <= 12) {
            ++expected;
            CHECK(probe.w == 1);
            CHECK(probe.side != 2);
            CHECK(probe.compare != 2);
          }
          if (bits >= 60) CHECK(probe.side == 2);
        }
      }
    }
  }
  CHECK(decided > 0);
  CHECK(undecided > 0);
  CHECK(expected > 0);
}

// Whole intersections whose vertices are exact ties or just off them: the cube
// [-m, m]^3 for m a midpoint between doubles (scaled by 2^+-200), and moved by 2^-80 ulp;
// the rounded result must be the exact one rounded (checked), with or without the exact
// polytope.
TEST_CASE("halfspace_intersection: vertices on rounding midpoints round to even") {
  for (int s : {0, -200, 200}) {
    for (int k : {0, 80}) {
      const double x = std::ldexp(1.0, s), ulp = std::nextafter(x, HUGE_VAL) - x;
      const Exact m = Exact(x) + Exact(ulp / 2) + (k ? Exact(std::ldexp(ulp, -k)) : Exact(0));
      HalfSpaces hs;
      const double axes[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                 {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
      for (const auto& a : axes)
        hs.push_back(plane(a[0], a[1], a[2], m, static_cast<int>(hs.size())));
      hs.push_back(plane(1, 1, 1, Exact(3) * m - Exact(ulp), 6));  // cuts one corner
      const MaybePolytope r = checked(hs);
      REQUIRE(r.polytope);
      CHECK(r.polytope->num_vertices() == 10);
    }
  }
}

// exact_difference takes the double difference only where Sterbenz makes it exact: compared
// with the Mpzf subtraction on nearby, distant, opposite-signed, zero, subnormal, huge and
// tiny pairs, and in the upward rounding of the interval filters.
TEST_CASE("halfspace_intersection: exact differences of doubles") {
  std::vector<double> values = {0.0,
                                -0.0,
                                1.0,
                                -1.0,
                                2.0,
                                0.5,
                                std::nextafter(2.0, 3.0),
                                std::nextafter(0.5, 0.0),
                                1e6 + 0.1,
                                -3e5,
                                0x1p200,
                                std::nextafter(0x1p201, 0.0),
                                0x1p-200,
                                0x1p-1074,
                                0x1p-1073,
                                0x1p-1022,
                                std::numeric_limits<double>::max(),
                                std::nextafter(std::numeric_limits<double>::max(), 0.0),
                                std::numeric_limits<double>::max() / 2};
  std::mt19937_64 rng(5);
  for (int i = 0; i < 200; ++i) {
    const double x = std::ldexp(std::uniform_real_distribution<double>(-1, 1)(rng),
                                std::uniform_int_distribution<int>(-1000, 1000)(rng));
    values.push_back(x);
    values.push_back(std::nextafter(x, 0.0) * (1 + 0x1p-30));
    values.push_back(x * 1.999999999);
    values.push_back(x * 0.5);
  }
  int wrong = 0, sterbenz = 0;
  for (const bool upward : {false, true}) {
    std::optional<RoundingGuard> guard;
    if (upward) guard.emplace();
    for (double a : values)
      for (double b : values) {
        const ExactN d = exact_difference(a, b);
        wrong += !(d == ExactN(a) - ExactN(b));
        const double rounded = a - b;  // overflows for DBL_MAX - (-DBL_MAX): no Mpzf of it
        sterbenz += std::isfinite(rounded) && d == ExactN(rounded);
      }
  }
  CHECK(wrong == 0);
  CHECK(sterbenz > 0);
  const V3<ExactN> v = exact_difference(V3<double>{1, 0x1p-1074, -1e300}, V3<double>{3, 1, 1e300});
  CHECK((v.x == ExactN(-2) && v.y == ExactN(0x1p-1074) - ExactN(1) &&
         v.z == ExactN(-1e300) - ExactN(1e300)));
}

namespace {

/// x as a double-double times 2^scale, and a bound on its distance to x times 2^scale (the
/// exact distance rounded up), optionally moved off it by `shift` of its lowest bits.
DD scaled_dd(const ExactN& x, int scale, double shift, double& error) {
  DD d = to_dd(x * ExactN(std::ldexp(1.0, scale)), error);
  if (!std::isfinite(error)) return d;  // beyond the doubles
  if (shift != 0) d = quick_two_sum(d.hi, d.lo + shift * std::ldexp(std::abs(d.hi), -104));
  const ExactN off = ExactN(d.hi) + ExactN(d.lo) - x * ExactN(std::ldexp(1.0, scale));
  // |off| rounded up (to_double is within half an ulp, or 2^-1075 below the normals).
  error = CGAL::sign(off) == 0 ? 0 : std::nextafter(std::abs(off.to_double()), HUGE_VAL);
  return d;
}

/// Same vertices bit for bit, in order, and the same facet cycles and labels.
std::string mesh_difference(const morph::LabelledMesh& a, const morph::LabelledMesh& b) {
  if (a.mesh.n_vertices() != b.mesh.n_vertices() || a.mesh.n_faces() != b.mesh.n_faces())
    return "sizes differ";
  for (std::size_t v = 0; v < a.mesh.n_vertices(); ++v)
    for (int k = 0; k < 3; ++k)
      if (!same_double(a.mesh.points()[v][k], b.mesh.points()[v][k]))
        return "vertex " + std::to_string(v) + " differs";
  for (const morph::Mesh::FaceHandle f : a.mesh.faces()) {
    std::vector<int> fa, fb;
    for (const morph::Mesh::VertexHandle v : a.mesh.fv_range(f)) fa.push_back(v.idx());
    for (const morph::Mesh::VertexHandle v : b.mesh.fv_range(f)) fb.push_back(v.idx());
    if (fa != fb) return "face " + std::to_string(f.idx()) + " differs";
  }
  if (a.origins.size() != b.origins.size()) return "labels differ";
  for (std::size_t f = 0; f < a.origins.size(); ++f)
    if (a.origins[f].kind != b.origins[f].kind || a.origins[f].a.index != b.origins[f].a.index ||
        a.origins[f].b.index != b.origins[f].b.index)
      return "label " + std::to_string(f) + " differs";
  return "";
}

/// The opening's sum (A (-) B) (+) B with the eroded polytope's exact points on demand and
/// its sums rounded by the precise stage, and by the route before (every exact point up
/// front, every sum rounded exactly): the same polytope, the same mesh bit for bit.
void check_opening_routes(const Polytope& A, const Polytope& B) {
  const MaybePolytope lazy = erode_polytope(A, B);
  const MaybePolytope eager = erode_polytope(A, B, {.eager_exact = true});
  REQUIRE(lazy.reason == eager.reason);
  if (!lazy.polytope) return;
  CHECK(lazy.polytope->exact_points.lazy);
  CHECK(!eager.polytope->exact_points.lazy);
  CHECK(eager.polytope->exact_points.precise.empty());
  const morph::LabelledMesh want = sum_mesh(*eager.polytope, B, fims_facets(*eager.polytope, B));
  const morph::LabelledMesh got = sum_mesh(*lazy.polytope, B, fims_facets(*lazy.polytope, B));
  CHECK(mesh_difference(got, want) == "");
  // Every sum left to the exact rounding, on exact points computed on demand.
  Polytope undecided = *lazy.polytope;
  for (PrecisePoint& p : undecided.exact_points.precise) p.valid = p.doubles = false;
  CHECK(mesh_difference(sum_mesh(undecided, B, fims_facets(undecided, B)), want) == "");
  CHECK(difference(lazy, eager) == "");  // reads every exact point on demand
  CHECK(rounded_from_exact(lazy));
  check_direct_polytope(A, B, lazy);
}

}  // namespace

// An opening rounds the sums e + b of the eroded polytope's vertices e = X / W (given in
// double-double with error bounds, times an unknown factor) and double points b in
// double-double (round_precise_sum), exactly only where that cannot decide. What it decides
// must be mpfr's rounding of the rational sum: sums on exact ties, within 2^-k ulp of a
// rounding midpoint, cancelling, at scales 2^+-200, far from the origin, with non-dyadic W,
// factors 2^+-80 and double-doubles moved off the exact values within their bounds.
TEST_CASE("halfspace_intersection: sums rounded by the precise stage are the exact roundings") {
  const double bases[] = {1.0, 3.0, -5.0, 0.1, 12345.678, -0x1p40 - 1, 1e-3};
  int decided = 0, decidable = 0, total = 0, near_decided = 0;
  CGAL::Protect_FPU_rounding<true> nearest(CGAL_FE_TONEAREST);
  for (int s : {0, -200, 200}) {
    for (int k : {1, 0, 10, 30, 45, 52, 60, 80}) {  // 1: an exact tie; 0: a double
      for (int base = 0; base < 7; ++base) {
        const double t = std::ldexp(bases[base], s);
        const double ulp = std::nextafter(t, HUGE_VAL) - t;
        ExactN y = ExactN(t);  // the sum e + b
        if (k >= 1) y = y + ExactN(ulp / 2);
        if (k > 1) y = y + ExactN(std::ldexp(ulp, -k) * (base % 2 ? 1 : -1));
        const double want = round_to_nearest(Exact(y));
        for (const double b : {0.0, std::ldexp(1.0, s), std::ldexp(-3.75, s), -t, t * 0.999,
                               std::ldexp(1e15, s), std::ldexp(-7e13, s), 1e300, 0x1p-1070}) {
          for (const ExactN& W : {ExactN(1), ExactN(3), ExactN(105), ExactN(0x1p-100) * ExactN(7),
                                  ExactN(0x1p40) * ExactN(11)}) {
            const ExactN X = (y - ExactN(b)) * W;  // e = X / W = y - b
            for (int scale : {0, -80, 80}) {
              for (double shift : {0.0, 3.0, -2.5}) {
                double ex, ew, got;
                const DD Xd = scaled_dd(X, scale, shift, ex), Wd = scaled_dd(W, scale, -shift, ew);
                if (!std::isfinite(ex) || !std::isfinite(ew)) continue;
                ++total;
                if (!round_precise_sum(Xd, ex, Wd, ew, b, got)) continue;
                ++decided;
                if (k == 0 || k == 10 || k == 30) ++decidable;
                if (k >= 60) ++near_decided;
                CAPTURE(s);
                CAPTURE(k);
                CAPTURE(base);
                CAPTURE(b);
                CAPTURE(scale);
                CHECK(k != 1);  // an exact tie is never decided (the bound is never zero)
                CHECK(same_double(got, want));
              }
            }
          }
        }
      }
    }
  }
  MESSAGE(decided << " of " << total << " sums decided by the precise stage, " << near_decided
                  << " within 2^-60 ulp of a midpoint");
  CHECK(decidable > total / 8);  // the stage does its work where it can
  CHECK(near_decided == 0);      // its bound is far wider than 2^-60 ulp
}

// The precise rounding tests the candidate X.hi / W.hi moved by its residual, with that
// candidate's residual updated from the first one's (round_precise): quotients X / W with
// odd W (never a double-double's exact quotient), X / W a random double moved by d ulps
// (d from 0 to 1, and just off the midpoint), at scales up to 2^+-300 and across powers of
// two. Every decision is the exact rounding, and every quotient further than 2^-30 ulp from
// a midpoint is decided (the updated residual's bound is tight enough).
TEST_CASE("halfspace_intersection: the precise rounding's corrected candidate rounds exactly") {
  CGAL::Protect_FPU_rounding<true> nearest(CGAL_FE_TONEAREST);
  std::mt19937_64 random(13);
  std::uniform_real_distribution<double> unit(1.0, 2.0);
  int far = 0, far_decided = 0, decided = 0;
  const double offsets[] = {0.0, 0.1, 0.3, 0.49, 0.5 - 0x1p-20, 0.5 + 0x1p-20, 0.51, 0.7, 0.9};
  for (int trial = 0; trial < 60; ++trial) {
    const int e = trial % 3 == 0 ? 0 : trial % 3 == 1 ? 300 : -300;
    // Every fifth a power of two, where the gaps on either side differ.
    const double x = std::ldexp(trial % 5 == 0 ? (trial % 2 ? 1.0 : -1.0) : unit(random), e);
    const double ulp = std::nextafter(std::abs(x), HUGE_VAL) - std::abs(x);
    for (const double d : offsets) {
      for (const double sign : {1.0, -1.0}) {
        const ExactN y = ExactN(x) + ExactN(sign * d * ulp);  // (exact: few bits)
        const double want = round_to_nearest(Exact(y));
        for (const double w : {3.0, 7.0, 105.0, 0x1p-200 * 11}) {
          const ExactN W(w), X = y * W;
          for (const int scale : {0, 90, -90}) {
            double ex, ew, got;
            const DD Xd = scaled_dd(X, scale, 0.0, ex), Wd = scaled_dd(W, scale, 0.0, ew);
            if (!std::isfinite(ex) || !std::isfinite(ew)) continue;
            const bool ok = round_precise_sum(Xd, ex, Wd, ew, 0.0, got);
            // Distance to the nearest midpoint, in ulps of the smaller gap.
            const double from_mid = std::abs(0.5 - std::abs(std::fmod(d, 1.0)));
            if (from_mid > 0x1p-30 && std::abs(x) != std::ldexp(1.0, e)) {
              ++far;
              far_decided += ok;
            }
            if (!ok) continue;
            ++decided;
            CAPTURE(trial);
            CAPTURE(d);
            CAPTURE(w);
            CAPTURE(scale);
            CHECK(same_double(got, want));
          }
        }
      }
    }
  }
  CHECK(far > 1000);
  CHECK(far_decided == far);
  CHECK(decided >= far);
}

// Whole openings by both routes: random polytopes and elements of several sizes, operands
// scaled by 2^+-200, far from the origin, and an element 2^-40 times A's size (its sums lie
// within rounding of A's vertices).
TEST_CASE("halfspace_intersection: openings with exact points on demand are the exact route's") {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    for (const double size : {0.02, 0.1, 0.4}) {
      CAPTURE(seed);
      CAPTURE(size);
      const Polytope A = make_operand(morph::test::random_sphere_polytope(60, seed), "A");
      const morph::Mesh B = random_element(seed);
      check_opening_routes(A, make_operand(morph::test::scaled(B, size), "B"));
    }
  }
  const morph::Mesh& a = sample("icosphere_320.off");
  const morph::Mesh b =
      morph::test::transformed(sample("icosphere_80.off"), morph::test::random_rotation(11));
  const std::pair<morph::Mesh, morph::Mesh> cases[] = {
      {a, morph::test::scaled(b, 0x1p-40)},
      {morph::test::scaled(a, 0x1p200), morph::test::scaled(b, 0x1p195)},
      {morph::test::scaled(a, 0x1p-200), morph::test::scaled(b, 0x1p-205)},
      {morph::test::translated(a, {1e6, -3e5, 7e5}), morph::test::scaled(b, 1.0 / 32)},
  };
  for (const auto& [A, B] : cases) check_opening_routes(make_operand(A, "A"), make_operand(B, "B"));
}

// A triangle's normal in double-double straight from its double corners (set_normal_dd)
// against the exact cross product: each component within 2^-101 of its |hi| whenever it is
// set, on random, nearly degenerate (nearly collinear corners: cancellation in every
// component), 2^+-200-scaled and far-shifted triangles; set for many of them.
TEST_CASE("halfspace_intersection: a triangle's double-double normal is within its bound") {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> unit(-1, 1);
  int set = 0, total = 0;
  for (int scale : {0, 200, -200}) {
    for (double shift : {0.0, 1e6, -3e9}) {
      for (int kind = 0; kind < 3; ++kind) {
        for (int trial = 0; trial < 200; ++trial) {
          const auto point = [&](double s) {
            return V3<double>{std::ldexp(shift + s * unit(rng), scale),
                              std::ldexp(shift + s * unit(rng), scale),
                              std::ldexp(s * unit(rng), scale)};
          };
          V3<double> p0 = point(1), p1 = point(1), p2 = point(1);
          if (kind == 1) {  // nearly collinear: p2 next to the midpoint of p0 p1
            for (double V3<double>::*c : {&V3<double>::x, &V3<double>::y, &V3<double>::z})
              p2.*c = std::nextafter(p0.*c / 2 + p1.*c / 2, HUGE_VAL);
          } else if (kind == 2) {  // a tiny triangle, ulps apart
            p1 = {std::nextafter(p0.x, HUGE_VAL), p0.y, std::nextafter(p0.z, -HUGE_VAL)};
            p2 = {p0.x, std::nextafter(p0.y, HUGE_VAL), std::nextafter(p0.z, HUGE_VAL)};
          }
          HalfSpace h;
          h.normal() = cross(to_exact_n(p1) - to_exact_n(p0), to_exact_n(p2) - to_exact_n(p0));
          set_normal_dd(h, p0, p1, p2);
          ++total;
          if (!h.has_normal_dd) continue;
          ++set;
          const ExactN* exact[3] = {&h.exact_normal().x, &h.exact_normal().y, &h.exact_normal().z};
          for (int k = 0; k < 3; ++k) {
            const DD& d = h.normal_dd[k];
            const Exact diff = Exact(*exact[k]) - Exact(d.hi) - Exact(d.lo);
            const Exact error = diff < 0 ? -diff : diff;
            CHECK(error <= Exact(std::abs(d.hi)) * Exact(0x1p-101));
            CHECK(std::abs(d.lo) <= std::abs(d.hi) * 0x1p-52);
          }
        }
      }
    }
  }
  CHECK(set > 0);
  MESSAGE("double-double normals set for " << set << " of " << total << " triangles");
}

// The check's far-plane tests of an edge are one sign, which it and the guess's flips reuse
// (build_verified, triangulate_polygon): plane d at the vertex of (a, b, c) and plane c at
// that of (b, a, d) (the same edge seen from its other triangle) have the same sign, any
// rotation of a triangle's corners gives the same vertex, and after the flip of edge a -> c
// of (a, c, b) to (b, d) the new edge's test, plane c at the vertex of (a, d, b), has the
// sign opposite to the flipped one's (d at the vertex of (a, c, b)).
// Exact evaluation (Cramer's rule in Mpzf) on four planes nearly through one point (the
// flips' ties), exactly through it, and generic, scaled by 2^+-200 and far from the origin.
TEST_CASE("halfspace_intersection: an edge's two far-plane tests are one sign") {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> unit(-1, 1);
  struct P {
    V3<ExactN> n;
    ExactN d;
  };
  // Sign of <n_e, X> - d_e W for X / W the meet of a, b, c (W = det(n_a, n_b, n_c)).
  const auto side = [](const P& a, const P& b, const P& c, const P& e) {
    const V3<ExactN> bc = cross(b.n, c.n), ca = cross(c.n, a.n), ab = cross(a.n, b.n);
    const ExactN W = dot(a.n, bc);
    const V3<ExactN> X{a.d * bc.x + b.d * ca.x + c.d * ab.x, a.d * bc.y + b.d * ca.y + c.d * ab.y,
                       a.d * bc.z + b.d * ca.z + c.d * ab.z};
    return CGAL::sign(dot(e.n, X) - e.d * W);
  };
  int zeros = 0, total = 0;
  for (int scale : {0, 200, -200}) {
    for (double shift : {0.0, 1e6, -3e9}) {
      for (int kind = 0; kind < 3; ++kind) {  // through a point, nearly, generic
        for (int trial = 0; trial < 100; ++trial) {
          const V3<double> o{shift + unit(rng), shift + unit(rng), unit(rng)};
          std::array<P, 4> q;
          for (P& p : q) {
            const V3<double> n{unit(rng), unit(rng), unit(rng)};
            p.n = to_exact_n(n);
            // Through o, exactly, or moved by 2^-60 of its offset, or anywhere.
            const V3<double> at =
                kind == 2 ? V3<double>{shift + unit(rng), unit(rng), unit(rng)} : o;
            p.d = dot(p.n, to_exact_n(at));
            if (kind == 1) p.d = p.d + ExactN(std::ldexp(unit(rng), -60)) * p.d;
            const ExactN s(std::ldexp(1.0, scale));
            p.d = p.d * s;  // the planes scaled by 2^scale about the origin
          }
          const auto& [a, b, c, d] = q;
          const int s = side(a, b, c, d);
          CHECK(side(b, a, d, c) == s);
          CHECK(side(b, c, a, d) == s);  // a rotation of (a, b, c)
          // The flip of edge a -> c between (a, c, b) and (c, a, d) to (a, d, b), (d, c, b).
          const int f = side(a, c, b, d);
          CHECK(side(c, a, d, b) == f);
          CHECK(side(a, d, b, c) == -f);  // the new edge d -> b of (a, d, b), far c
          CHECK(side(d, b, a, c) == -f);  // the same triangle rotated
          CHECK(side(d, c, b, a) == -f);  // its twin in (d, c, b): edge b -> d, far a
          zeros += s == 0;
          ++total;
        }
      }
    }
  }
  CHECK(zeros > 0);
  CHECK(zeros < total);
}

// HalfSpace constructs its exact values only when set or made: a default one reads zero with
// denominator 1, copies carry the values (or their absence) and the denominator.
TEST_CASE("halfspace_intersection: half-spaces copy their exact values when they have them") {
  HalfSpace empty;
  CHECK(!empty.has_exact_values());
  CHECK(empty.unit_denominator());
  CHECK(empty.denominator() == ExactN(1));
  CHECK(CGAL::sign(empty.exact_offset()) == CGAL::ZERO);
  CHECK(CGAL::sign(empty.exact_normal().y) == CGAL::ZERO);
  HalfSpace h = make_halfspace({ExactN(1), ExactN(2), ExactN(3)}, Exact(5) / Exact(3), 7);
  CHECK(h.has_exact_values());
  CHECK(!h.unit_denominator());
  HalfSpace copy = h;
  CHECK(copy.has_exact_values());
  CHECK(copy.source == 7);
  CHECK(copy.exact_normal().z == ExactN(3));
  CHECK(copy.exact_offset() == ExactN(5));
  CHECK(copy.denominator() == ExactN(3));
  // Assigned an empty one: values and denominator go.
  copy = empty;
  CHECK(!copy.has_exact_values());
  CHECK(copy.unit_denominator());
  CHECK(CGAL::sign(copy.exact_normal().z) == CGAL::ZERO);
  // An empty one assigned a full one.
  empty = h;
  CHECK(empty.has_exact_values());
  CHECK(empty.exact_normal().y == ExactN(2));
  CHECK(empty.denominator() == ExactN(3));
  // A set denominator of 1 reads as a unit one.
  HalfSpace unit = make_halfspace({ExactN(1), ExactN(0), ExactN(0)}, Exact(4), 0);
  CHECK(unit.unit_denominator());
  CHECK(unit.exact_offset() == ExactN(4));
}

// An erosion takes the signs that A's own convexity makes certain from A: the orientation of
// every triangle of its guess (three normals of A's fan at a vertex, in order), and, for a
// polytope of exact triangles (ExpectedVertices::moved_by), the far-plane sign across each
// edge of A between two polygons that one vertex of B moved. Each of them is the sign the
// tests give (verify_certified makes those tests too), and the result is the one made
// testing them all, whether facets vanish or not and wherever B's origin lies. A UV sphere's
// nearly planar quadrilaterals give orientations only: their planes do not pass through their
// corners.
TEST_CASE("halfspace_intersection: the signs a guess takes from A's convexity are the tests'") {
  // orientations: those alone (not exact triangles); some: far-plane signs where they
  // happen to be (B has about as many vertices as A); most: B has far fewer vertices than A
  enum class Certifies { orientations, some, most };
  struct Case {
    morph::Mesh A, B;
    Certifies certifies;
  };
  const Case cases[] = {
      {morph::make_icosphere(1.0, 4), morph::make_icosphere(0.25, 1), Certifies::most},
      {morph::make_icosphere(1.0, 3), morph::test::scaled(morph::make_icosphere(1.0, 3), 0.25),
       Certifies::some},
      {morph::test::random_sphere_polytope(400, 11), morph::test::cube(0.3), Certifies::most},
      {morph::test::random_sphere_polytope(300, 12),
       morph::test::translated(morph::test::tetrahedron(0.2), {0.3, -0.2, 0.1}), Certifies::most},
      {morph::test::random_sphere_polytope(200, 13),
       morph::test::transformed(morph::test::random_sphere_polytope(40, 14, 0.2),
                                morph::test::random_rotation(15)),
       Certifies::some},
      {morph::make_uv_sphere(1.0, 40), morph::test::cube(0.3), Certifies::orientations},
  };
  for (const Case& c : cases) {
    const Polytope A = make_operand(c.A, "A");
    const Polytope B = make_operand(c.B, "B");
    CAPTURE(A.num_faces());
    RepairCounts counts, untaken;
    const MaybePolytope r = erode_polytope(A, B, {.counts = &counts, .verify_certified = true});
    REQUIRE(r.polytope);
    CHECK(difference(erode_polytope(A, B, {.counts = &untaken, .certify = false}), r) == "");
    CHECK(untaken.certified == 0);
    CHECK(counts.certified_wrong == 0);
    CAPTURE(counts.certified);
    // A guess of A's fans has k - 2 triangles per vertex of k facets.
    const long triangles = static_cast<long>(A.fan_face.size()) - 2L * A.num_vertices();
    if (c.certifies == Certifies::orientations) CHECK(counts.certified == triangles);
    if (c.certifies == Certifies::some) CHECK(counts.certified >= triangles);
    // And most far-plane signs: about as many again.
    if (c.certifies == Certifies::most) CHECK(counts.certified > 3 * A.num_faces());
  }
}

// The planes a repair removes from the surface — by a 3-1 flip, or as the folded end of an
// edge that cannot flip, by a fan of its neighbours — lie strictly inside the result (see
// DualSurface::inside): the check does not walk to them, and with verify_certified it does,
// finding each strictly below the result's highest vertex along its normal. Here where
// many vanish (a UV sphere's rows of quadrilaterals, an icosphere's facets near the arcs of
// a small element's Gauss map), and on a cube with a chamfered edge whose chamfer an
// octahedron of radius r makes vanish (chamfer width c < r) or leaves touching the result
// along an edge (c = r: a plane through two vertices, not strictly inside).
TEST_CASE("halfspace_intersection: the planes a repair removes stay strictly inside") {
  const auto chamfered = [](double c) {
    std::vector<morph::Point> p;
    for (double z : {-1.0, 1.0}) {
      for (const auto& [x, y] : {std::pair(-1.0, -1.0), std::pair(1.0, -1.0), std::pair(-1.0, 1.0),
                                 std::pair(1.0, 1.0 - c), std::pair(1.0 - c, 1.0)})
        p.push_back({x, y, z});
    }
    return morph::test::convex_hull_mesh(p);
  };
  struct Case {
    morph::Mesh A, B;
    bool removes;
  };
  const Case cases[] = {
      {morph::make_uv_sphere(1.0, 40), morph::test::cube(0.3), true},
      {morph::make_icosphere(1.0, 4), morph::make_icosphere(0.25, 1), true},
      {morph::make_uv_sphere(1.0, 66), morph::test::scaled(sample("snub_dodecahedron.off"), 0.25),
       true},
      {morph::test::random_sphere_polytope(2000, 21),
       morph::test::transformed(morph::test::random_sphere_polytope(60, 22, 0.3),
                                morph::test::random_rotation(23)),
       true},
      {chamfered(0.125), morph::test::octahedron(0.25), false},
      {chamfered(0.25), morph::test::octahedron(0.25), false},
  };
  for (const Case& c : cases) {
    const Polytope A = make_operand(c.A, "A");
    const Polytope B = make_operand(c.B, "B");
    CAPTURE(A.num_faces());
    RepairCounts skipped, walked;
    const MaybePolytope r = erode_polytope(A, B, {.counts = &skipped});
    REQUIRE(r.polytope);
    CHECK(difference(erode_polytope(A, B, {.guess = false}), r) == "");
    CHECK(difference(erode_polytope(A, B, {.counts = &walked, .verify_certified = true}), r) == "");
    CHECK(walked.certified_wrong == 0);
    CHECK(skipped.check_planes + skipped.removals == walked.check_planes);
    if (c.removes) CHECK(skipped.removals > 0);
    if (c.removes) CHECK(skipped.fan_removals > 0);
  }
  // The chamfer vanishes, or touches the result along an edge.
  const Polytope B = make_operand(morph::test::octahedron(0.25), "B");
  CHECK(erode_polytope(make_operand(chamfered(0.125), "A"), B).polytope->num_faces() == 6);
  CHECK(erode_polytope(make_operand(chamfered(0.25), "A"), B).polytope->num_faces() == 6);
  CHECK(erode_polytope(make_operand(chamfered(0.375), "A"), B).polytope->num_faces() == 7);
}
