// The FIMS kernel: translated, corner and edge facets of A (+) B from the overlay of
// the two Gauss maps, every decision exact (see gauss_map.h and docs/algorithm.md).
#include "fims.h"

#include <morph/error.h>

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "gauss_map.h"
#include "parallel.h"

namespace morph::detail {

namespace {

constexpr int kGrain = 256;

Element element_of(const Polytope& P, const Location& loc) {
  switch (loc.kind) {
    case Location::Kind::vertex:
      return {Element::Kind::vertex, P.vertex_source[loc.index]};
    case Location::Kind::edge:
      return {Element::Kind::edge, P.edge_source[loc.index]};
    case Location::Kind::face:
      return {Element::Kind::facet, P.face_source[loc.index]};
  }
  return {};
}

/// A facet under construction.
struct Facet {
  std::vector<std::pair<int, int>> corners;
  FacetOrigin origin;
};

/// The facet of A (+) B whose normal is the normal of facet f of X (X is A when
/// x_is_a), located at `loc` in Y's Gauss map.
void facet_at_normal(const Polytope& X, int f, const Polytope& Y, const Location& loc, bool x_is_a,
                     std::vector<Arc>& x_arcs, std::vector<Arc>& y_arcs, Facet& out) {
  arcs_around(X, {Location::Kind::face, f}, x_arcs);
  arcs_around(Y, loc, y_arcs);
  out.corners.clear();
  overlay_regions(NormalRef{&X, f}, x_arcs, y_arcs, loc.index, out.corners);
  if (!x_is_a)
    for (auto& c : out.corners) std::swap(c.first, c.second);
  const Element ex{Element::Kind::facet, X.face_source[f]};
  const Element ey = element_of(Y, loc);
  out.origin = x_is_a ? FacetOrigin{FacetKind::translated, ex, ey} : FacetOrigin{FacetKind::corner, ey, ex};
}

struct Crossing {
  int edge_b;
  int side;
};

/// The edges of B whose arcs cross the arc of edge a of A, by a breadth-first walk over
/// the regions of B that the arc touches, starting where the arc starts.
void edge_crossings(const Polytope& A, int a, const Polytope& B, const Location& start,
                    std::vector<int>& region_stamp, std::vector<int>& edge_stamp, std::vector<int>& queue,
                    std::vector<Crossing>& out) {
  const auto& ea = A.edges[a];
  const NormalRef n1{&A, ea.left}, n2{&A, ea.right};
  const int stamp = a + 1;
  queue.clear();
  auto visit = [&](int v) {
    if (region_stamp[v] != stamp) {
      region_stamp[v] = stamp;
      queue.push_back(v);
    }
  };
  switch (start.kind) {
    case Location::Kind::vertex:
      visit(start.index);
      break;
    case Location::Kind::edge:
      visit(B.edges[start.index].from);
      visit(B.edges[start.index].to);
      break;
    case Location::Kind::face:
      for (int k = 0; k < B.degree(start.index); ++k) visit(B.corner(start.index, k));
      break;
  }
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const int v = queue[q];
    for (int s = B.fan_begin[v]; s < B.fan_begin[v + 1]; ++s) {
      const int e = B.fan_edge[s];
      if (edge_stamp[e] == stamp) continue;
      edge_stamp[e] = stamp;
      const auto& eb = B.edges[e];
      const ArcContact c = arc_contact(n1, n2, NormalRef{&B, eb.left}, NormalRef{&B, eb.right});
      if (c.crosses) out.push_back({e, c.side});
      if (c.touches) visit(B.fan_vertex[s]);
    }
  }
  std::sort(out.begin(), out.end(), [](const Crossing& x, const Crossing& y) { return x.edge_b < y.edge_b; });
}

/// The parallelogram a (+) b, counter-clockwise about its outward normal.
void edge_facet(const Polytope& A, int a, const Polytope& B, const Crossing& c, Facet& out) {
  const auto& ea = A.edges[a];
  const auto& eb = B.edges[c.edge_b];
  const int ua = ea.from, wa = ea.to, ub = eb.from, wb = eb.to;
  if (c.side > 0)
    out.corners = {{wa, ub}, {wa, wb}, {ua, wb}, {ua, ub}};
  else
    out.corners = {{wa, wb}, {wa, ub}, {ua, ub}, {ua, wb}};
  out.origin = {FacetKind::edge, {Element::Kind::edge, A.edge_source[a]}, {Element::Kind::edge, B.edge_source[c.edge_b]}};
}

void append(SumFacets& out, const Facet& f) {
  for (const auto& c : f.corners) out.corners.push_back(pair_key(c.first, c.second));
  out.face_begin.push_back(static_cast<int>(out.corners.size()));
  out.origins.push_back(f.origin);
}

}  // namespace

SumFacets fims_facets(const Polytope& A, const Polytope& B) {
  const std::vector<Location> loc_a = locate_all(A, B);  // contributing vertices of A's facets
  const std::vector<Location> loc_b = locate_all(B, A);  // where B's facets sit on A

  // Translated facets: one per facet of A.
  std::vector<Facet> translated(A.num_faces());
  parallel_chunks(A.num_faces(), kGrain, [&](int begin, int end) {
    RoundingGuard guard;
    std::vector<Arc> xa, ya;
    for (int f = begin; f < end; ++f) facet_at_normal(A, f, B, loc_a[f], true, xa, ya, translated[f]);
  });
  // Corner facets: one per facet of B whose normal is not also a facet normal of A.
  std::vector<Facet> corner(B.num_faces());
  parallel_chunks(B.num_faces(), kGrain, [&](int begin, int end) {
    RoundingGuard guard;
    std::vector<Arc> xa, ya;
    for (int g = begin; g < end; ++g)
      if (loc_b[g].kind != Location::Kind::face) facet_at_normal(B, g, A, loc_b[g], false, xa, ya, corner[g]);
  });
  // Edge facets: for every edge of A whose two facets have different contributing
  // vertices, the edges of B whose arcs its arc crosses.
  std::vector<std::vector<Crossing>> crossings(A.num_edges());
  struct Scratch {
    std::vector<int> region_stamp, edge_stamp, queue;
  };
  tbb::enumerable_thread_specific<Scratch> scratch([&] {
    return Scratch{std::vector<int>(B.num_vertices(), 0), std::vector<int>(B.num_edges(), 0), {}};
  });
  parallel_chunks(A.num_edges(), kGrain, [&](int begin, int end) {
    RoundingGuard guard;
    Scratch& s = scratch.local();
    for (int a = begin; a < end; ++a) {
      const auto& l = loc_a[A.edges[a].left];
      const auto& r = loc_a[A.edges[a].right];
      if (l.kind == Location::Kind::vertex && r.kind == Location::Kind::vertex && l.index == r.index) continue;
      edge_crossings(A, a, B, l, s.region_stamp, s.edge_stamp, s.queue, crossings[a]);
    }
  });

  SumFacets out;
  for (const auto& f : translated) append(out, f);
  for (int g = 0; g < B.num_faces(); ++g)
    if (loc_b[g].kind != Location::Kind::face) append(out, corner[g]);
  Facet ef;
  for (int a = 0; a < A.num_edges(); ++a)
    for (const auto& c : crossings[a]) {
      edge_facet(A, a, B, c, ef);
      append(out, ef);
    }
  return out;
}

namespace {

/// The distinct vertex pairs of the facets, sorted, and each corner's index among them.
/// Linear in the number of corners: a counting sort buckets the corners by their vertex
/// of A, and in each bucket only the few distinct partners in B are sorted.
void index_vertices(const SumFacets& facets, int num_a, int num_b, std::vector<std::uint64_t>& pairs,
                    std::vector<int>& corners) {
  const int nc = static_cast<int>(facets.corners.size());
  // first[i]..first[i + 1]: the corners at vertex i of A, in `by_a`.
  std::vector<int> first(num_a + 1, 0), by_a(nc);
  for (const std::uint64_t key : facets.corners) ++first[pair_first(key)];
  std::partial_sum(first.begin(), first.end(), first.begin());  // first[i]: end of bucket i
  for (int c = nc - 1; c >= 0; --c) by_a[--first[pair_first(facets.corners[c])]] = c;
  std::vector<int> slot(num_b, -1);  // pair index of (i, j) while bucket i is numbered
  std::vector<int> partners;
  pairs.clear();
  corners.resize(nc);
  for (int i = 0; i < num_a; ++i) {
    partners.clear();
    for (int k = first[i]; k < first[i + 1]; ++k) {
      const int j = pair_second(facets.corners[by_a[k]]);
      if (slot[j] < 0) {
        slot[j] = 0;
        partners.push_back(j);
      }
    }
    std::sort(partners.begin(), partners.end());
    for (const int j : partners) {
      slot[j] = static_cast<int>(pairs.size());
      pairs.push_back(pair_key(i, j));
    }
    for (int k = first[i]; k < first[i + 1]; ++k) corners[by_a[k]] = slot[pair_second(facets.corners[by_a[k]])];
    for (const int j : partners) slot[j] = -1;
  }
}

}  // namespace

LabelledMesh sum_mesh(const Polytope& A, const Polytope& B, const SumFacets& facets) {
  std::vector<std::uint64_t> pairs;
  std::vector<int> corners;
  index_vertices(facets, A.num_vertices(), B.num_vertices(), pairs, corners);
  std::vector<V3<double>> points(pairs.size());
  const bool exact = !A.exact_points.empty() || !B.exact_points.empty();
  parallel_chunks(static_cast<int>(pairs.size()), 1024, [&](int begin, int end) {
    for (int v = begin; v < end; ++v) {
      const int i = pair_first(pairs[v]), j = pair_second(pairs[v]);
      if (!exact) {  // one correctly rounded addition per coordinate
        const auto& a = A.points[i];
        const auto& b = B.points[j];
        points[v] = {a.x + b.x, a.y + b.y, a.z + b.z};
      } else {
        const V3<Exact> s = A.exact_point(i) + B.exact_point(j);
        points[v] = {round_to_nearest(s.x), round_to_nearest(s.y), round_to_nearest(s.z)};
      }
    }
  });
  std::vector<int> source;
  // Initialised in place: OpenMesh meshes have no move assignment, only a deep copy.
  LabelledMesh out{clean_mesh(points, facets.face_begin, corners, &source), {}};
  // A face with no source (a triangle of the hull fallback that no facet owns) has no origin.
  out.origins.reserve(source.size());
  for (int f : source) out.origins.push_back(f >= 0 ? facets.origins[f] : FacetOrigin{FacetKind::edge, {}, {}});
  return out;
}

Polytope sum_polytope(const Polytope& A, const Polytope& B, const SumFacets& facets) {
  std::vector<std::uint64_t> pairs;
  std::vector<int> corners;
  index_vertices(facets, A.num_vertices(), B.num_vertices(), pairs, corners);
  std::vector<V3<double>> points(pairs.size());
  std::vector<V3<Exact>> exact(pairs.size());
  for (std::size_t v = 0; v < pairs.size(); ++v) {
    exact[v] = A.exact_point(pair_first(pairs[v])) + B.exact_point(pair_second(pairs[v]));
    points[v] = {round_to_nearest(exact[v].x), round_to_nearest(exact[v].y), round_to_nearest(exact[v].z)};
  }
  if (!A.exact_points.empty() || !B.exact_points.empty())
    throw error("internal error: an exact sum needs operands with double points");
  std::vector<std::vector<int>> faces(facets.num_faces());
  std::vector<V3<ExactN>> normals(facets.num_faces());
  std::vector<V3<ExactN>> cycle;
  for (int f = 0; f < facets.num_faces(); ++f) {
    faces[f].assign(corners.begin() + facets.face_begin[f], corners.begin() + facets.face_begin[f + 1]);
    cycle.clear();
    for (int c = facets.face_begin[f]; c < facets.face_begin[f + 1]; ++c)
      cycle.push_back(to_exact_n(A.points[pair_first(facets.corners[c])]) +
                      to_exact_n(B.points[pair_second(facets.corners[c])]));
    normals[f] = newell_normal<ExactN>(static_cast<int>(cycle.size()),
                                       [&](int i) -> const V3<ExactN>& { return cycle[i]; });
  }
  return make_polytope(std::move(points), std::move(exact), faces, std::move(normals), "A (+) B");
}

}  // namespace morph::detail

namespace morph {

LabelledMesh minkowski_sum(const Mesh& A, const Mesh& B, const MinkowskiOptions& options) {
  return detail::run_with_threads(options.threads, [&] {
    const detail::Polytope pa = detail::make_operand(A, "A");
    const detail::Polytope pb = detail::make_operand(B, "B");
    return detail::sum_mesh(pa, pb, detail::fims_facets(pa, pb));
  });
}

}  // namespace morph
