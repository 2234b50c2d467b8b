// Dilation, erosion, opening and closing on the exact kernel. Chained operations pass
// exact polytopes from one step to the next and round once, at the end.
#include <morph/morphology.h>

#include "fims.h"
#include "halfspace_intersection.h"
#include "parallel.h"

namespace morph {

namespace {

using detail::Operands;
using detail::Polytope;

MorphResult empty_result(const detail::MaybePolytope& m) {
  MorphResult r;
  r.empty_reason = m.reason;
  r.message = m.message;
  return r;
}

MorphResult from_sum(const Polytope& a, const Polytope& b) {
  LabelledMesh s = detail::sum_mesh(a, b, detail::fims_facets(a, b));
  MorphResult r;
  r.mesh = std::move(s.mesh);  // a copy (OpenMesh has no move), a few microseconds
  r.origins = std::move(s.origins);
  return r;
}

/// The mesh of an erosion's result, each face labelled by origin_of(facet of `p`). `p`'s
/// corners are moved into the mesh (origin_of reads only its labels).
template <class OriginOf>
MorphResult from_rounded(detail::RoundedPolytope& p, const OriginOf& origin_of) {
  std::vector<int> source;
  // The mesh made in place: assigned, it was copied (OpenMesh has no move assignment).
  MorphResult r{
      .mesh = detail::clean_mesh(p.points, p.face_begin, std::move(p.corner_vertex), &source),
      .origins = {},
      .message = {}};
  r.origins.reserve(source.size());
  for (int f : source)
    r.origins.push_back(f >= 0 ? origin_of(f) : FacetOrigin{FacetKind::translated, {}, {}});
  return r;
}

/// An erosion's facet: a facet of A moved inwards by a vertex of B.
FacetOrigin erosion_origin(const detail::RoundedPolytope& p, int f) {
  return {FacetKind::translated,
          {Element::Kind::facet, p.face_source[f]},
          {Element::Kind::vertex, p.face_element[f]}};
}

// A final erosion is only written out: no exact polytope.
constexpr detail::IntersectOptions kFinal{.polytope = false};

}  // namespace

MorphResult dilate(const Mesh& A, const Mesh& B, const MorphologyOptions& options) {
  return detail::run_with_threads(options.threads, [&] {
    const Operands op = detail::make_operands(A, B);
    return from_sum(op.a, op.b);
  });
}

MorphResult erode(const Mesh& A, const Mesh& B, const MorphologyOptions& options) {
  return detail::run_with_threads(options.threads, [&] {
    const Operands op = detail::make_operands(A, B);
    detail::MaybePolytope e = detail::erode_polytope(op.a, op.b, kFinal);
    if (e.reason != EmptyReason::none) return empty_result(e);
    return from_rounded(e.rounded, [&](int f) { return erosion_origin(e.rounded, f); });
  });
}

MorphResult open(const Mesh& A, const Mesh& B, const MorphologyOptions& options) {
  return detail::run_with_threads(options.threads, [&] {
    const Operands op = detail::make_operands(A, B);
    const detail::MaybePolytope e = detail::erode_polytope(op.a, op.b);
    return e.polytope ? from_sum(*e.polytope, op.b) : empty_result(e);
  });
}

MorphResult close(const Mesh& A, const Mesh& B, const MorphologyOptions& options) {
  return detail::run_with_threads(options.threads, [&] {
    const Operands op = detail::make_operands(A, B);
    detail::Closing c = detail::close_polytope(op.a, op.b, kFinal);
    if (c.eroded.reason != EmptyReason::none) return empty_result(c.eroded);
    // Each facet lies on a facet of A (+) B (its half-space's source): labelled as that one.
    return from_rounded(c.eroded.rounded,
                        [&](int f) { return c.origins[c.eroded.rounded.face_source[f]]; });
  });
}

}  // namespace morph
