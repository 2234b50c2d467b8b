// Exact half-space intersection by duality: with a point o strictly inside, the
// half-space <n, x> <= d maps to the dual point n / (d - <n, o>); the facets of the
// intersection are the dual points that are vertices of their convex hull, and its
// vertices are the hull's facets. Coordinates stay exact rationals throughout.
#include "halfspace_intersection.h"

#include <morph/error.h>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/QP_functions.h>
#include <CGAL/QP_models.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <numeric>

#include "gauss_map.h"
#include "parallel.h"

namespace morph::detail {

namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using HullMesh = CGAL::Surface_mesh<Kernel::Point_3>;

Kernel::FT to_kernel(const Exact& q) { return Kernel::FT(mpq_class(q.mpq())); }

Exact abs_value(const Exact& x) { return x < 0 ? -x : x; }

/// Chebyshev-like centre for the L1 norm: maximise t subject to
/// <n_i, x> + |n_i|_1 t <= d_i, t <= 1. t* > 0: a solid (x* strictly inside);
/// t* = 0: flat; t* < 0: empty.
struct CentreResult {
  Exact t;
  V3<Exact> x;
};
CentreResult exact_centre(const std::vector<HalfSpace>& hs) {
  using Program = CGAL::Quadratic_program<Exact>;
  Program lp(CGAL::SMALLER, false, 0, false, 0);
  for (int i = 0; i < static_cast<int>(hs.size()); ++i) {
    const V3<Exact> n = to_rational(hs[i].normal);
    lp.set_a(0, i, n.x);
    lp.set_a(1, i, n.y);
    lp.set_a(2, i, n.z);
    lp.set_a(3, i, abs_value(n.x) + abs_value(n.y) + abs_value(n.z));
    lp.set_b(i, hs[i].offset);
  }
  lp.set_u(3, true, Exact(1));
  lp.set_c(3, Exact(-1));
  const auto solution = CGAL::solve_linear_program(lp, Exact());
  if (!solution.is_optimal()) throw error("internal error: the centre of an erosion could not be found");
  std::vector<Exact> value;
  for (auto it = solution.variable_values_begin(); it != solution.variable_values_end(); ++it)
    value.push_back(it->numerator() / it->denominator());
  return {value[3], {value[0], value[1], value[2]}};
}

/// o strictly inside every half-space? (interval filter, exact when undecided)
bool strictly_inside(const std::vector<HalfSpace>& hs, const V3<Exact>& o) {
  const V3<Interval> oi = to_interval(o);
  std::atomic<bool> inside = true;
  parallel_chunks(static_cast<int>(hs.size()), 512, [&](int begin, int end) {
    RoundingGuard guard;
    for (int i = begin; i < end && inside; ++i) {
      const V3<ExactN>& ne = hs[i].normal;
      const V3<Interval> n{Interval(ne.x.to_interval()), Interval(ne.y.to_interval()), Interval(ne.z.to_interval())};
      int s = interval_sign(Interval(CGAL::to_interval(hs[i].offset)) - dot(n, oi));
      if (s == 2) s = CGAL::sign(hs[i].offset - dot(to_rational(ne), o));
      if (s <= 0) inside = false;
    }
  });
  return inside;
}

}  // namespace

MaybePolytope intersect_halfspaces(const std::vector<HalfSpace>& hs, const V3<double>& hint) {
  MaybePolytope out;
  V3<Exact> o = to_exact(hint);
  if (!strictly_inside(hs, o)) {
    const CentreResult c = exact_centre(hs);
    if (c.t < 0) {
      out.reason = EmptyReason::empty;
      out.message = "the structuring element fits nowhere inside the mesh: the erosion is empty";
      return out;
    }
    if (c.t == 0) {
      out.reason = EmptyReason::flat;
      out.message = "the structuring element fits only on a plane, a segment or a point: the erosion has no interior";
      return out;
    }
    o = c.x;
  }
  // Dual points, exact; their hull with CGAL's exact kernel.
  const int n = static_cast<int>(hs.size());
  std::vector<V3<Exact>> dual(n);
  std::vector<Kernel::Point_3> points(n);
  std::map<Kernel::Point_3, int> index_of;
  for (int i = 0; i < n; ++i) {
    const V3<Exact> nr = to_rational(hs[i].normal);
    const Exact den = hs[i].offset - dot(nr, o);
    dual[i] = {nr.x / den, nr.y / den, nr.z / den};
    points[i] = Kernel::Point_3(to_kernel(dual[i].x), to_kernel(dual[i].y), to_kernel(dual[i].z));
    index_of.emplace(points[i], i);
  }
  HullMesh hull;
  CGAL::convex_hull_3(points.begin(), points.end(), hull);
  // Group coplanar adjacent hull triangles: each group is a vertex of the intersection.
  std::map<HullMesh::Face_index, int> group;
  std::vector<std::vector<HullMesh::Face_index>> groups;
  for (auto f : hull.faces()) {
    if (group.count(f)) continue;
    const int g = static_cast<int>(groups.size());
    groups.emplace_back();
    std::vector<HullMesh::Face_index> stack{f};
    group[f] = g;
    const auto h0 = hull.halfedge(f);
    const auto& p0 = hull.point(hull.source(h0));
    const auto& p1 = hull.point(hull.target(h0));
    const auto& p2 = hull.point(hull.target(hull.next(h0)));
    while (!stack.empty()) {
      const auto cur = stack.back();
      stack.pop_back();
      groups[g].push_back(cur);
      for (auto h : CGAL::halfedges_around_face(hull.halfedge(cur), hull)) {
        const auto nb = hull.face(hull.opposite(h));
        if (group.count(nb)) continue;
        const auto& q = hull.point(hull.target(hull.next(hull.opposite(h))));
        if (CGAL::coplanar(p0, p1, p2, q)) {
          group[nb] = g;
          stack.push_back(nb);
        }
      }
    }
  }
  // The vertex of each group: x = o + w with <w, y> = 1 on the group's plane.
  std::vector<V3<Exact>> vertex(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const auto h = hull.halfedge(groups[g][0]);
    const int i0 = index_of.at(hull.point(hull.source(h)));
    const int i1 = index_of.at(hull.point(hull.target(h)));
    const int i2 = index_of.at(hull.point(hull.target(hull.next(h))));
    const V3<Exact> nrm = cross(dual[i1] - dual[i0], dual[i2] - dual[i0]);
    const Exact k = dot(nrm, dual[i0]);
    vertex[g] = {o.x + nrm.x / k, o.y + nrm.y / k, o.z + nrm.z / k};
  }
  // Facets: dual hull vertices with at least three groups around them (others lie on a
  // hull edge or facet: their planes only touch the intersection).
  std::vector<std::vector<int>> faces;
  std::vector<int> face_source, face_halfspace;
  for (auto v : hull.vertices()) {
    std::vector<int> cyc;
    for (auto f : CGAL::faces_around_target(hull.halfedge(v), hull)) {
      const int g = group.at(f);
      if (cyc.empty() || cyc.back() != g) cyc.push_back(g);
    }
    while (cyc.size() > 1 && cyc.front() == cyc.back()) cyc.pop_back();
    if (cyc.size() < 3) continue;
    faces.push_back(std::move(cyc));
    face_halfspace.push_back(index_of.at(hull.point(v)));
    face_source.push_back(hs[face_halfspace.back()].source);
  }
  if (faces.empty()) throw error("internal error: an intersection of half-spaces has no facets");
  // Number vertices and facets canonically (CGAL's hull order depends on its internal
  // shuffling): a vertex by the sorted half-spaces through it, a facet by its half-space,
  // each cycle starting at its smallest vertex. The output then depends only on the input.
  {
    std::vector<std::vector<int>> key(groups.size());
    for (std::size_t g = 0; g < groups.size(); ++g) {
      for (auto f : groups[g])
        for (auto v : CGAL::vertices_around_face(hull.halfedge(f), hull)) key[g].push_back(index_of.at(hull.point(v)));
      std::sort(key[g].begin(), key[g].end());
      key[g].erase(std::unique(key[g].begin(), key[g].end()), key[g].end());
    }
    std::vector<int> order(groups.size()), rank(groups.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
    std::vector<V3<Exact>> sorted_vertex(groups.size());
    for (std::size_t r = 0; r < order.size(); ++r) {
      rank[order[r]] = static_cast<int>(r);
      sorted_vertex[r] = vertex[order[r]];
    }
    vertex = std::move(sorted_vertex);
    std::vector<int> forder(faces.size());
    std::iota(forder.begin(), forder.end(), 0);
    std::sort(forder.begin(), forder.end(), [&](int a, int b) { return face_halfspace[a] < face_halfspace[b]; });
    std::vector<std::vector<int>> sorted_faces;
    std::vector<int> sorted_source, sorted_halfspace;
    for (int f : forder) {
      auto cyc = faces[f];
      for (int& g : cyc) g = rank[g];
      std::rotate(cyc.begin(), std::min_element(cyc.begin(), cyc.end()), cyc.end());
      sorted_faces.push_back(std::move(cyc));
      sorted_source.push_back(face_source[f]);
      sorted_halfspace.push_back(face_halfspace[f]);
    }
    faces = std::move(sorted_faces);
    face_source = std::move(sorted_source);
    face_halfspace = std::move(sorted_halfspace);
  }
  // Circulating around a hull vertex may run clockwise: orient by the first facet.
  {
    const auto& cyc = faces[0];
    const V3<Exact> nw = newell_normal<Exact>(static_cast<int>(cyc.size()),
                                              [&](int i) -> const V3<Exact>& { return vertex[cyc[i]]; });
    if (CGAL::sign(dot(nw, to_rational(hs[face_halfspace[0]].normal))) < 0)
      for (auto& c : faces) std::reverse(c.begin(), c.end());
  }
  std::vector<V3<double>> rounded(vertex.size());
  for (std::size_t v = 0; v < vertex.size(); ++v)
    rounded[v] = {round_to_nearest(vertex[v].x), round_to_nearest(vertex[v].y), round_to_nearest(vertex[v].z)};
  std::vector<V3<ExactN>> normals(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) normals[f] = hs[face_halfspace[f]].normal;
  Polytope p = make_polytope(std::move(rounded), std::move(vertex), faces, std::move(normals), "A (-) B");
  for (auto& s : p.face_source) s = face_source[s];
  out.polytope = std::move(p);
  return out;
}

MaybePolytope erode_polytope(const Polytope& A, const Polytope& B) {
  const std::vector<Location> loc = locate_all(A, B);
  const int nf = A.num_faces();
  std::vector<HalfSpace> hs(nf);
  parallel_chunks(nf, 64, [&](int begin, int end) {
    for (int f = begin; f < end; ++f) {
      const V3<Exact> n = to_rational(A.exact_normal(f));
      Exact offset = dot(n, A.exact_point(A.corner(f, 0)));
      for (int k = 1; k < A.degree(f); ++k) offset = std::max(offset, dot(n, A.exact_point(A.corner(f, k))));
      hs[f] = {A.exact_normal(f), offset - dot(n, B.exact_point(location_vertex(B, loc[f]))), A.face_source[f]};
    }
  });
  // A point usually inside: A's vertex centroid minus B's.
  V3<double> ca{0, 0, 0}, cb{0, 0, 0};
  for (const auto& p : A.points) ca = ca + p;
  for (const auto& p : B.points) cb = cb + p;
  const double ka = 1.0 / A.num_vertices(), kb = 1.0 / B.num_vertices();
  return intersect_halfspaces(hs, {ca.x * ka - cb.x * kb, ca.y * ka - cb.y * kb, ca.z * ka - cb.z * kb});
}

}  // namespace morph::detail
