// The operand checks of validate.h: topology (closed, 2-manifold, connected, genus 0),
// non-degenerate faces, outward orientation, planarity and edge convexity.
//
// Every check is one pass over the mesh (plus, for convexity, one pass over the
// vertices of the two faces of each edge), so validating a 300k-facet mesh costs a few
// tens of milliseconds. Messages name the first offending element by its index.
#include <morph/error.h>
#include <morph/validate.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "validate_detail.h"

namespace morph {
namespace {

// A mesh whose signed volume is below this fraction of the sum of the absolute
// volumes of its fan tetrahedra is flat: the tetrahedra cancel out up to rounding
// (a convex body measured from an interior point has no cancellation at all, ratio 1).
constexpr double kFlatVolumeRatio = 1e-12;

// A face whose Newell normal (twice its area) is below this fraction of D^2 has zero
// area up to rounding: exactly collinear points computed in double give ~1e-16 D^2.
constexpr double kZeroAreaRatio = 1e-14;

enum class Verdict { ok, invalid, inverted, not_convex };

struct Finding {
  Verdict verdict = Verdict::ok;
  std::string problem;
  double volume = 0;  // set when the orientation check ran
};

Finding fail(Verdict verdict, std::string problem) { return {verdict, std::move(problem), 0}; }

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2g", value);
  return buffer;
}

std::string vertex_pair(const Mesh& mesh, Mesh::EdgeHandle edge) {
  const auto h = mesh.halfedge_handle(edge, 0);
  return std::to_string(mesh.from_vertex_handle(h).idx()) + "-" +
         std::to_string(mesh.to_vertex_handle(h).idx());
}

// Diagonal of the axis-aligned bounding box of the (non-deleted) vertices, and its centre.
struct Extent {
  double diagonal = 0;
  Point centre{0, 0, 0};
};

Extent bounding_box(const Mesh& mesh) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Point lo(inf, inf, inf), hi(-inf, -inf, -inf);
  bool any = false;
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
    any = true;
  }
  if (!any) return {};
  return {(hi - lo).norm(), (lo + hi) * 0.5};
}

// ---------------------------------------------------------------- topology

// Plain union-find over vertex indices, for connectivity.
struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

Finding closed_manifold(const Mesh& mesh) {
  std::size_t n_vertices = 0, n_edges = 0, n_faces = 0;
  for (auto f : mesh.faces()) {
    (void)f;
    ++n_faces;
  }
  if (n_faces == 0) return fail(Verdict::invalid, "the mesh is empty (it has no faces)");

  for (auto e : mesh.edges()) {
    ++n_edges;
    if (mesh.is_boundary(e))
      return fail(Verdict::invalid, "edge " + std::to_string(e.idx()) + " (vertices " +
                                        vertex_pair(mesh, e) +
                                        ") has only one face: the mesh is not closed");
  }

  // A vertex is manifold when the faces around it form one fan: the circulator around
  // it (which walks one fan) must meet every halfedge leaving it, and reach each
  // neighbour once (two edges between the same vertices pinch the surface).
  std::vector<int> outgoing(mesh.n_vertices(), 0);
  for (auto h : mesh.halfedges()) ++outgoing[mesh.from_vertex_handle(h).idx()];
  // seen[w] == v: w was already reached from v (a stamp, so the array is never cleared).
  std::vector<int> seen(mesh.n_vertices(), -1);
  for (auto v : mesh.vertices()) {
    ++n_vertices;
    if (outgoing[v.idx()] == 0)
      return fail(Verdict::invalid,
                  "vertex " + std::to_string(v.idx()) + " is isolated (it belongs to no face)");
    int reached = 0;
    bool pinched = false;
    // The outgoing halfedges around v, as the circulator walks them.
    const auto first = mesh.halfedge_handle(v);
    auto h = first;
    do {
      const int w = mesh.to_vertex_handle(h).idx();
      pinched = pinched || seen[w] == v.idx();
      seen[w] = v.idx();
      if (++reached > outgoing[v.idx()]) break;  // corrupt links
      h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));
    } while (h != first);
    if (reached != outgoing[v.idx()])
      return fail(Verdict::invalid, "vertex " + std::to_string(v.idx()) +
                                        " is not manifold: its faces form more than one fan");
    if (pinched) {
      // Name the smallest neighbour reached twice.
      std::vector<int> neighbours;
      for (auto h : mesh.voh_range(v)) neighbours.push_back(mesh.to_vertex_handle(h).idx());
      std::sort(neighbours.begin(), neighbours.end());
      const auto twice = std::adjacent_find(neighbours.begin(), neighbours.end());
      return fail(Verdict::invalid, "vertices " + std::to_string(v.idx()) + " and " +
                                        std::to_string(*twice) +
                                        " are joined by two edges: the mesh is not 2-manifold");
    }
  }

  DisjointSets components(mesh.n_vertices());
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    components.unite(mesh.from_vertex_handle(h).idx(), mesh.to_vertex_handle(h).idx());
  }
  int first = -1;
  for (auto v : mesh.vertices()) {
    if (first < 0) {
      first = v.idx();
    } else if (components.find(v.idx()) != components.find(first)) {
      return fail(Verdict::invalid, "the mesh is not connected: vertex " + std::to_string(v.idx()) +
                                        " is not connected to vertex " + std::to_string(first));
    }
  }

  const long long euler = static_cast<long long>(n_vertices) - static_cast<long long>(n_edges) +
                          static_cast<long long>(n_faces);
  if (euler != 2)
    return fail(Verdict::invalid,
                "the mesh has genus " + std::to_string((2 - euler) / 2) +
                    " (Euler characteristic V - E + F = " + std::to_string(n_vertices) + " - " +
                    std::to_string(n_edges) + " + " + std::to_string(n_faces) + " = " +
                    std::to_string(euler) +
                    "), not 0: a convex polyhedron is a topological sphere");
  return {};
}

// ---------------------------------------------------------------- geometry

// Newell normal (twice the vector area) of a face, and its vertex centroid; computed
// relative to the centroid to keep rounding small.
struct FacePlane {
  Point centroid{0, 0, 0};
  Point normal{0, 0, 0};  // unit length once the face is known to be non-degenerate
};

// What the geometric checks share: the extent, and every face's plane (its Newell
// normal not yet normalised), computed once by nondegenerate().
struct Geometry {
  Extent extent;
  std::vector<FacePlane> planes;  // by face index
};

// The vertices of face f in the order of its vertex circulator (starting at the target
// of the face's halfedge), without the circulator's overhead.
template <class Visit>
void for_each_corner(const Mesh& mesh, Mesh::FaceHandle f, const Visit& visit) {
  const auto first = mesh.halfedge_handle(f);
  auto h = first;
  do {
    visit(mesh.to_vertex_handle(h));
    h = mesh.next_halfedge_handle(h);
  } while (h != first);
}

FacePlane newell_plane(const std::vector<Point>& corners) {
  FacePlane plane;
  for (const auto& p : corners) plane.centroid += p;
  plane.centroid /= static_cast<double>(corners.size());
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Point a = corners[i] - plane.centroid;
    const Point b = corners[i + 1 == corners.size() ? 0 : i + 1] - plane.centroid;
    plane.normal += OpenMesh::cross(a, b);
  }
  return plane;
}

// Whether two of `values` are equal (quadratic: faces are small; sorting would allocate).
template <class T>
bool has_equal_pair(const std::vector<T>& values) {
  for (std::size_t i = 0; i < values.size(); ++i)
    for (std::size_t j = i + 1; j < values.size(); ++j)
      if (values[i] == values[j]) return true;
  return false;
}

// Fills `geometry` (extent and face planes) for the later checks when the mesh passes.
Finding nondegenerate(const Mesh& mesh, Geometry& geometry) {
  for (auto v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      return fail(Verdict::invalid,
                  "vertex " + std::to_string(v.idx()) + " has a coordinate that is not finite");
  }
  geometry.extent = bounding_box(mesh);
  const double diagonal = geometry.extent.diagonal;
  geometry.planes.assign(mesh.n_faces(), FacePlane{});
  std::vector<Point> corners;
  std::vector<int> ids;
  for (auto f : mesh.faces()) {
    ids.clear();
    corners.clear();
    for_each_corner(mesh, f, [&](Mesh::VertexHandle v) {
      ids.push_back(v.idx());
      corners.push_back(mesh.point(v));
    });
    const auto face = [&] { return "face " + std::to_string(f.idx()); };
    if (ids.size() < 3)
      return fail(Verdict::invalid, face() + " has " + std::to_string(ids.size()) +
                                        " vertices; a face needs at least 3");
    if (has_equal_pair(ids)) {
      std::sort(ids.begin(), ids.end());
      const auto twice = std::adjacent_find(ids.begin(), ids.end());
      return fail(Verdict::invalid,
                  face() + " uses vertex " + std::to_string(*twice) + " more than once");
    }
    const FacePlane plane = newell_plane(corners);
    if (has_equal_pair(corners))
      return fail(Verdict::invalid, face() + " has two vertices at the same position");
    if (!(plane.normal.norm() > kZeroAreaRatio * diagonal * diagonal))
      return fail(Verdict::invalid, face() + " has zero area (its vertices are collinear)");
    geometry.planes[f.idx()] = plane;
  }
  return {};
}

Finding nondegenerate(const Mesh& mesh) {
  Geometry geometry;
  return nondegenerate(mesh, geometry);
}

// Signed volume relative to `origin`, and the sum of the absolute volumes of the fan
// tetrahedra (the scale of the rounding error).
std::pair<double, double> fan_volumes(const Mesh& mesh, const Point& origin) {
  double total = 0, absolute = 0;
  for (auto f : mesh.faces()) {
    auto h = mesh.halfedge_handle(f);
    const Point a = mesh.point(mesh.from_vertex_handle(h)) - origin;
    for (h = mesh.next_halfedge_handle(h);
         mesh.to_vertex_handle(h) != mesh.from_vertex_handle(mesh.halfedge_handle(f));
         h = mesh.next_halfedge_handle(h)) {
      const Point b = mesh.point(mesh.from_vertex_handle(h)) - origin;
      const Point c = mesh.point(mesh.to_vertex_handle(h)) - origin;
      const double six_v = OpenMesh::dot(a, OpenMesh::cross(b, c));
      total += six_v;
      absolute += std::abs(six_v);
    }
  }
  return {total / 6, absolute / 6};
}

Finding outward(const Mesh& mesh, const Extent& extent) {
  // OpenMesh links the two halfedges of every edge in opposite directions, so the faces
  // of a closed mesh are consistently oriented by construction; what remains is the sign.
  const auto [volume, absolute] = fan_volumes(mesh, extent.centre);
  if (!(std::abs(volume) > kFlatVolumeRatio * absolute))
    return fail(Verdict::invalid,
                "the mesh encloses no volume (signed volume " + number(volume) + "): it is flat");
  if (volume < 0)
    return {Verdict::inverted,
            "the faces are oriented inwards (signed volume " + number(volume) + " < 0)", volume};
  return {Verdict::ok, {}, volume};
}

Finding outward(const Mesh& mesh) { return outward(mesh, bounding_box(mesh)); }

// Planarity, then edge convexity; `geometry` from nondegenerate(), its planes normalised
// here.
Finding planar_and_convex(const Mesh& mesh, double relative_tolerance, Geometry& geometry) {
  const double tolerance = relative_tolerance * geometry.extent.diagonal;
  std::vector<FacePlane>& planes = geometry.planes;
  for (auto f : mesh.faces()) {
    FacePlane& plane = planes[f.idx()];
    plane.normal.normalize();
    Mesh::VertexHandle off_plane;
    double distance = 0;
    for_each_corner(mesh, f, [&](Mesh::VertexHandle v) {
      if (off_plane.is_valid()) return;
      distance = std::abs(OpenMesh::dot(mesh.point(v) - plane.centroid, plane.normal));
      if (!(distance <= tolerance)) off_plane = v;
    });
    if (off_plane.is_valid())
      return fail(Verdict::not_convex,
                  "face " + std::to_string(f.idx()) + " is not planar: vertex " +
                      std::to_string(off_plane.idx()) + " is " + number(distance) +
                      " from its plane (tolerance " + number(tolerance) + ")");
  }
  for (auto e : mesh.edges()) {
    for (int side = 0; side < 2; ++side) {
      const auto h = mesh.halfedge_handle(e, side);
      const auto f = mesh.face_handle(h);
      const auto g = mesh.opposite_face_handle(h);
      const FacePlane& plane = planes[f.idx()];
      // The edge's own vertices belong to f and passed the planarity check: their height
      // is at most the tolerance, so only g's other vertices can fail.
      const auto from = mesh.from_vertex_handle(h), to = mesh.to_vertex_handle(h);
      Mesh::VertexHandle above;
      double height = 0;
      for_each_corner(mesh, g, [&](Mesh::VertexHandle v) {
        if (above.is_valid() || v == from || v == to) return;
        height = OpenMesh::dot(mesh.point(v) - plane.centroid, plane.normal);
        if (!(height <= tolerance)) above = v;
      });
      if (above.is_valid())
        return fail(Verdict::not_convex, "edge " + std::to_string(e.idx()) + " (vertices " +
                                             vertex_pair(mesh, e) + ") is reflex: vertex " +
                                             std::to_string(above.idx()) + " of face " +
                                             std::to_string(g.idx()) + " is " + number(height) +
                                             " above the plane of face " + std::to_string(f.idx()) +
                                             " (tolerance " + number(tolerance) + ")");
    }
  }
  return {};
}

// The full rule; stops at the first problem. An inverted mesh is reported as such
// before the geometric checks (which assume outward normals).
Finding convex_polyhedron(const Mesh& mesh, double relative_tolerance) {
  if (Finding found = closed_manifold(mesh); found.verdict != Verdict::ok) return found;
  Geometry geometry;
  if (Finding found = nondegenerate(mesh, geometry); found.verdict != Verdict::ok) return found;
  if (Finding found = outward(mesh, geometry.extent); found.verdict != Verdict::ok) return found;
  return planar_and_convex(mesh, relative_tolerance, geometry);
}

CheckResult to_result(Finding found) { return {std::move(found.problem), {}}; }

// A copy of `mesh` without deleted elements, each face's vertex order reversed if `flip`.
Mesh rebuilt(const Mesh& mesh, bool flip) {
  Mesh out;
  std::vector<Mesh::VertexHandle> map(mesh.n_vertices());
  for (auto v : mesh.vertices()) map[v.idx()] = out.add_vertex(mesh.point(v));
  std::vector<Mesh::VertexHandle> face;
  for (auto f : mesh.faces()) {
    face.clear();
    for (auto v : mesh.fv_range(f)) face.push_back(map[v.idx()]);
    if (flip) std::reverse(face.begin(), face.end());
    out.add_face(face);
  }
  return out;
}

}  // namespace

CheckResult check_closed_manifold(const Mesh& mesh) { return to_result(closed_manifold(mesh)); }

CheckResult check_outward_oriented(const Mesh& mesh) {
  if (Finding found = closed_manifold(mesh); found.verdict != Verdict::ok)
    return {"orientation is undefined: " + found.problem, {}};
  return to_result(outward(mesh));
}

CheckResult check_nondegenerate(const Mesh& mesh) { return to_result(nondegenerate(mesh)); }

CheckResult check_convex_polyhedron(const Mesh& mesh, const ValidationOptions& options) {
  return to_result(convex_polyhedron(mesh, options.planarity_tolerance));
}

PreparedMesh prepare_convex_polyhedron(const Mesh& mesh, std::string_view name,
                                       const ValidationOptions& options) {
  std::optional<PreparedMesh> flipped = detail::check_operand(mesh, name, options);
  if (!flipped) return {mesh, {}};
  return std::move(*flipped);
}

namespace detail {

std::optional<PreparedMesh> check_operand(const Mesh& mesh, std::string_view name,
                                          const ValidationOptions& options) {
  const auto prefix = [&] { return std::string(name) + ": "; };
  const auto raise = [&](const Finding& found) {
    if (found.verdict == Verdict::not_convex) throw not_convex(prefix() + found.problem);
    throw invalid_mesh(prefix() + found.problem);
  };
  Finding found = convex_polyhedron(mesh, options.planarity_tolerance);
  if (found.verdict == Verdict::ok) return std::nullopt;
  if (found.verdict != Verdict::inverted || !options.fix_inverted) raise(found);

  // Rare: check the flipped copy itself, so that messages name its elements as before.
  PreparedMesh prepared{rebuilt(mesh, true), {}};
  prepared.notes.push_back(prefix() + "orientation was inverted (signed volume " +
                           number(found.volume) + "); the faces were reversed");
  found = convex_polyhedron(prepared.mesh, options.planarity_tolerance);
  if (found.verdict != Verdict::ok) raise(found);
  return prepared;
}

}  // namespace detail

double signed_volume(const Mesh& mesh) {
  return fan_volumes(mesh, bounding_box(mesh).centre).first;
}

}  // namespace morph
