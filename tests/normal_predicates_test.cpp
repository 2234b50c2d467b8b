// Tests of the predicates on facet normals (libmorph/src/polytope.h), every decision of
// the FIMS kernel: the double filter and the double-double stage must give the sign of
// the exact evaluation, above all on the nearly degenerate triples that pairs of fine
// spheres are full of (nearly parallel facets, mirror-symmetric facets).
#include <CGAL/Mpzf.h>
#include <doctest/doctest.h>
#include <morph/io.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <random>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "../libmorph/src/gauss_map.h"
#include "../libmorph/src/halfspace_intersection.h"
#include "../libmorph/src/polytope.h"
#include "support/polytopes.h"

namespace {

using morph::Mesh;
using morph::detail::NormalRef;
using morph::detail::Polytope;

struct Tally {
  int triples = 0, zero = 0, tiny = 0;  // tiny: |det| of the unit normals below 1e-13
  int tiny_cross = 0;                   // the same for (a x b) . (a x c)
};

/// For each facet of A, the `near` facets of B with the closest normals; every triple of
/// A's facet and two of those, in both argument orders, against exact evaluation.
void check_near_triples(const Polytope& A, const Polytope& B, int near, Tally& tally) {
  std::vector<int> order(B.num_faces());
  for (int f = 0; f < A.num_faces(); ++f) {
    const auto& n = A.unit_normals[f];
    std::iota(order.begin(), order.end(), 0);
    std::partial_sort(order.begin(), order.begin() + near, order.end(), [&](int g, int h) {
      const auto &u = B.unit_normals[g], &w = B.unit_normals[h];
      return n.x * u.x + n.y * u.y + n.z * u.z > n.x * w.x + n.y * w.y + n.z * w.z;
    });
    const NormalRef a{&A, f};
    for (int i = 0; i < near; ++i)
      for (int j = i + 1; j < near; ++j) {
        const NormalRef b{&B, order[i]}, c{&B, order[j]};
        const int exact = CGAL::sign(morph::detail::det(a.exact(), b.exact(), c.exact()));
        CHECK(morph::detail::orient_normals(a, b, c) == exact);
        CHECK(morph::detail::orient_normals(b, a, c) == -exact);
        CHECK(morph::detail::orient_normals(c, b, a) == -exact);
        const int exact_cross =
            CGAL::sign(morph::detail::cross_dot(a.exact(), b.exact(), a.exact(), c.exact()));
        CHECK(morph::detail::cross_dot_normals(a, b, a, c) == exact_cross);
        CHECK(morph::detail::cross_dot_normals(b, c, a, c) ==
              CGAL::sign(morph::detail::cross_dot(b.exact(), c.exact(), a.exact(), c.exact())));
        ++tally.triples;
        tally.zero += exact == 0;
        const auto &p = a.unit(), &q = b.unit(), &r = c.unit();
        const double d = p.x * (q.y * r.z - q.z * r.y) + p.y * (q.z * r.x - q.x * r.z) +
                         p.z * (q.x * r.y - q.y * r.x);
        tally.tiny += exact != 0 && std::abs(d) < 1e-13;
        auto dot = [](const auto& u, const auto& w) { return u.x * w.x + u.y * w.y + u.z * w.z; };
        const double cd = dot(p, p) * dot(q, r) - dot(p, r) * dot(q, p);
        tally.tiny_cross += exact_cross != 0 && std::abs(cd) < 1e-13;
      }
  }
}

/// The rotation by `angle` about (1, 2, 3), row-major.
std::vector<double> small_rotation(double angle) {
  const double l = std::sqrt(14.0), x = 1 / l, y = 2 / l, z = 3 / l;
  const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
  return {t * x * x + c,     t * x * y - s * z, t * x * z + s * y,  //
          t * x * y + s * z, t * y * y + c,     t * y * z - s * x,  //
          t * x * z - s * y, t * y * z + s * x, t * z * z + c};
}

Mesh sample(const std::string& name) {
  return morph::read_mesh(std::string(MORPH_SAMPLES_DIR) + "/" + name);
}

/// The mesh moved by (t, 2t, 3t).
Mesh shifted(Mesh mesh, double t) {
  for (const auto v : mesh.vertices())
    mesh.set_point(v, mesh.point(v) + morph::Point(t, 2 * t, 3 * t));
  return mesh;
}

// A's facets in `order`, the three whose unit normals are closest to n first.
template <class V>
void closest_three(const Polytope& A, const V& n, std::vector<int>& order) {
  std::iota(order.begin(), order.end(), 0);
  std::partial_sort(order.begin(), order.begin() + 3, order.end(), [&](int f, int g) {
    const auto &u = A.unit_normals[f], &w = A.unit_normals[g];
    return n.x * u.x + n.y * u.y + n.z * u.z > n.x * w.x + n.y * w.y + n.z * w.z;
  });
}

}  // namespace

TEST_CASE(
    "normal predicates: the filters agree with exact evaluation on nearly degenerate triples") {
  const Mesh ico320 = sample("icosphere_320.off"), ico1280 = sample("icosphere_1280.off");
  struct Pair {
    std::string what;
    Mesh a, b;
    bool degenerate = false;  // known to hold exactly coplanar and nearly coplanar triples
  };
  const std::vector<Pair> pairs = {
      {"icosphere 320 and 1280 (nearly parallel and mirror-symmetric facets)", ico320, ico1280,
       true},
      {"icosphere 1280 and a copy turned by 1e-12", ico1280,
       morph::test::transformed(ico1280, small_rotation(1e-12))},
      {"tiny and huge copies", morph::test::scaled(ico320, 1e-60),
       morph::test::scaled(ico1280, 1e60)},
      {"integer polytopes", morph::test::random_integer_polytope(60, 3, 4),
       morph::test::random_integer_polytope(60, 4, 4)},
  };
  for (const auto& pair : pairs) {
    CAPTURE(pair.what);
    const Polytope A = morph::detail::make_operand(pair.a, "A");
    const Polytope B = morph::detail::make_operand(pair.b, "B");
    Tally tally;
    check_near_triples(A, B, 6, tally);
    MESSAGE(pair.what << ": " << tally.triples << " triples, " << tally.zero
                      << " exactly coplanar, " << tally.tiny << " nonzero below the double filter ("
                      << tally.tiny_cross << " of cross_dot)");
    CHECK(tally.triples > 0);
    if (pair.degenerate) {
      CHECK(tally.zero > 0);
      CHECK(tally.tiny > 0);
      CHECK(tally.tiny_cross > 0);
    }
  }
}

// An erosion's facets carry given exact normals (exact points): their double-double stage
// splits those normals, and must agree with exact evaluation against the element's
// normals, which are nearly parallel to them (A and B are fine spheres).
TEST_CASE("normal predicates: the double-double stage on an erosion's given normals") {
  const Polytope A = morph::detail::make_operand(sample("icosphere_1280.off"), "A");
  const Polytope B =
      morph::detail::make_operand(morph::test::scaled(sample("icosphere_320.off"), 0.25), "B");
  const morph::detail::MaybePolytope e = morph::detail::erode_polytope(A, B);
  REQUIRE(e.polytope);
  const Polytope& E = *e.polytope;
  REQUIRE(!E.exact_points.empty());
  for (int f = 0; f < E.num_faces(); ++f) {
    const auto& n = E.precise_normal(f);
    REQUIRE(n.valid);
    // The split is tight: each error is far below the double-double's precision.
    for (int i = 0; i < 3; ++i) CHECK(n.error[i] <= 0x1p-100);
  }
  Tally tally;
  check_near_triples(E, B, 6, tally);
  check_near_triples(B, E, 6, tally);
  check_near_triples(E, E, 6, tally);
  MESSAGE("erosion: " << tally.triples << " triples, " << tally.zero << " exactly coplanar, "
                      << tally.tiny << " nonzero below the double filter");
  CHECK(tally.triples > 0);
}

// The kernel orients normals against an arc by its plane N_left x N_right, made once per
// edge (gauss_map.h): the same double stage evaluated in other operations, with the same
// bound; it must agree with exact evaluation where the filter is tested hardest.
TEST_CASE("normal predicates: orientation against an arc's plane agrees with exact evaluation") {
  const Mesh ico1280 = sample("icosphere_1280.off");
  const std::vector<std::pair<Mesh, Mesh>> pairs = {
      {sample("icosphere_320.off"), ico1280},
      {ico1280, morph::test::transformed(ico1280, small_rotation(1e-12))}};
  for (const auto& [a, b] : pairs) {
    const Polytope A = morph::detail::make_operand(a, "A");
    const Polytope B = morph::detail::make_operand(b, "B");
    const auto planes = morph::detail::arc_planes(B);
    int tested = 0, zero = 0;
    std::vector<int> order(A.num_faces());
    for (int e = 0; e < B.num_edges(); ++e) {
      const NormalRef l{&B, B.edges[e].left}, r{&B, B.edges[e].right};
      // A's facets with the normals closest to the arc's ends.
      for (const NormalRef& end : {l, r}) {
        closest_three(A, end.unit(), order);
        for (int k = 0; k < 3; ++k) {
          const NormalRef x{&A, order[k]};
          const int exact = CGAL::sign(morph::detail::det(l.exact(), r.exact(), x.exact()));
          CHECK(morph::detail::orient_arc(B, e, planes[e], x) == exact);
          ++tested;
          zero += exact == 0;
        }
      }
    }
    CHECK(tested > 0);
    MESSAGE(tested << " orientations against arcs, " << zero << " exactly zero");
  }
}

// Pairs for the slot-plane tests: a finer sphere, a nearly identical one, and the same far
// from unit scale and shifted (normals do not change).
namespace {
std::vector<std::pair<Mesh, Mesh>> slot_test_pairs() {
  const Mesh ico1280 = sample("icosphere_1280.off");
  return {{sample("icosphere_320.off"), ico1280},
          {ico1280, morph::test::transformed(ico1280, small_rotation(1e-12))},
          {morph::test::transformed(ico1280, {0x1p-200, 0, 0, 0, 0x1p-200, 0, 0, 0, 0x1p-200}),
           morph::test::transformed(sample("icosphere_320.off"),
                                    {0x1p200, 0, 0, 0, 0x1p200, 0, 0, 0, 0x1p200})},
          {shifted(sample("icosphere_320.off"), 1024), shifted(ico1280, -4096)}};
}
}  // namespace

// locate's region test reads the arc planes per fan slot, oriented as the slot runs
// (slot_planes): the filter's decisions must be those of exact det(N_fan[s], N_fan[s+1], x),
// also for the slots that run against their edge, on the nearest normals of a finer sphere,
// a nearly identical one, and the same far from unit scale (normals do not change).
TEST_CASE("normal predicates: a region's slot planes agree with exact evaluation") {
  const std::vector<std::pair<Mesh, Mesh>> pairs = slot_test_pairs();
  for (const auto& [a, b] : pairs) {
    const Polytope A = morph::detail::make_operand(a, "A");
    const Polytope B = morph::detail::make_operand(b, "B");
    const auto slots = morph::detail::slot_planes(B);
    REQUIRE(slots.size() == B.fan_face.size());
    int tested = 0, decided = 0, flipped = 0, not_cross = 0;
    std::vector<int> order(A.num_faces());
    for (int v = 0; v < B.num_vertices(); ++v) {
      const int begin = B.fan_begin[v], n = B.fan_begin[v + 1] - begin;
      for (int i = 0; i < n; ++i) {
        const int s = begin + i;
        const NormalRef l{&B, B.fan_face[s]}, r{&B, B.fan_face[begin + (i + 1) % n]};
        flipped += B.edges[B.fan_edge[s]].left != l.face;
        // Each slot's plane is cross_plane of its two normals, bit for bit (the last slot's
        // second normal is the fan's first).
        const morph::detail::ArcPlane c = morph::detail::cross_plane(l.unit(), r.unit());
        not_cross += !(slots[s].x == c.x && slots[s].y == c.y && slots[s].z == c.z &&
                       slots[s].error == c.error);
        closest_three(A, l.unit(), order);
        for (int k = 0; k < 3; ++k) {
          const NormalRef x{&A, order[k]};
          const int exact = CGAL::sign(morph::detail::det(l.exact(), r.exact(), x.exact()));
          const int filter = morph::detail::orient_arc_filter(slots[s], x);
          if (filter != morph::detail::kUndecided) {
            CHECK(filter == exact);
            ++decided;
          }
          ++tested;
        }
      }
    }
    CHECK(flipped > 0);
    CHECK(decided > 0);
    CHECK(not_cross == 0);
    MESSAGE(tested << " slot orientations, " << decided << " decided by the filter");
  }
}

// The kernel's walks make a region's slot planes on first use (SlotCache): the same doubles
// as slot_planes, so every walk answers as with them, or with planes formed at each test.
// Walks from a far, fixed start and from the previous answer, with and without the first
// step in doubles (the kernel skips it after a walk that stayed where it started), on the
// pairs above; a vertex answer's region must contain the direction by exact evaluation.
TEST_CASE("normal predicates: locate with a SlotCache answers as with slot_planes") {
  using morph::detail::Location;
  const std::vector<std::pair<Mesh, Mesh>> pairs = slot_test_pairs();
  auto same = [](const Location& x, const Location& y) {
    return x.kind == y.kind && x.index == y.index;
  };
  for (const auto& [a, b] : pairs) {
    const Polytope A = morph::detail::make_operand(a, "A");
    const Polytope B = morph::detail::make_operand(b, "B");
    const auto slots = morph::detail::slot_planes(B);
    morph::detail::SlotCache cache(B);
    int differing = 0, hint = 0, outside = 0, vertex_answers = 0;
    for (int f = 0; f < A.num_faces(); ++f) {
      const NormalRef n{&A, f};
      for (const int start : {0, B.num_vertices() - 1, hint}) {
        const Location want = morph::detail::locate(B, slots.data(), n, start);
        differing += !same(morph::detail::locate(B, cache, n, start), want);
        differing += !same(morph::detail::locate(B, nullptr, n, start), want);
        differing += !same(morph::detail::locate(B, cache, n, start, false), want);
        differing += !same(morph::detail::locate(B, slots.data(), n, start, false), want);
        if (start != hint || want.kind != Location::Kind::vertex) continue;
        ++vertex_answers;
        const int v = want.index, begin = B.fan_begin[v], d = B.fan_begin[v + 1] - begin;
        for (int i = 0; i < d; ++i) {
          const NormalRef l{&B, B.fan_face[begin + i]}, r{&B, B.fan_face[begin + (i + 1) % d]};
          outside += CGAL::sign(morph::detail::det(l.exact(), r.exact(), n.exact())) <= 0;
        }
      }
      hint = morph::detail::location_vertex(B, morph::detail::locate(B, cache, n, hint));
    }
    CHECK(differing == 0);
    CHECK(outside == 0);
    CHECK(vertex_answers > 0);
    // The cache's planes (made by the walks, or here for regions they did not reach) are
    // slot_planes', bit for bit.
    int planes_differing = 0;
    for (int v = 0; v < B.num_vertices(); ++v) {
      const morph::detail::ArcPlane* const made = cache.region(v);
      for (int s = B.fan_begin[v]; s < B.fan_begin[v + 1]; ++s)
        planes_differing += !(made[s].x == slots[s].x && made[s].y == slots[s].y &&
                              made[s].z == slots[s].z && made[s].error == slots[s].error);
    }
    CHECK(planes_differing == 0);
  }
}

// A region's cap (RegionCap) stands in for its region test: every direction in it must be
// inside the region by exact evaluation, on every slot. Checked on the facet normals of
// nearly degenerate pairs (the finer sphere's normals within 1e-16 of the coarser's region
// corners, a copy turned by 1e-12, scaled far from unit size) and of the pair whose walks use
// caps in the kernel (uvsphere_1600 on the snub dodecahedron's map); the caps' radii must
// stay below each slot's great circle's distance from the centre, and walks with caps must
// answer as without.
TEST_CASE("normal predicates: a region's cap holds only directions inside the region") {
  using morph::detail::Location;
  std::vector<std::pair<Mesh, Mesh>> pairs = slot_test_pairs();
  pairs.emplace_back(sample("uvsphere_1600.off"), sample("snub_dodecahedron.off"));
  pairs.emplace_back(sample("icosphere_1280.off"), sample("icosphere_320.off"));
  int total_in_caps = 0;
  for (const auto& [a, b] : pairs) {
    const Polytope A = morph::detail::make_operand(a, "A");
    const Polytope B = morph::detail::make_operand(b, "B");
    const auto slots = morph::detail::slot_planes(B);
    morph::detail::SlotCache cache(B, true);
    REQUIRE(cache.has_caps());
    int capped = 0, in_caps = 0, outside = 0, wide = 0, differing = 0;
    for (int v = 0; v < B.num_vertices(); ++v) {
      const morph::detail::RegionCap cap = morph::detail::region_cap(B, slots.data(), v);
      if (cap.threshold > 1) continue;
      ++capped;
      const int begin = B.fan_begin[v], d = B.fan_begin[v + 1] - begin;
      const double radius = std::acos(cap.threshold);
      for (int s = begin; s < begin + d; ++s) {
        const auto& p = slots[s];
        const double size = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
        wide += std::asin((cap.x * p.x + cap.y * p.y + cap.z * p.z) / size) <= radius;
      }
      for (int f = 0; f < A.num_faces(); ++f) {
        if (!morph::detail::in_cap(cap, A.unit_normals[f])) continue;
        ++in_caps;
        const NormalRef n{&A, f};
        for (int i = 0; i < d; ++i) {
          const NormalRef l{&B, B.fan_face[begin + i]}, r{&B, B.fan_face[begin + (i + 1) % d]};
          outside += CGAL::sign(morph::detail::det(l.exact(), r.exact(), n.exact())) <= 0;
        }
      }
    }
    int hint = 0;
    for (int f = 0; f < A.num_faces(); ++f) {
      const NormalRef n{&A, f};
      for (const int start : {0, hint}) {
        const Location want = morph::detail::locate(B, slots.data(), n, start);
        for (const bool step : {true, false}) {
          const Location got = morph::detail::locate(B, cache, n, start, step);
          differing += got.kind != want.kind || got.index != want.index;
        }
      }
      hint = morph::detail::location_vertex(B, morph::detail::locate(B, cache, n, hint));
    }
    CHECK(capped > 0);
    CHECK(outside == 0);
    CHECK(wide == 0);
    CHECK(differing == 0);
    total_in_caps += in_caps;
  }
  CHECK(total_in_caps > 1000);
}

// Within a NearPairScope, orient_undecided decides nearly parallel pairs with the pair's
// cross product kept from an earlier predicate: each answer must be exact evaluation's, the
// first time (the product made) and after (kept), in every argument order, on triples of a
// facet normal, a neighbour's across one of its edges (the arcs the kernel tests) and the
// closest normals of the other polytope (within 1e-16 on the finer sphere, or exactly
// parallel under a scale by a power of two), and with nested scopes.
TEST_CASE("normal predicates: orient_undecided with kept cross products agrees with exact") {
  const std::vector<std::pair<Mesh, Mesh>> pairs = slot_test_pairs();
  int decided = 0;
  for (const auto& [a, b] : pairs) {
    const Polytope A = morph::detail::make_operand(a, "A");
    const Polytope B = morph::detail::make_operand(b, "B");
    const morph::detail::NearPairScope outer(A, B);
    std::vector<int> order(B.num_faces());
    int wrong = 0;
    for (int f = 0; f < A.num_faces(); ++f) {
      closest_three(B, A.unit_normals[f], order);
      const morph::detail::NearPairScope inner(A, B);  // nested: kept per facet, then restored
      for (int k = A.face_begin[f]; k < A.face_begin[f + 1]; ++k) {
        const auto& e = A.edges[A.corner_edge[k]];
        const NormalRef n{&A, f}, h{&A, e.left == f ? e.right : e.left};
        for (int j = 0; j < 3; ++j) {
          const NormalRef g{&B, order[j]};
          const NormalRef triples[6][3] = {{n, h, g}, {h, n, g}, {g, n, h},
                                           {n, g, h}, {h, g, n}, {g, h, n}};
          for (const auto& t : triples) {
            const int exact =
                CGAL::sign(morph::detail::det(t[0].exact(), t[1].exact(), t[2].exact()));
            for (int repeat = 0; repeat < 2; ++repeat) {
              wrong += morph::detail::orient_undecided(t[0], t[1], t[2]) != exact;
              ++decided;
            }
          }
        }
      }
    }
    CHECK(wrong == 0);
  }
  CHECK(decided > 0);
}

// same_normal (gauss_map.h) spares the later stages the predicates on exactly coincident
// normals (A (+) A, A (+) -A, A (+) an exact translate or a copy scaled by a power of two):
// it must claim equal directions only where they are exactly equal (not for a copy scaled by
// 0.3 or -0.5, unless exactly so), and the kernel's predicates with that shortcut must still
// agree with exact evaluation on triples holding such pairs, also scaled by 2^+-200 and
// moved far from the origin (where it must claim nothing that is not exact).
TEST_CASE("normal predicates: same_normal and the kernel's orientations on coincident normals") {
  using morph::Point;
  namespace test = morph::test;
  const Mesh ico320 = sample("icosphere_320.off");
  const Mesh integer = test::random_integer_polytope(30, 17, 4);
  const std::vector<double> up = {0x1p200, 0, 0, 0, 0x1p200, 0, 0, 0, 0x1p200};
  const std::vector<double> down = {0x1p-200, 0, 0, 0, 0x1p-200, 0, 0, 0, 0x1p-200};
  struct Pair {
    std::string what;
    Mesh a, b;
    bool coincident;  // same_normal must find every exactly equal direction
  };
  const std::vector<Pair> pairs = {
      {"icosphere A + A", ico320, ico320, true},
      {"icosphere A + -A (centrally symmetric)", ico320, test::reflected(ico320), true},
      {"integer A + exact translate", integer, test::translated(integer, Point(3, -1, 7)), true},
      {"integer A + -A", integer, test::reflected(integer), false},
      {"icosphere A + 0.5 A", ico320, test::scaled(ico320, 0.5), true},
      {"icosphere A + 0.25 A", ico320, test::scaled(ico320, 0.25), true},
      {"icosphere A + 2 A", ico320, test::scaled(ico320, 2), true},
      {"icosphere A + 2^-250 A (the smallest supported size)", ico320,
       test::scaled(ico320, 0x1p-250), true},
      {"icosphere 2^-250 A + 2^250 A", test::scaled(ico320, 0x1p-250),
       test::scaled(ico320, 0x1p250), true},
      {"icosphere A + 2^250 A (the largest supported size)", ico320, test::scaled(ico320, 0x1p250),
       true},
      {"integer A + (0.5 A + t)", integer,
       test::translated(test::scaled(integer, 0.5), Point(3, -1, 7)), true},
      {"integer A + (8 A + t)", integer,
       test::translated(test::scaled(integer, 8), Point(-5, 2, 1)), true},
      {"icosphere A + 0.3 A (rounded)", ico320, test::scaled(ico320, 0.3), false},
      {"integer A + 0.3 A (rounded)", integer, test::scaled(integer, 0.3), false},
      {"icosphere A + -0.5 A", ico320, test::reflected(test::scaled(ico320, 0.5)), false},
      {"integer A + -0.5 A", integer, test::reflected(test::scaled(integer, 0.5)), false},
      {"icosphere A + A, both scaled by 2^200", test::transformed(ico320, up),
       test::transformed(ico320, up), true},
      {"icosphere A + A, both scaled by 2^-200", test::transformed(ico320, down),
       test::transformed(ico320, down), true},
      {"icosphere scaled by 2^-200 and by 2^200 (a scaling by 2^400)",
       test::transformed(ico320, down), test::transformed(ico320, up), true},
      {"icosphere and a rounded far translate", ico320, shifted(ico320, 1024), false},
      {"icosphere and a copy turned by 1e-12", ico320,
       test::transformed(ico320, small_rotation(1e-12)), false},
  };
  for (const auto& pair : pairs) {
    CAPTURE(pair.what);
    const Polytope A = morph::detail::make_operand(pair.a, "A");
    const Polytope B = morph::detail::make_operand(pair.b, "B");
    const auto planes = morph::detail::arc_planes(B);
    int equal = 0, shown = 0, tested = 0, zero = 0;
    std::vector<int> order(B.num_faces());
    for (int f = 0; f < A.num_faces(); ++f) {
      const NormalRef a{&A, f};
      closest_three(B, a.unit(), order);
      for (int k = 0; k < 3; ++k) {
        const NormalRef b{&B, order[k]};
        const auto c = morph::detail::cross(a.exact(), b.exact());
        const bool same = CGAL::sign(c.x) == CGAL::ZERO && CGAL::sign(c.y) == CGAL::ZERO &&
                          CGAL::sign(c.z) == CGAL::ZERO &&
                          CGAL::sign(morph::detail::dot(a.exact(), b.exact())) > 0;
        const bool claimed = morph::detail::same_normal(a, b);
        CHECK(morph::detail::same_normal(b, a) == claimed);
        if (claimed) CHECK(same);
        if (pair.coincident && same) CHECK(claimed);
        equal += same;
        shown += claimed;
      }
      // Triples of a, its nearest facet of B, and their neighbours, in all the forms the
      // kernel evaluates: orient on three normals and against B's arc planes.
      const NormalRef b{&B, order[0]};
      std::vector<NormalRef> around;
      for (const auto& [P, g] : {std::pair{&A, f}, std::pair{&B, order[0]}})
        for (int i = P->face_begin[g]; i < P->face_begin[g + 1]; ++i) {
          const auto& e = P->edges[P->corner_edge[i]];
          around.push_back({P, e.left == g ? e.right : e.left});
        }
      for (const NormalRef& x : around) {
        for (const auto& [p, q, r] :
             {std::tuple{a, b, x}, std::tuple{b, x, a}, std::tuple{x, a, b}}) {
          const int exact = CGAL::sign(morph::detail::det(p.exact(), q.exact(), r.exact()));
          CHECK(morph::detail::orient(p, q, r) == exact);
          zero += exact == 0;
          ++tested;
        }
      }
      for (int i = B.face_begin[b.face]; i < B.face_begin[b.face + 1]; ++i) {
        const int e = B.corner_edge[i];
        const NormalRef l{&B, B.edges[e].left}, r{&B, B.edges[e].right};
        for (const NormalRef& x : {a, around[0]}) {
          const int exact = CGAL::sign(morph::detail::det(l.exact(), r.exact(), x.exact()));
          CHECK(morph::detail::orient_arc(B, e, planes[e], x) == exact);
          ++tested;
        }
      }
    }
    MESSAGE(pair.what << ": " << equal << " exactly equal directions among the nearest, " << shown
                      << " shown by same_normal; " << tested << " orientations, " << zero
                      << " exactly zero");
    if (pair.coincident) CHECK(shown > 0);
  }
}

// The double-double stage alone (orient_normals_precise, and cross_dot_normals_precise) must
// return the exact sign or kUndecided, never a wrong sign: on triples of a facet of A, its nearest
// facets of B and their neighbours (a nearly parallel pair with a far third normal, decided from
// the pair's precise normals only, and mirror-symmetric triples, whose shared zero component is
// shown from the points), in every argument order, also scaled by 2^+-200, moved far from the
// origin, and for a copy turned by 1e-12 (every pair nearly parallel). The precise normals'
// zero components must be exactly those of the exact normals.
TEST_CASE("normal predicates: the double-double stage alone agrees with exact evaluation") {
  namespace test = morph::test;
  const Mesh ico320 = sample("icosphere_320.off"), ico1280 = sample("icosphere_1280.off");
  const std::vector<double> up = {0x1p200, 0, 0, 0, 0x1p200, 0, 0, 0, 0x1p200};
  const std::vector<double> down = {0x1p-200, 0, 0, 0, 0x1p-200, 0, 0, 0, 0x1p-200};
  struct Pair {
    std::string what;
    Mesh a, b;
    bool degenerate;  // known to hold nearly parallel pairs and exactly coplanar triples
  };
  const std::vector<Pair> pairs = {
      {"icosphere 320 and 1280", ico320, ico1280, true},
      {"icosphere 320 and 1280 scaled by 2^-200 and 2^200", test::transformed(ico320, down),
       test::transformed(ico1280, up), true},
      {"icosphere 320 and 1280 far from the origin", shifted(ico320, 1024), shifted(ico1280, -4096),
       false},
      {"icosphere 1280 and a copy turned by 1e-12", ico1280,
       test::transformed(ico1280, small_rotation(1e-12)), false},
      {"integer polytopes", test::random_integer_polytope(60, 3, 4),
       test::random_integer_polytope(60, 4, 4), false},
  };
  for (const auto& pair : pairs) {
    CAPTURE(pair.what);
    const Polytope A = morph::detail::make_operand(pair.a, "A");
    const Polytope B = morph::detail::make_operand(pair.b, "B");
    for (const Polytope* P : {&A, &B})
      for (int f = 0; f < P->num_faces(); ++f) {
        const auto& n = P->precise_normal(f);
        if (!n.valid) continue;
        const auto& x = P->exact_normal(f);
        for (int i = 0; i < 3; ++i)
          CHECK(n.exactly_zero(i) == (CGAL::sign(i == 0 ? x.x : i == 1 ? x.y : x.z) == 0));
      }
    int tested = 0, decided = 0, zero = 0, zero_decided = 0, tiny = 0, tiny_decided = 0;
    int tested_cross = 0, decided_cross = 0, full_decided = 0;
    std::vector<int> order(B.num_faces());
    for (int f = 0; f < A.num_faces(); ++f) {
      const NormalRef a{&A, f};
      closest_three(B, a.unit(), order);
      std::vector<NormalRef> near = {a};
      for (int k = 0; k < 3; ++k) near.push_back({&B, order[k]});
      for (const auto& [P, g] : {std::pair{&A, f}, std::pair{&B, order[0]}})
        for (int i = P->face_begin[g]; i < P->face_begin[g + 1]; ++i) {
          const auto& e = P->edges[P->corner_edge[i]];
          near.push_back({P, e.left == g ? e.right : e.left});
        }
      for (std::size_t i = 0; i < near.size(); ++i)
        for (std::size_t j = i + 1; j < near.size(); ++j)
          for (std::size_t k = j + 1; k < near.size(); ++k) {
            const NormalRef &p = near[i], &q = near[j], &r = near[k];
            const int exact = CGAL::sign(morph::detail::det(p.exact(), q.exact(), r.exact()));
            const auto &u = p.unit(), &v = q.unit(), &w = r.unit();
            const double filter = u.x * (v.y * w.z - v.z * w.y) + u.y * (v.z * w.x - v.x * w.z) +
                                  u.z * (v.x * w.y - v.y * w.x);
            const bool below = exact != 0 && std::abs(filter) < 1e-13;
            bool all = true;
            for (const auto& [x, y, z, sign] :
                 {std::tuple{p, q, r, 1}, std::tuple{q, r, p, 1}, std::tuple{r, p, q, 1},
                  std::tuple{q, p, r, -1}, std::tuple{p, r, q, -1}, std::tuple{r, q, p, -1}}) {
              const int s = morph::detail::orient_normals_precise(x, y, z);
              if (s != morph::detail::kUndecided) CHECK(s == sign * exact);
              all = all && s != morph::detail::kUndecided;
              ++tested;
              decided += s != morph::detail::kUndecided;
              // Without the pair's step (orient_undecided's entry after a kept product).
              const int full = morph::detail::orient_normals_precise_full(x, y, z);
              if (full != morph::detail::kUndecided) CHECK(full == sign * exact);
              full_decided += full != morph::detail::kUndecided;
            }
            // (x x y) . (z x t) in the forms between() evaluates on such triples, and with
            // the nearly parallel pair second.
            for (const auto& [x, y, z, t] :
                 {std::tuple{p, q, p, r}, std::tuple{q, r, p, r}, std::tuple{p, r, q, r},
                  std::tuple{r, p, q, p}, std::tuple{q, p, r, q}, std::tuple{p, q, r, p}}) {
              const int exact_cross =
                  CGAL::sign(morph::detail::cross_dot(x.exact(), y.exact(), z.exact(), t.exact()));
              const int s = morph::detail::cross_dot_normals_precise(x, y, z, t);
              if (s != morph::detail::kUndecided) CHECK(s == exact_cross);
              ++tested_cross;
              decided_cross += s != morph::detail::kUndecided;
            }
            zero += exact == 0;
            zero_decided += exact == 0 && all;
            tiny += below;
            tiny_decided += below && all;
          }
    }
    MESSAGE(pair.what << ": " << tested << " orientations, " << decided << " decided; " << zero
                      << " exactly coplanar triples (" << zero_decided << " decided), " << tiny
                      << " nonzero below the double filter (" << tiny_decided << " decided); "
                      << tested_cross << " of cross_dot, " << decided_cross << " decided");
    CHECK(decided > 0);
    CHECK(full_decided > 0);
    CHECK(decided_cross > 0);
    if (pair.degenerate) {
      CHECK(zero_decided > 0);
      CHECK(tiny_decided > 0);
    }
  }
}

// Precise normals are made on first use in one flat array per polytope: threads racing for
// the same facets must all read the values one thread alone makes, bit for bit.
TEST_CASE("normal predicates: precise normals made by racing threads are a lone thread's") {
  const Mesh ico = sample("icosphere_1280.off");
  const Polytope alone = morph::detail::make_operand(ico, "alone");
  const Polytope shared = morph::detail::make_operand(ico, "shared");
  constexpr int kThreads = 4;
  std::vector<std::vector<morph::detail::PreciseNormal>> seen(kThreads);
  {
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t)
      threads.emplace_back([&, t] {
        // Different orders, so that threads meet on slots being written.
        for (int i = 0; i < shared.num_faces(); ++i) {
          const int f = t % 2 == 0 ? i : shared.num_faces() - 1 - i;
          seen[t].push_back(shared.precise_normal(f));
        }
      });
    for (auto& thread : threads) thread.join();
  }
  auto same = [](const morph::detail::PreciseNormal& x, const morph::detail::PreciseNormal& y) {
    return std::memcmp(x.hi, y.hi, sizeof x.hi) == 0 && std::memcmp(x.lo, y.lo, sizeof x.lo) == 0 &&
           std::memcmp(x.error, y.error, sizeof x.error) == 0 && x.valid == y.valid;
  };
  int differing = 0;
  for (int t = 0; t < kThreads; ++t)
    for (int i = 0; i < alone.num_faces(); ++i) {
      const int f = t % 2 == 0 ? i : alone.num_faces() - 1 - i;
      const auto& y = alone.precise_normal(f);
      differing += !same(seen[t][i], y) || !same(shared.precise_normal(f), y);
    }
  CHECK(differing == 0);
}

// two_prod takes a fused multiply-subtract where the processor has one (kHasFma): its doubles
// must be Dekker's, bit for bit (the sign of a zero too), and hi + lo the exact product, on
// random products over a wide range of exponents and on hard ones: significands with all
// bits set, 26-bit halves (Dekker's split), ties of the rounding of hi, powers of two, signed
// zeros, products near the ends of Dekker's range.
TEST_CASE("normal predicates: two_prod with FMA is Dekker's, bit for bit") {
  using morph::detail::DD;
  std::mt19937_64 rng(20261124);
  auto random_double = [&](int min_exponent, int max_exponent) {
    const double significand = 1 + static_cast<double>(rng() >> 12) * 0x1p-52;  // 53 bits
    const int exponent =
        min_exponent +
        static_cast<int>(rng() % static_cast<unsigned>(max_exponent - min_exponent + 1));
    return std::ldexp(rng() % 2 ? -significand : significand, exponent);
  };
  std::vector<std::pair<double, double>> cases;
  for (int i = 0; i < 200000; ++i)
    cases.emplace_back(random_double(-450, 450), random_double(-450, 450));
  const double hard[] = {0.0,
                         -0.0,
                         1.0,
                         -1.0,
                         0x1.fffffffffffffp0,
                         -0x1.fffffffffffffp-1,
                         1 + 0x1p-52,
                         1 - 0x1p-53,
                         134217729.0,  // 2^27 + 1, the split constant
                         0x1.0000001p0,
                         0x1.fffffffp0,
                         0x1.8000000000001p0,
                         0x1.5555555555555p-2,
                         0x1p-500,
                         0x1.fffffffffffffp-480,
                         0x1p990,
                         0x1.fffffffffffffp994,
                         3.0,
                         0.1,
                         -0.7};
  for (double a : hard)
    for (double b : hard)
      if (std::abs(a * b) < 0x1p1000 && (a * b == 0 || std::abs(a * b) > 0x1p-960))
        cases.emplace_back(a, b);
  // Ties: a b exactly halfway between two doubles (hi rounds to even), either side.
  for (int k = 1; k < 2000; k += 2) {
    const double a = 1 + k * 0x1p-27, b = 1 + (2001 - k) * 0x1p-27;
    cases.emplace_back(a, b);
    cases.emplace_back(-a, b);
  }
  int not_exact = 0, differing = 0;
  for (const auto& [a, b] : cases) {
    const DD d = morph::detail::two_prod_dekker(a, b);
    not_exact += CGAL::sign(morph::detail::ExactN(d.hi) + morph::detail::ExactN(d.lo) -
                            morph::detail::ExactN(a) * morph::detail::ExactN(b)) != CGAL::ZERO;
    if (!morph::detail::kHasFma) continue;
    const DD f = morph::detail::two_prod_fma(a, b), t = morph::detail::two_prod(a, b);
    auto bits = [](double x) { return std::bit_cast<std::uint64_t>(x); };
    differing += bits(f.hi) != bits(d.hi) || bits(f.lo) != bits(d.lo) || bits(t.hi) != bits(d.hi) ||
                 bits(t.lo) != bits(d.lo);
  }
  CHECK(not_exact == 0);
  CHECK(differing == 0);
  const std::string compared =
      morph::detail::kHasFma ? "FMA compared with Dekker" : "no FMA here: Dekker's only";
  MESSAGE(cases.size() << " products; " << compared);
}
