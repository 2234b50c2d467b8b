// fims_facets with one thread, when A has more vertices than B, makes the translated facets'
// buffer the result's arrays (take_head) rather than copying them (gather_head, with threads);
// sum_mesh given the facets to keep takes their origins when nothing merges. Both must give
// what the copying paths give, element for element. And the arenas keep to a caller's cap on
// TBB's threads.
#include <doctest/doctest.h>
#include <morph/minkowski_sum.h>
#include <morph/structuring_element.h>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <cstdint>
#include <vector>

#include "fims.h"
#include "parallel.h"
#include "polytope.h"
#include "support/polytopes.h"

namespace {

bool same_origin(const morph::FacetOrigin& x, const morph::FacetOrigin& y) {
  return x.kind == y.kind && x.a.kind == y.a.kind && x.a.index == y.a.index &&
         x.b.kind == y.b.kind && x.b.index == y.b.index;
}

int differing_origins(const std::vector<morph::FacetOrigin>& x,
                      const std::vector<morph::FacetOrigin>& y) {
  int differing = 0;
  for (std::size_t f = 0; f < x.size() && f < y.size(); ++f) differing += !same_origin(x[f], y[f]);
  return differing;
}

}  // namespace

TEST_CASE("fims_facets and sum_mesh take their arrays as the copying paths make them") {
  using morph::Mesh;
  // A with more vertices than B (642 against 42): the translated facets are the head.
  const Mesh A = morph::make_icosphere(1.0, 3);
  const Mesh B =
      morph::test::transformed(morph::make_icosphere(0.5, 1), morph::test::random_rotation(11));
  const morph::detail::Polytope pa = morph::detail::make_operand(A, "A");
  const morph::detail::Polytope pb = morph::detail::make_operand(B, "B");
  REQUIRE(pa.num_vertices() > pb.num_vertices());
  const auto facets_at = [&](int threads) {
    return morph::detail::run_with_threads(threads,
                                           [&] { return morph::detail::fims_facets(pa, pb); });
  };
  const morph::detail::SumFacets one = facets_at(1), two = facets_at(2);
  CHECK(one.face_begin == two.face_begin);
  CHECK(one.corners == two.corners);
  REQUIRE(one.origins.size() == two.origins.size());
  CHECK(differing_origins(one.origins, two.origins) == 0);

  const morph::LabelledMesh kept = morph::detail::sum_mesh(pa, pb, one);
  morph::detail::SumFacets copy = one;
  const morph::LabelledMesh taken = morph::detail::sum_mesh(pa, pb, std::move(copy));
  // Nothing merges here: each facet is a face, so the origins are taken.
  REQUIRE(kept.origins.size() == static_cast<std::size_t>(one.num_faces()));
  REQUIRE(taken.origins.size() == kept.origins.size());
  CHECK(differing_origins(taken.origins, kept.origins) == 0);
  CHECK(differing_origins(taken.origins, one.origins) == 0);
  REQUIRE(taken.mesh.n_vertices() == kept.mesh.n_vertices());
  REQUIRE(taken.mesh.n_faces() == kept.mesh.n_faces());
  int differing = 0;
  for (auto v : kept.mesh.vertices())
    differing += kept.mesh.point(v) != taken.mesh.point(Mesh::VertexHandle(v.idx()));
  CHECK(differing == 0);
}

// A (+) A: each facet normal of one map at a facet normal of the other (translated facets
// from overlays, no corner facets); the origins whichever path sum_mesh takes.
TEST_CASE("sum_mesh given its facets gives the same origins for A (+) A") {
  using morph::Mesh;
  const Mesh A = morph::make_icosphere(1.0, 2);
  const morph::detail::Polytope pa = morph::detail::make_operand(A, "A");
  const morph::detail::SumFacets facets =
      morph::detail::run_with_threads(1, [&] { return morph::detail::fims_facets(pa, pa); });
  const morph::LabelledMesh kept = morph::detail::sum_mesh(pa, pa, facets);
  morph::detail::SumFacets copy = facets;
  const morph::LabelledMesh taken = morph::detail::sum_mesh(pa, pa, std::move(copy));
  REQUIRE(taken.origins.size() == kept.origins.size());
  CHECK(differing_origins(taken.origins, kept.origins) == 0);
  CHECK(taken.mesh.n_faces() == kept.mesh.n_faces());
}

// A caller that caps TBB's threads with tbb::global_control: the operations' arenas keep to
// the cap (their sequential paths, not side-by-side ones with a single thread to run them),
// and the result is the one without a cap.
TEST_CASE("run_with_threads keeps to a tbb::global_control cap") {
  using morph::detail::run_with_threads;
  const auto concurrency = [] { return tbb::this_task_arena::max_concurrency(); };
  const int all = concurrency();
  const morph::Mesh A = morph::make_icosphere(1.0, 3);
  const morph::Mesh B = morph::make_icosphere(0.5, 2);
  const morph::LabelledMesh free_sum = morph::minkowski_sum(A, B);
  {
    const tbb::global_control cap(tbb::global_control::max_allowed_parallelism, 1);
    CHECK(run_with_threads(0, concurrency) == 1);
    CHECK(run_with_threads(4, concurrency) == 1);
    const morph::LabelledMesh capped = morph::minkowski_sum(A, B);
    REQUIRE(capped.mesh.n_vertices() == free_sum.mesh.n_vertices());
    REQUIRE(capped.mesh.n_faces() == free_sum.mesh.n_faces());
    int differing = 0;
    for (auto v : free_sum.mesh.vertices())
      differing += free_sum.mesh.point(v) != capped.mesh.point(v);
    CHECK(differing == 0);
    CHECK(differing_origins(capped.origins, free_sum.origins) == 0);
  }
  CHECK(run_with_threads(0, concurrency) == all);
  CHECK(run_with_threads(1, concurrency) == 1);
}
