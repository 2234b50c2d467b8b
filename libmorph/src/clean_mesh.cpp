// The last step of every operation: from an exact result (facet cycles over rounded
// points) to a clean mesh, merging features below double precision.
#include <morph/error.h>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <tuple>

#include "fims.h"

namespace morph::detail {

namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using HullMesh = CGAL::Surface_mesh<Kernel::Point_3>;

/// Builds `mesh` from the facet cycles over clusters; false (mesh untouched) when they no
/// longer describe a closed manifold, and the hull route must be taken.
bool build_direct(const std::vector<V3<double>>& points, const std::vector<int>& face_begin,
                  const std::vector<int>& corners, const std::vector<int>& rep, Mesh& mesh,
                  std::vector<int>* source) {
  const int n = static_cast<int>(points.size());
  const int nf = static_cast<int>(face_begin.size()) - 1;
  std::vector<std::vector<int>> faces(nf);
  std::vector<char> used(n, 0);
  std::set<std::pair<int, int>> directed;
  for (int f = 0; f < nf; ++f) {
    auto& cyc = faces[f];
    for (int c = face_begin[f]; c < face_begin[f + 1]; ++c) {
      const int v = rep[corners[c]];
      if (cyc.empty() || cyc.back() != v) cyc.push_back(v);
    }
    while (cyc.size() > 1 && cyc.front() == cyc.back()) cyc.pop_back();
    std::vector<int> sorted = cyc;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return false;
    if (cyc.size() < 3) {
      if (cyc.size() == 2) return false;  // a facet collapsed onto an edge: glue by hull
      cyc.clear();
      continue;
    }
    for (std::size_t k = 0; k < cyc.size(); ++k) {
      if (!directed.emplace(cyc[k], cyc[(k + 1) % cyc.size()]).second) return false;
      used[cyc[k]] = 1;
    }
  }
  for (const auto& [u, w] : directed)
    if (!directed.count({w, u})) return false;
  std::vector<Mesh::VertexHandle> handle(n);
  Mesh m;
  for (int v = 0; v < n; ++v)
    if (used[v]) handle[v] = m.add_vertex(Point(points[v].x, points[v].y, points[v].z));
  std::vector<Mesh::VertexHandle> fh;
  std::vector<int> src;
  for (int f = 0; f < nf; ++f) {
    if (faces[f].empty()) continue;
    fh.clear();
    for (int v : faces[f]) fh.push_back(handle[v]);
    if (!m.add_face(fh).is_valid()) return false;
    src.push_back(f);
  }
  mesh = std::move(m);
  if (source) *source = std::move(src);
  return true;
}

/// The exact convex hull of the cluster points, its triangles grouped into the facets
/// their corners came from.
Mesh build_by_hull(const std::vector<V3<double>>& points, const std::vector<int>& face_begin,
                   const std::vector<int>& corners, const std::vector<int>& rep, std::vector<int>* source) {
  const int nf = static_cast<int>(face_begin.size()) - 1;
  std::map<int, std::vector<int>> facets_of;  // cluster -> facets that had a corner in it
  for (int f = 0; f < nf; ++f)
    for (int c = face_begin[f]; c < face_begin[f + 1]; ++c) facets_of[rep[corners[c]]].push_back(f);
  std::vector<Kernel::Point_3> pts;
  std::map<Kernel::Point_3, int> cluster_of;
  for (auto& [cl, fs] : facets_of) {
    std::sort(fs.begin(), fs.end());
    fs.erase(std::unique(fs.begin(), fs.end()), fs.end());
    const auto& p = points[cl];
    pts.emplace_back(p.x, p.y, p.z);
    cluster_of.emplace(pts.back(), cl);
  }
  HullMesh hull;
  CGAL::convex_hull_3(pts.begin(), pts.end(), hull);
  // Unit normals of the result's facets (from their rounded corners).
  std::vector<V3<double>> facet_normal(nf);
  for (int f = 0; f < nf; ++f) {
    V3<double> sum{0, 0, 0};
    for (int c = face_begin[f]; c < face_begin[f + 1]; ++c) {
      const auto& p = points[corners[c]];
      const auto& q = points[corners[c + 1 == face_begin[f + 1] ? face_begin[f] : c + 1]];
      sum = sum + cross(p, q);
    }
    const double len = std::sqrt(dot(sum, sum));
    facet_normal[f] = len > 0 ? V3<double>{sum.x / len, sum.y / len, sum.z / len} : sum;
  }
  // Facet of each hull triangle: among the facets its corners came from (those shared by
  // all three when there are any), the one whose normal is closest to the triangle's.
  std::map<HullMesh::Face_index, int> facet;
  int next_own = nf;
  for (auto t : hull.faces()) {
    std::vector<int> cl;
    for (auto v : CGAL::vertices_around_face(hull.halfedge(t), hull)) cl.push_back(cluster_of.at(hull.point(v)));
    std::vector<int> common = facets_of.at(cl[0]), all = common;
    for (std::size_t k = 1; k < cl.size(); ++k) {
      const auto& fs = facets_of.at(cl[k]);
      std::vector<int> keep;
      std::set_intersection(common.begin(), common.end(), fs.begin(), fs.end(), std::back_inserter(keep));
      common = std::move(keep);
      all.insert(all.end(), fs.begin(), fs.end());
    }
    const std::vector<int>& candidates = common.empty() ? all : common;
    const V3<double> tn = cross(points[cl[1]] - points[cl[0]], points[cl[2]] - points[cl[0]]);
    int best = -1;
    double best_dot = -2;
    for (int f : candidates) {
      const double d = dot(tn, facet_normal[f]);
      if (d > best_dot || (d == best_dot && f < best)) {
        best_dot = d;
        best = f;
      }
    }
    facet[t] = best >= 0 ? best : next_own++;
  }
  // Boundary cycle of each group; a group that is not one disc keeps its triangles.
  std::map<int, std::vector<HullMesh::Face_index>> groups;
  for (auto t : hull.faces()) groups[facet[t]].push_back(t);
  // CGAL's hull keys internal maps by pointer, so its order is not reproducible: everything
  // below is ordered by cluster index instead (vertices, cycle starts, loose triangles).
  Mesh mesh;
  std::map<int, Mesh::VertexHandle> handle;
  auto vertex = [&](HullMesh::Vertex_index v) { return handle.at(cluster_of.at(hull.point(v))); };
  auto cluster = [&](HullMesh::Vertex_index v) { return cluster_of.at(hull.point(v)); };
  std::vector<std::pair<std::vector<HullMesh::Vertex_index>, int>> out_faces;
  for (auto& [g, tris] : groups) {
    std::map<HullMesh::Vertex_index, HullMesh::Vertex_index> next;
    bool disc = true;
    for (auto t : tris)
      for (auto h : CGAL::halfedges_around_face(hull.halfedge(t), hull))
        if (facet[hull.face(hull.opposite(h))] != g)
          disc = disc && next.emplace(hull.source(h), hull.target(h)).second;
    std::vector<HullMesh::Vertex_index> cyc;
    if (disc && !next.empty()) {
      auto start = next.begin()->first;
      for (const auto& [v, w] : next)
        if (cluster(v) < cluster(start)) start = v;
      auto v = start;
      do {
        cyc.push_back(v);
        v = next.at(v);
      } while (v != start && cyc.size() <= next.size());
      disc = cyc.size() == next.size();
    }
    const int src = g < nf ? g : -1;
    if (disc) {
      out_faces.emplace_back(std::move(cyc), src);
    } else {
      std::vector<std::vector<HullMesh::Vertex_index>> loose;
      for (auto t : tris) {
        std::vector<HullMesh::Vertex_index> tri;
        for (auto v : CGAL::vertices_around_face(hull.halfedge(t), hull)) tri.push_back(v);
        std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end(), [&](auto a, auto b) {
                      return cluster(a) < cluster(b);
                    }), tri.end());
        loose.push_back(std::move(tri));
      }
      std::sort(loose.begin(), loose.end(), [&](const auto& a, const auto& b) {
        return std::make_tuple(cluster(a[0]), cluster(a[1]), cluster(a[2])) <
               std::make_tuple(cluster(b[0]), cluster(b[1]), cluster(b[2]));
      });
      for (auto& tri : loose) out_faces.emplace_back(std::move(tri), src);
    }
  }
  for (const auto& f : out_faces)
    for (auto v : f.first) handle[cluster(v)];
  for (auto& [cl, h] : handle) h = mesh.add_vertex(Point(points[cl].x, points[cl].y, points[cl].z));
  std::vector<int> src;
  std::vector<Mesh::VertexHandle> fh;
  for (auto& [cyc, s] : out_faces) {
    fh.clear();
    for (auto v : cyc) fh.push_back(vertex(v));
    if (!mesh.add_face(fh).is_valid())
      throw error("internal error: the hull of a result could not be joined into a mesh");
    src.push_back(s);
  }
  if (source) *source = std::move(src);
  return mesh;
}

}  // namespace

Mesh clean_mesh(const std::vector<V3<double>>& points, const std::vector<int>& face_begin,
                const std::vector<int>& corners, std::vector<int>* source) {
  constexpr int kPairwiseDegree = 16;  // facets up to this degree are checked corner by corner
  const int n = static_cast<int>(points.size());
  const int nf = static_cast<int>(face_begin.size()) - 1;
  V3<double> lo{0, 0, 0}, hi{0, 0, 0};
  if (n > 0) lo = hi = points[0];
  for (const auto& p : points) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const V3<double> span = hi - lo;
  const double limit = kFeatureTolerance * std::sqrt(dot(span, span));
  std::vector<int> rep(n);
  std::iota(rep.begin(), rep.end(), 0);
  auto find = [&](int x) {
    while (rep[x] != x) x = rep[x] = rep[rep[x]];
    return x;
  };
  bool merged = false;
  auto merge_if_close = [&](int u, int w) {
    const V3<double> d = points[u] - points[w];
    if (std::sqrt(dot(d, d)) <= limit) {
      const int a = find(u), b = find(w);
      if (a != b) {
        rep[std::max(a, b)] = std::min(a, b);
        merged = true;
      }
    }
  };
  for (int f = 0; f < nf; ++f) {
    const int b = face_begin[f], e = face_begin[f + 1];
    if (e - b <= kPairwiseDegree) {  // also across a facet: the diagonal of a thin parallelogram
      for (int c = b; c < e; ++c)
        for (int d = c + 1; d < e; ++d) merge_if_close(corners[c], corners[d]);
    } else {
      for (int c = b; c < e; ++c) merge_if_close(corners[c], corners[c + 1 == e ? b : c + 1]);
    }
  }
  for (int v = 0; v < n; ++v) rep[v] = find(v);
  Mesh mesh;
  if (build_direct(points, face_begin, corners, rep, mesh, source)) {
    if (!merged) return mesh;
    // Merged: check that every facet still turns convexly; else rebuild by hull.
    bool convex = true;
    for (auto f : mesh.faces()) {
      const auto nrm = mesh.calc_face_normal(f);
      double longest = 0;
      for (auto h : mesh.fh_range(f)) longest = std::max(longest, mesh.calc_edge_length(h));
      OpenMesh::Vec3d twice_area(0, 0, 0);
      for (auto h : mesh.fh_range(f))
        twice_area += OpenMesh::cross(mesh.point(mesh.from_vertex_handle(h)), mesh.point(mesh.to_vertex_handle(h)));
      if (twice_area.norm() <= 2 * limit * longest) convex = false;  // thinner than the feature size
      for (auto h : mesh.fh_range(f)) {
        const auto a = mesh.point(mesh.from_vertex_handle(h)), b = mesh.point(mesh.to_vertex_handle(h)),
                   c = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
        if (OpenMesh::dot(OpenMesh::cross(b - a, c - b), nrm) <= 0) convex = false;
      }
    }
    if (convex) return mesh;
  }
  return build_by_hull(points, face_begin, corners, rep, source);
}

}  // namespace morph::detail
