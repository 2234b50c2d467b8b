// Dilation, erosion, opening and closing on the exact kernel. Chained operations pass
// exact polytopes from one step to the next and round once, at the end.
#include <morph/morphology.h>

#include "fims.h"
#include "halfspace_intersection.h"
#include "parallel.h"

namespace morph {

namespace {

using detail::Polytope;

using detail::Operands;

Operands prepare(const Mesh& A, const Mesh& B) { return detail::make_operands(A, B); }

MorphResult empty_result(const detail::MaybePolytope& m) {
  MorphResult r;
  r.empty_reason = m.reason;
  r.message = m.message;
  return r;
}

MorphResult from_sum(const Polytope& a, const Polytope& b) {
  LabelledMesh s = detail::sum_mesh(a, b, detail::fims_facets(a, b));
  MorphResult r;
  r.mesh = std::move(s.mesh);
  r.origins = std::move(s.origins);
  return r;
}

MorphResult from_rounded(const detail::RoundedPolytope& p) {
  MorphResult r;
  r.mesh = detail::clean_mesh(p.points, p.face_begin, p.corner_vertex, nullptr);
  return r;
}

// A final erosion is only written out: no exact polytope.
constexpr detail::IntersectOptions kFinal{.polytope = false};

}  // namespace

MorphResult dilate(const Mesh& A, const Mesh& B, const MorphologyOptions& options) {
  return detail::run_with_threads(options.threads, [&] {
    const Operands op = prepare(A, B);
    return from_sum(op.a, op.b);
  });
}

MorphResult erode(const Mesh& A, const Mesh& B, const MorphologyOptions& options) {
  return detail::run_with_threads(options.threads, [&] {
    const Operands op = prepare(A, B);
    const detail::MaybePolytope e = detail::erode_polytope(op.a, op.b, kFinal);
    return e.reason == EmptyReason::none ? from_rounded(e.rounded) : empty_result(e);
  });
}

MorphResult open(const Mesh& A, const Mesh& B, const MorphologyOptions& options) {
  return detail::run_with_threads(options.threads, [&] {
    const Operands op = prepare(A, B);
    const detail::MaybePolytope e = detail::erode_polytope(op.a, op.b);
    return e.polytope ? from_sum(*e.polytope, op.b) : empty_result(e);
  });
}

MorphResult close(const Mesh& A, const Mesh& B, const MorphologyOptions& options) {
  return detail::run_with_threads(options.threads, [&] {
    const Operands op = prepare(A, B);
    const Polytope s = detail::sum_polytope(op.a, op.b, detail::fims_facets(op.a, op.b));
    const detail::MaybePolytope e = detail::erode_polytope(s, op.b, kFinal);
    return e.reason == EmptyReason::none ? from_rounded(e.rounded) : empty_result(e);
  });
}

}  // namespace morph
