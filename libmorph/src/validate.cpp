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
#include <memory>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "double_pair.h"
#include "polytope.h"
#include "validate_detail.h"

namespace morph {
namespace {

// A mesh whose signed volume is below this fraction of the sum of the absolute
// volumes of its fan tetrahedra is flat: the tetrahedra cancel out up to rounding
// (a convex body measured from an interior point has no cancellation at all, ratio 1).
constexpr double kFlatVolumeRatio = 1e-12;

// A face whose width, twice its area (its Newell normal's length) over its longest edge, is at
// most this fraction of D has zero area: its vertices are collinear up to rounding (points
// computed in double on one line lie within ~1e-16 D of it). Width, not area against D^2: an
// exact result's facet may be small (an erosion's, where three planes cut a corner a few
// 1e-8 D across) or thin (an opening's edge facet, 2e-5 D long and 4e-10 D wide), and still a
// proper face. The longest edge is at most D, so a face above kZeroAreaRatio D^2 passes: the
// faces' fast paths test that alone, and send a face below it (rare) to the general path.
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

// The mesh's arrays read by plain index. OpenMesh's skipping iterators and its
// per-element property look-ups (point(), status()) cost more than the checks themselves,
// so each array is looked up once here. Element counts include deleted elements, which
// the checks skip exactly as OpenMesh's iterators do.
struct MeshView {
  // `none_deleted`: the caller knows that no element is deleted (skips the status scans).
  explicit MeshView(const Mesh& m, bool none_deleted = false)
      : mesh(m),
        points(m.points()),
        n_vertices(static_cast<int>(m.n_vertices())),
        n_edges(static_cast<int>(m.n_edges())),
        n_halfedges(static_cast<int>(m.n_halfedges())),
        n_faces(static_cast<int>(m.n_faces())),
        vertex_status(none_deleted ? nullptr : deleted_status(m, m.vertex_status_pph())),
        edge_status(none_deleted ? nullptr : deleted_status(m, m.edge_status_pph())),
        halfedge_status(none_deleted ? nullptr : deleted_status(m, m.halfedge_status_pph())),
        face_status(none_deleted ? nullptr : deleted_status(m, m.face_status_pph())),
        arrays(m) {}

  const Mesh& mesh;
  const Point* points;
  int n_vertices, n_edges, n_halfedges, n_faces;
  // Null when no element of that kind is deleted (or the kind has no status).
  const OpenMesh::Attributes::StatusInfo *vertex_status, *edge_status, *halfedge_status,
      *face_status;
  detail::HalfedgeArrays arrays;

  template <class StatusHandle>
  static const OpenMesh::Attributes::StatusInfo* deleted_status(const Mesh& m,
                                                                StatusHandle handle) {
    if (!handle.is_valid()) return nullptr;
    const auto& status = m.property(handle).data_vector();
    const bool any =
        std::any_of(status.begin(), status.end(), [](const auto& s) { return s.deleted(); });
    return any ? status.data() : nullptr;
  }

  bool live_vertex(int v) const { return !vertex_status || !vertex_status[v].deleted(); }
  bool live_edge(int e) const { return !edge_status || !edge_status[e].deleted(); }
  bool live_halfedge(int h) const { return !halfedge_status || !halfedge_status[h].deleted(); }
  bool live_face(int f) const { return !face_status || !face_status[f].deleted(); }

  // OpenMesh stores the two halfedges of edge e as 2e and 2e + 1.
  int to(int h) const { return arrays.to(h); }
  int from(int h) const { return arrays.from(h); }
  int next(int h) const { return arrays.next(h); }
  int face(int h) const { return arrays.face(h); }
  int halfedge_of_vertex(int v) const { return arrays.halfedge_of_vertex(v); }
  int halfedge_of_face(int f) const { return arrays.halfedge_of_face(f); }
};

std::string vertex_pair(const MeshView& m, int edge) {
  return std::to_string(m.from(2 * edge)) + "-" + std::to_string(m.to(2 * edge));
}

// Diagonal of the axis-aligned bounding box of the (non-deleted) vertices, and its centre.
struct Extent {
  double diagonal = 0;
  Point centre{0, 0, 0};
};

Extent extent_of(const Point& lo, const Point& hi) { return {(hi - lo).norm(), (lo + hi) * 0.5}; }

Extent bounding_box(const MeshView& m) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Point lo(inf, inf, inf), hi(-inf, -inf, -inf);
  bool any = false;
  for (int v = 0; v < m.n_vertices; ++v) {
    if (!m.live_vertex(v)) continue;
    lo.minimize(m.points[v]);
    hi.maximize(m.points[v]);
    any = true;
  }
  if (!any) return {};
  return extent_of(lo, hi);
}

// The vertex cycle of every live face, in the order of its vertex circulator (starting
// at the target of the face's halfedge), read once for all the geometric checks. A
// deleted face has an empty cycle.
struct FaceCycles {
  FaceCycles() = default;
  FaceCycles(FaceCycles&&) = default;  // the arrays keep their buffers
  FaceCycles& operator=(FaceCycles&&) = default;
  // Over all faces: begin has size F + 1; corner k of face f is vertex[begin[f] + k], and
  // across[begin[f] + k] the face across the edge that ends at it (if any). Either the
  // stores below (face_cycles()) or a caller's arrays (detail::FaceCycleView).
  const int* begin = nullptr;
  const int* vertex = nullptr;
  const int* across = nullptr;
  std::vector<int> begin_store, vertex_store, across_store;
  int degree(int f) const { return begin[f + 1] - begin[f]; }
  const int* corners(int f) const { return vertex + begin[f]; }
};

FaceCycles face_cycles(const MeshView& m) {
  FaceCycles cycles;
  cycles.begin_store.resize(m.n_faces + 1);
  // At most one corner per halfedge: written by index, trimmed at the end.
  cycles.vertex_store.resize(m.n_halfedges);
  cycles.across_store.resize(m.n_halfedges);
  int* const vertex = cycles.vertex_store.data();
  int* const across = cycles.across_store.data();
  int c = 0;
  for (int f = 0; f < m.n_faces; ++f) {
    cycles.begin_store[f] = c;
    if (!m.live_face(f)) continue;
    const int first = m.halfedge_of_face(f);
    int h = first;
    do {
      if (c == m.n_halfedges)
        throw error("internal error: mesh face " + std::to_string(f) +
                    " is not a closed cycle of halfedges");
      vertex[c] = m.to(h);
      across[c] = m.face(h ^ 1);
      ++c;
      h = m.next(h);
    } while (h != first);
  }
  cycles.begin_store[m.n_faces] = c;
  cycles.begin = cycles.begin_store.data();
  cycles.vertex = vertex;
  cycles.across = across;
  return cycles;
}

// ---------------------------------------------------------------- topology

Finding closed_manifold(const MeshView& m) {
  long long n_vertices = 0, n_edges = 0, n_faces = 0;
  for (int f = 0; f < m.n_faces; ++f) n_faces += m.live_face(f);
  if (n_faces == 0) return fail(Verdict::invalid, "the mesh is empty (it has no faces)");

  for (int e = 0; e < m.n_edges; ++e) {
    if (!m.live_edge(e)) continue;
    ++n_edges;
    if (m.face(2 * e) < 0 || m.face(2 * e + 1) < 0)
      return fail(Verdict::invalid, "edge " + std::to_string(e) + " (vertices " +
                                        vertex_pair(m, e) +
                                        ") has only one face: the mesh is not closed");
  }

  // A vertex is manifold when the faces around it form one fan: the circulator around
  // it (which walks one fan) must meet every halfedge leaving it, and reach each
  // neighbour once (two edges between the same vertices pinch the surface).
  enum class Fan : char { unreached, queued, one, isolated, several, pinched };
  // What the walks know of a vertex, kept together (a walk reads them for each neighbour).
  struct VertexState {
    int outgoing = 0;  // live halfedges leaving it
    int seen = -1;     // == v: reached from v already (a stamp, never cleared)
    Fan fan = Fan::unreached;
  };
  std::vector<VertexState> state(m.n_vertices);
  for (int h = 0; h < m.n_halfedges; ++h)
    if (m.live_halfedge(h)) ++state[m.from(h)].outgoing;
  // Walks the fan of v, calling visit(w) for each neighbour w it reaches.
  const auto walk_fan = [&](int v, const auto& visit) {
    if (state[v].outgoing == 0) return Fan::isolated;
    int reached = 0;
    bool pinched = false;
    // The outgoing halfedges around v, as the circulator walks them.
    const int first = m.halfedge_of_vertex(v);
    int h = first;
    do {
      const int w = m.to(h);
      visit(w);
      pinched = pinched || state[w].seen == v;
      state[w].seen = v;
      if (++reached > state[v].outgoing) break;  // corrupt links
      h = m.next(h ^ 1);
    } while (h != first);
    if (reached != state[v].outgoing) return Fan::several;
    return pinched ? Fan::pinched : Fan::one;
  };

  // Each fan is walked once, in a search from the first vertex that also finds the
  // vertices connected to it (through the fans, which hold every edge once the vertices
  // pass); then the vertices are judged in index order, as the rule lists them.
  int first = 0;
  while (first < m.n_vertices && !m.live_vertex(first)) ++first;
  std::vector<int> stack;
  const auto reach = [&](int w) {
    if (state[w].fan != Fan::unreached) return;
    state[w].fan = Fan::queued;
    stack.push_back(w);
  };
  if (first < m.n_vertices) reach(first);
  while (!stack.empty()) {
    const int v = stack.back();
    stack.pop_back();
    state[v].fan = walk_fan(v, reach);
  }
  for (int v = 0; v < m.n_vertices; ++v) {
    if (!m.live_vertex(v)) continue;
    ++n_vertices;
    const Fan found = state[v].fan == Fan::unreached ? walk_fan(v, [](int) {}) : state[v].fan;
    if (found == Fan::isolated)
      return fail(Verdict::invalid,
                  "vertex " + std::to_string(v) + " is isolated (it belongs to no face)");
    if (found == Fan::several)
      return fail(Verdict::invalid, "vertex " + std::to_string(v) +
                                        " is not manifold: its faces form more than one fan");
    if (found == Fan::pinched) {
      // Name the smallest neighbour reached twice.
      std::vector<int> neighbours;
      for (auto oh : m.mesh.voh_range(Mesh::VertexHandle(v)))
        neighbours.push_back(m.mesh.to_vertex_handle(oh).idx());
      std::sort(neighbours.begin(), neighbours.end());
      const auto twice = std::adjacent_find(neighbours.begin(), neighbours.end());
      return fail(Verdict::invalid, "vertices " + std::to_string(v) + " and " +
                                        std::to_string(*twice) +
                                        " are joined by two edges: the mesh is not 2-manifold");
    }
  }
  for (int v = first + 1; v < m.n_vertices; ++v)
    if (m.live_vertex(v) && state[v].fan == Fan::unreached)
      return fail(Verdict::invalid, "the mesh is not connected: vertex " + std::to_string(v) +
                                        " is not connected to vertex " + std::to_string(first));

  const long long euler = n_vertices - n_edges + n_faces;
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

FacePlane newell_plane(const Point* points, const int* corners, int n) {
  FacePlane plane;
  for (int i = 0; i < n; ++i) plane.centroid += points[corners[i]];
  plane.centroid *= 1.0 / n;
  for (int i = 0; i < n; ++i) {
    const Point a = points[corners[i]] - plane.centroid;
    const Point b = points[corners[i + 1 == n ? 0 : i + 1]] - plane.centroid;
    plane.normal += OpenMesh::cross(a, b);
  }
  return plane;
}

// Signed distance of p above a face's plane.
double height(const FacePlane& plane, const Point& p) {
  return OpenMesh::dot(p - plane.centroid, plane.normal);
}

// Six times the signed volume about an origin, and six times the sum of the absolute
// volumes of the fan tetrahedra (the scale of the rounding error).
struct FanVolumes {
  double total = 0, absolute = 0;

  // Adds the fan of a face from its last corner (the source of its halfedge).
  void add_face(const Point* points, const int* corners, int n, const Point& origin) {
    const Point a = points[corners[n - 1]] - origin;
    for (int k = 0; corners[k + 1] != corners[n - 1]; ++k) {
      const Point b = points[corners[k]] - origin;
      const Point c = points[corners[k + 1]] - origin;
      const double six_v = OpenMesh::dot(a, OpenMesh::cross(b, c));
      total += six_v;
      absolute += std::abs(six_v);
    }
  }
};

FanVolumes fan_volumes(const MeshView& m, const FaceCycles& cycles, const Point& origin) {
  FanVolumes volumes;
  for (int f = 0; f < m.n_faces; ++f)
    if (cycles.degree(f) > 0)
      volumes.add_face(m.points, cycles.corners(f), cycles.degree(f), origin);
  return volumes;
}

// What the geometric checks share, gathered in one pass over the faces by
// nondegenerate(): the extent, the face cycles, the fan volumes about the extent's
// centre, the first face that is not planar and whether any edge may be reflex (both
// reported only after the orientation, as the rule orders them).
struct Geometry {
  Extent extent;
  FaceCycles cycles;
  FanVolumes volumes;
  int non_planar_face = -1;
  bool reflex = false;  // some vertex lies above the plane of a neighbouring face
  // Optional (null: none): where each face's unit normal goes (see unit_normal()), and
  // whether every face's could be given.
  detail::UnitNormal* unit = nullptr;
  bool unit_complete = true;
  // With `unit`: whether every edge is proven strictly convex (see StrictBelow).
  bool edges_proven = false;
  // Optional (null: none): the caller's bounding box of the vertices (see geometry_passes).
  const detail::PointBox* box = nullptr;
};

// A proof that an edge between two triangles is strictly convex, from the reflex test's height
// of the far corner v of triangle g across the edge above the plane of triangle f: the edge is
// strictly convex exactly when v lies strictly below the exact plane of f (det(N_f, N_g, d) =
// -|d|^2 (v - from) . N_f, as in triangle_edge_convexity(), polytope.cpp), which the computed
// height h proves when h < -(e_f W + K). With c the computed centroid, n the unit normal (the
// unit normal left for the polytope: the same values), within e_f of the exact normal's unit
// vector N, w = v - c, M a bound on |coordinates| and one ulp 2^-52 per operation (any rounding
// mode): fl(v - c) is within 2^-52 |w|_1 of w and the dot adds at most 3 ulps of |w|_1 |n|_inf,
// so h is within 4 ulps of W (margins) of w . n, which is within e_f |w| of w . N; and w . N
// differs from the signed distance of v to the plane by the distance of c to the plane, at
// most |c - exact centroid| <= 3 * 4 ulps of M (two additions of at most 3M, the rounded
// 1/3, the product); W bounds |w|_1 (v and c in the bounding box, c up to its rounding);
// plus an absolute term for underflow.
struct StrictBelow {
  double W, K;  // K: the terms that do not scale with e_f
  StrictBelow(const Extent& extent) {
    const Point& c = extent.centre;
    const double M =
        (std::max({std::abs(c[0]), std::abs(c[1]), std::abs(c[2])}) + extent.diagonal) * 1.01;
    W = (1.74 * extent.diagonal + 0x1p-48 * M) * 1.01;
    K = (4 * 0x1p-52 * W + 16 * 0x1p-52 * M) * 1.01 + 1e-300;
  }
  // -(e_f W + K), the threshold for face f's heights.
  double threshold(double error) const { return -(error * W * 1.01 + K); }
};

// The unit normal that a face's checks leave for the polytope: detail::centroid_unit_normal()
// of the face's Newell sum as they computed it (the same operations as
// Polytope::compute_normals(), so the same values). `complete` turns false when the sum is
// out of that function's range: the caller then computes every unit normal itself.
inline void unit_normal(detail::UnitNormal& out, double nx, double ny, double nz, double length,
                        double inverse, double magnitude, int d, bool& complete) {
  if (!detail::centroid_unit_normal(nx, ny, nz, length, inverse, magnitude, d, out)) {
    complete = false;
    out.error = std::numeric_limits<double>::infinity();  // proves nothing (see StrictBelow)
  }
}

using detail::norm1;

// The plane of face f with its unit normal (the face is known to be non-degenerate).
FacePlane unit_plane(const MeshView& m, const FaceCycles& cycles, int f) {
  FacePlane plane = newell_plane(m.points, cycles.corners(f), cycles.degree(f));
  plane.normal *= 1.0 / plane.normal.norm();
  return plane;
}

// Whether a vertex of face g across f's edge from -> to (other than the edge's ends, which
// passed f's planarity check) lies above f's plane by more than the tolerance.
bool reflex_across(const MeshView& m, const FaceCycles& cycles, const FacePlane& plane, int g,
                   int from, int to, double tolerance) {
  const int* corners = cycles.corners(g);
  const int n = cycles.degree(g);
  if (n == 3) {  // the usual case: the one corner off the edge, found without a loop
    const int v = corners[0] != from && corners[0] != to   ? corners[0]
                  : corners[1] != from && corners[1] != to ? corners[1]
                                                           : corners[2];
    // A triangle that repeats a vertex fails its own check later, which then wins.
    return !(height(plane, m.points[v]) <= tolerance);
  }
  for (int k = 0; k < n; ++k) {
    const int v = corners[k];
    if (v == from || v == to) continue;
    if (!(height(plane, m.points[v]) <= tolerance)) return true;
  }
  return false;
}

// Whether two of the n values key(0), ..., key(n - 1) are equal (quadratic: faces are
// small; sorting would allocate).
template <class Key>
bool has_equal_pair(int n, const Key& key) {
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (key(i) == key(j)) return true;
  return false;
}

// The plane of a triangle or a quadrilateral, computed ahead of its checks. nondegenerate()
// works on these faces in three parts: triangle_plane() and quad_plane() read only the corners
// (the Newell sum, the centroid and the fan volumes), plane_root() then takes the square root
// and the division, and the heights come last, with triangle_passes() and quad_passes(). Each
// of the first two parts runs over every such face in a loop whose iterations do not depend on
// each other, short enough for several faces' chains of dependent operations (the second's a
// square root then a division) to overlap.
struct SmallPlane {
  double cx, cy, cz;     // the centroid
  double nx, ny, nz;     // the Newell sum; once plane_root() has passed the face, the unit normal
  double first, second;  // six times the volumes of the fan's tetrahedra (a triangle has one)
  double length2;        // (nx * nx + ny * ny) + nz * nz of the Newell sum
  double magnitude;      // the sum of |a_k|_1 |a_(k+1)|_1 over the corners (for unit_normal())
  int degree;            // 3 or 4
  bool ok;               // false: a repeated vertex or position, or zero area (nothing else is set)
};

// The second part of a triangle's or quadrilateral's plane (see SmallPlane): its zero-area
// test, unit normal (and the unit normal it leaves for the polytope).
inline void plane_root(SmallPlane& q, double zero_area, detail::UnitNormal* unit,
                       bool& unit_complete) {
  if (!q.ok) return;
  const double length = std::sqrt(q.length2);
  if (!(length > zero_area)) {
    q.ok = false;
    return;
  }
  const double inverse = 1.0 / length;
  if (unit)
    unit_normal(*unit, q.nx, q.ny, q.nz, length, inverse, q.magnitude, q.degree, unit_complete);
  q.nx *= inverse;
  q.ny *= inverse;
  q.nz *= inverse;
}

// height(plane, p) of a plane given by its centroid and unit normal: the same operations.
struct PlaneHeight {
  double cx, cy, cz, nx, ny, nz;
  double operator()(const Point& p) const {
    return (p[0] - cx) * nx + (p[1] - cy) * ny + (p[2] - cz) * nz;
  }
};

using detail::both_at_most;
using detail::Pair;
using detail::pair_abs;

// PlaneHeight of two points at once, one in each lane: the same values, in half the
// operations (quad_passes() takes eight heights of each quadrilateral's neighbours).
struct PlaneHeights {
  Pair cx, cy, cz, nx, ny, nz;
  explicit PlaneHeights(const PlaneHeight& h)
      : cx{h.cx, h.cx},
        cy{h.cy, h.cy},
        cz{h.cz, h.cz},
        nx{h.nx, h.nx},
        ny{h.ny, h.ny},
        nz{h.nz, h.nz} {}
  Pair operator()(const Point& p, const Point& q) const {
    const Pair x{p[0], q[0]}, y{p[1], q[1]}, z{p[2], q[2]};
    return (x - cx) * nx + (y - cy) * ny + (z - cz) * nz;
  }
};

// A corner's coordinates: doubles, or Pairs holding one face's corner in each lane.
template <class T>
struct Coords {
  T x, y, z;
};

inline Coords<double> coords(const Point& p) { return {p[0], p[1], p[2]}; }
inline Coords<Pair> coords(const Point& p, const Point& q) {
  return {Pair{p[0], q[0]}, Pair{p[1], q[1]}, Pair{p[2], q[2]}};
}

inline double abs_of(double x) { return std::abs(x); }
inline Pair abs_of(Pair x) { return pair_abs(x); }

// norm1() lane by lane.
template <class T>
inline T norm1_of(T x, T y, T z) {
  return abs_of(x) + abs_of(y) + abs_of(z);
}

// Six times the volume of the tetrahedron (o, a, b, c): FanVolumes::add_face()'s
// dot(a - o, cross(b - o, c - o)), in OpenMesh's order of operations. Always inlined:
// quad_plane() calls it twice a face, and GCC otherwise makes it a call.
template <class T>
[[gnu::always_inline]] inline T six_volume(const Point& o, const Coords<T>& a, const Coords<T>& b,
                                           const Coords<T>& c) {
  const T u[3] = {a.x - o[0], a.y - o[1], a.z - o[2]};
  const T v[3] = {b.x - o[0], b.y - o[1], b.z - o[2]};
  const T w[3] = {c.x - o[0], c.y - o[1], c.z - o[2]};
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) + u[1] * (v[2] * w[0] - v[0] * w[2])) +
         u[2] * (v[0] * w[1] - v[1] * w[0]);
}

// SmallPlane's values, of one face (doubles) or of two (Pairs, one face in each lane: each
// lane's operations are those of one face, so its values are that face's).
template <class T>
struct PlaneValues {
  T cx, cy, cz, nx, ny, nz, first, second, length2, magnitude;
};

inline SmallPlane small_plane(const PlaneValues<double>& v, int degree) {
  return {v.cx,    v.cy,     v.cz,      v.nx,        v.ny,   v.nz,
          v.first, v.second, v.length2, v.magnitude, degree, true};
}
inline SmallPlane small_plane(const PlaneValues<Pair>& v, int lane, int degree) {
  return {v.cx[lane],    v.cy[lane],     v.cz[lane],      v.nx[lane],        v.ny[lane], v.nz[lane],
          v.first[lane], v.second[lane], v.length2[lane], v.magnitude[lane], degree,     true};
}

// A triangle's share of nondegenerate(), the usual case: the same operations in the same
// order as newell_plane(), height(), FanVolumes::add_face() and reflex_across(), unrolled
// into one place (the general path's loops and calls cost more than its arithmetic), so
// every value and verdict is the general path's. In two parts (see SmallPlane):
// triangle_plane() (or triangle_planes(), two at once), then triangle_passes(), which returns
// false, having changed nothing, when the triangle fails one of the checks that reject a mesh:
// the general path then names the problem.
// A repeated vertex or position needs no test of its own here: with two equal corners, two of
// the cross products below are opposites and the third is zero (a x a), so the normal is
// exactly zero (in round-to-nearest; within a few ulps of D^2 in any rounding mode, far below
// kZeroAreaRatio D^2) and the zero-area test rejects the triangle.
template <class T>
[[gnu::always_inline]] inline PlaneValues<T> triangle_values(const Coords<T>& p0,
                                                             const Coords<T>& p1,
                                                             const Coords<T>& p2,
                                                             const Point& centre, bool unit) {
  // Straight-line: OpenMesh's vector operations, one component at a time.
  const T cx = (((0.0 + p0.x) + p1.x) + p2.x) * (1.0 / 3);
  const T cy = (((0.0 + p0.y) + p1.y) + p2.y) * (1.0 / 3);
  const T cz = (((0.0 + p0.z) + p1.z) + p2.z) * (1.0 / 3);
  // The corners relative to the centroid.
  const T ax = p0.x - cx, ay = p0.y - cy, az = p0.z - cz;
  const T bx = p1.x - cx, by = p1.y - cy, bz = p1.z - cz;
  const T qx = p2.x - cx, qy = p2.y - cy, qz = p2.z - cz;
  // cross(u, v) component i: u[j] v[l] - u[l] v[j] with (j, l) = (i + 1, i + 2) mod 3,
  // summed over the edges a-b, b-q, q-a from zero.
  const T nx = ((0.0 + (ay * bz - az * by)) + (by * qz - bz * qy)) + (qy * az - qz * ay);
  const T ny = ((0.0 + (az * bx - ax * bz)) + (bz * qx - bx * qz)) + (qz * ax - qx * az);
  const T nz = ((0.0 + (ax * by - ay * bx)) + (bx * qy - by * qx)) + (qx * ay - qy * ax);
  T magnitude{};
  if (unit) {
    const T la = norm1_of(ax, ay, az), lb = norm1_of(bx, by, bz), lq = norm1_of(qx, qy, qz);
    magnitude = (la * lb + lb * lq) + lq * la;
  }
  // FanVolumes::add_face(): the one tetrahedron (q, a, b) of the fan from the last corner.
  const T volume = six_volume(centre, p2, p0, p1), length2 = (nx * nx + ny * ny) + nz * nz;
  return {cx, cy, cz, nx, ny, nz, volume, T{}, length2, magnitude};
}

SmallPlane triangle_plane(const MeshView& m, const int* ids, const Point& centre, bool unit) {
  const Point* const P = m.points;
  return small_plane(
      triangle_values(coords(P[ids[0]]), coords(P[ids[1]]), coords(P[ids[2]]), centre, unit), 3);
}

// triangle_plane() of two triangles at once (a in lane 0, b in lane 1): the same values.
void triangle_planes(const MeshView& m, const int* a, const int* b, const Point& centre, bool unit,
                     SmallPlane& qa, SmallPlane& qb) {
  const Point* const P = m.points;
  const PlaneValues<Pair> v = triangle_values(coords(P[a[0]], P[b[0]]), coords(P[a[1]], P[b[1]]),
                                              coords(P[a[2]], P[b[2]]), centre, unit);
  qa = small_plane(v, 0, 3);
  qb = small_plane(v, 1, 3);
}

// kProve: `proven`, when set (the caller has every face's unit normal in `unit`), is left set
// when the edges with triangles across are proven strictly convex (StrictBelow) and no other
// face is across, cleared otherwise (without kProve, none of this is compiled).
template <bool kProve>
bool triangle_passes(const MeshView& m, const FaceCycles& cycles, int f, const SmallPlane& q,
                     double tolerance, bool convexity, FanVolumes& volumes, int& non_planar_face,
                     bool& any_reflex, const detail::UnitNormal* unit, const StrictBelow& strict,
                     bool& proven) {
  if (!q.ok) return false;
  volumes.total += q.first;
  volumes.absolute += std::abs(q.first);
  const int b = cycles.begin[f];
  const int* ids = cycles.vertex + b;
  const int i0 = ids[0], i1 = ids[1], i2 = ids[2];
  const Point &p0 = m.points[i0], &p1 = m.points[i1], &p2 = m.points[i2];
  // height(plane, p): dot(p - centroid, normal), summed in OpenMesh's order.
  const PlaneHeight height{q.cx, q.cy, q.cz, q.nx, q.ny, q.nz};
  // With kProve, StrictBelow's bound on how far a height here is from the signed distance to the
  // exact plane, e_f W + K (infinite when the unit normal proves nothing). The corners lie in
  // that plane: when the bound is within the tolerance, so are their heights.
  const double bound =
      kProve && unit ? -strict.threshold(unit[f].error) : std::numeric_limits<double>::infinity();
  if (non_planar_face < 0 && !(bound <= tolerance) &&
      !(std::abs(height(p0)) <= tolerance && std::abs(height(p1)) <= tolerance &&
        std::abs(height(p2)) <= tolerance))
    non_planar_face = f;
  if (!convexity || any_reflex) return true;
  // The corner of each neighbouring triangle off the common edge from -> to (the edge that
  // ends at corner k); a neighbour that is not a triangle is checked after.
  const int* across = cycles.across + b;
  const int from[3] = {i2, i0, i1}, to[3] = {i0, i1, i2};
  bool reflex = false, polygon_across = false, below = true;
  const double threshold = kProve && proven ? -bound : 0;
  // While every edge met so far is proven, an edge to an earlier face g was proven by g's heights
  // (a triangle, as every face so far): strictly convex, so the far corner v of g lies strictly
  // below f's exact plane and its height here is below the bound; when that is within the
  // tolerance, the reflex test would pass and is skipped.
  const bool skip_earlier = kProve && proven && bound <= tolerance;
  for (int k = 0; k < 3; ++k) {
    const int g = across[k];
    if (skip_earlier && g < f) continue;
    const int gb = cycles.begin[g];
    if (cycles.begin[g + 1] - gb != 3) {
      polygon_across = true;
      continue;
    }
    const int* corners = cycles.vertex + gb;
    const int v = corners[0] != from[k] && corners[0] != to[k]   ? corners[0]
                  : corners[1] != from[k] && corners[1] != to[k] ? corners[1]
                                                                 : corners[2];
    if constexpr (kProve) {
      const double h = height(m.points[v]);
      reflex = reflex || !(h <= tolerance);
      below = below && h < threshold;
    } else {
      reflex = reflex || !(height(m.points[v]) <= tolerance);
    }
  }
  if constexpr (kProve) proven = proven && below && !polygon_across;
  if (polygon_across && !reflex) {
    const FacePlane plane{Point(q.cx, q.cy, q.cz), Point(q.nx, q.ny, q.nz)};
    for (int k = 0; k < 3 && !reflex; ++k)
      if (cycles.degree(across[k]) != 3)
        reflex = reflex_across(m, cycles, plane, across[k], from[k], to[k], tolerance);
  }
  any_reflex = reflex;
  return true;
}

// reflex_across() with the caller's height functions, for quad_passes: a triangle's or a
// quadrilateral's corners off the edge found without a loop (a quadrilateral's two in one pair).
// A quadrilateral g holds the edge as to -> from (the opposite halfedge); its corners off the
// edge are the two after `from`. When g repeats a vertex (so that these could differ from the
// loop's), g fails its own check in nondegenerate(), and that failure is the verdict whatever
// the reflex flag says. Always inlined: quad_passes() calls it four times a face, and GCC
// otherwise makes it a call.
[[gnu::always_inline]] inline bool reflex_across_small(const MeshView& m, const FaceCycles& cycles,
                                                       const PlaneHeight& height,
                                                       const PlaneHeights& heights, Pair tolerances,
                                                       int g, int from, int to, int guess,
                                                       double tolerance) {
  const int gb = cycles.begin[g];
  const int* corners = cycles.vertex + gb;
  const int n = cycles.begin[g + 1] - gb;
  // A quadrilateral of a grid whose faces all start at the same corner holds the edge at the
  // caller's guess (the position opposite the edge in the caller's face): no search then.
  if (n == 4 && corners[guess] == to && corners[(guess + 1) & 3] == from)
    return !both_at_most(
        heights(m.points[corners[(guess + 2) & 3]], m.points[corners[(guess + 3) & 3]]),
        tolerances);
  if (n == 3) {
    const int v = corners[0] != from && corners[0] != to   ? corners[0]
                  : corners[1] != from && corners[1] != to ? corners[1]
                                                           : corners[2];
    return !(height(m.points[v]) <= tolerance);
  }
  if (n == 4) {
    const int j = corners[0] == to ? 0 : corners[1] == to ? 1 : corners[2] == to ? 2 : 3;
    if (corners[(j + 1) & 3] == from && corners[j] == to)
      return !both_at_most(heights(m.points[corners[(j + 2) & 3]], m.points[corners[(j + 3) & 3]]),
                           tolerances);
  }
  for (int k = 0; k < n; ++k) {
    const int v = corners[k];
    if (v == from || v == to) continue;
    if (!(height(m.points[v]) <= tolerance)) return true;
  }
  return false;
}

// A quadrilateral's share of nondegenerate() (UV spheres and boxes are made of them), as
// triangle_passes: the same operations in the same order as newell_plane(), height(),
// FanVolumes::add_face() and reflex_across(), written out, so every value and verdict is
// the general path's. quad_plane() (or quad_planes(), two at once) returns ok false when the
// quadrilateral repeats a vertex or a position, and quad_passes() returns false, having changed
// nothing, then or when it has zero area: the general path then names the problem (a repeated
// vertex does not zero a quadrilateral's normal, so both are tested here).
[[gnu::always_inline]] inline bool quad_corners_distinct(const MeshView& m, const int* ids) {
  const int i0 = ids[0], i1 = ids[1], i2 = ids[2], i3 = ids[3];
  {
    // The usual case first: four pairwise different x coordinates make four different positions
    // (so four different vertices), told by three comparisons of pairs. Otherwise (two corners
    // with the same x, as a quadrilateral of a grid aligned with an axis has) the tests below.
    const double x0 = m.points[i0][0], x1 = m.points[i1][0], x2 = m.points[i2][0],
                 x3 = m.points[i3][0];
    if (!detail::any_equal(Pair{x0, x0}, Pair{x1, x2}, Pair{x0, x1}, Pair{x3, x2}, Pair{x1, x2},
                           Pair{x3, x3}))
      return true;
  }
  if (i0 == i1 || i0 == i2 || i0 == i3 || i1 == i2 || i1 == i3 || i2 == i3) return false;
  const Point &p0 = m.points[i0], &p1 = m.points[i1], &p2 = m.points[i2], &p3 = m.points[i3];
  return !(p0 == p1 || p0 == p2 || p0 == p3 || p1 == p2 || p1 == p3 || p2 == p3);
}

template <class T>
[[gnu::always_inline]] inline PlaneValues<T> quad_values(const Coords<T>& p0, const Coords<T>& p1,
                                                         const Coords<T>& p2, const Coords<T>& p3,
                                                         const Point& centre, bool unit) {
  // newell_plane(): the centroid summed from zero and scaled by 1.0 / 4 (exactly 0.25).
  const T cx = ((((0.0 + p0.x) + p1.x) + p2.x) + p3.x) * (1.0 / 4);
  const T cy = ((((0.0 + p0.y) + p1.y) + p2.y) + p3.y) * (1.0 / 4);
  const T cz = ((((0.0 + p0.z) + p1.z) + p2.z) + p3.z) * (1.0 / 4);
  // The corners relative to the centroid, and cross(u, v) summed over the edges a-b, b-q,
  // q-r, r-a from zero (component i: u[j] v[l] - u[l] v[j], (j, l) = (i + 1, i + 2) mod 3).
  const T ax = p0.x - cx, ay = p0.y - cy, az = p0.z - cz;
  const T bx = p1.x - cx, by = p1.y - cy, bz = p1.z - cz;
  const T qx = p2.x - cx, qy = p2.y - cy, qz = p2.z - cz;
  const T rx = p3.x - cx, ry = p3.y - cy, rz = p3.z - cz;
  const T nx = (((0.0 + (ay * bz - az * by)) + (by * qz - bz * qy)) + (qy * rz - qz * ry)) +
               (ry * az - rz * ay);
  const T ny = (((0.0 + (az * bx - ax * bz)) + (bz * qx - bx * qz)) + (qz * rx - qx * rz)) +
               (rz * ax - rx * az);
  const T nz = (((0.0 + (ax * by - ay * bx)) + (bx * qy - by * qx)) + (qx * ry - qy * rx)) +
               (rx * ay - ry * ax);
  T magnitude{};
  if (unit) {
    const T la = norm1_of(ax, ay, az), lb = norm1_of(bx, by, bz), lq = norm1_of(qx, qy, qz),
            lr = norm1_of(rx, ry, rz);
    magnitude = ((la * lb + lb * lq) + lq * lr) + lr * la;
  }
  // FanVolumes::add_face(): the fan from the last corner, tetrahedra (r, a, b), (r, b, q).
  const T first = six_volume(centre, p3, p0, p1), second = six_volume(centre, p3, p1, p2);
  const T length2 = (nx * nx + ny * ny) + nz * nz;
  return {cx, cy, cz, nx, ny, nz, first, second, length2, magnitude};
}

SmallPlane quad_plane(const MeshView& m, const int* ids, const Point& centre, bool unit) {
  if (!quad_corners_distinct(m, ids)) {
    SmallPlane q;
    q.ok = false;
    return q;
  }
  const Point* const P = m.points;
  return small_plane(quad_values(coords(P[ids[0]]), coords(P[ids[1]]), coords(P[ids[2]]),
                                 coords(P[ids[3]]), centre, unit),
                     4);
}

// quad_plane() of two quadrilaterals at once (a in lane 0, b in lane 1): the same values.
void quad_planes(const MeshView& m, const int* a, const int* b, const Point& centre, bool unit,
                 SmallPlane& qa, SmallPlane& qb) {
  if (!quad_corners_distinct(m, a) || !quad_corners_distinct(m, b)) {
    qa = quad_plane(m, a, centre, unit);
    qb = quad_plane(m, b, centre, unit);
    return;
  }
  const Point* const P = m.points;
  const PlaneValues<Pair> v =
      quad_values(coords(P[a[0]], P[b[0]]), coords(P[a[1]], P[b[1]]), coords(P[a[2]], P[b[2]]),
                  coords(P[a[3]], P[b[3]]), centre, unit);
  qa = small_plane(v, 0, 4);
  qb = small_plane(v, 1, 4);
}

bool quad_passes(const MeshView& m, const FaceCycles& cycles, int f, const SmallPlane& q,
                 double tolerance, bool convexity, FanVolumes& volumes, int& non_planar_face,
                 bool& any_reflex) {
  if (!q.ok) return false;
  volumes.total += q.first;
  volumes.absolute += std::abs(q.first);
  volumes.total += q.second;
  volumes.absolute += std::abs(q.second);
  const int b = cycles.begin[f];
  const int* ids = cycles.vertex + b;
  const int i0 = ids[0], i1 = ids[1], i2 = ids[2], i3 = ids[3];
  const Point &p0 = m.points[i0], &p1 = m.points[i1], &p2 = m.points[i2], &p3 = m.points[i3];
  // height(plane, p): dot(p - centroid, normal), summed in OpenMesh's order (a value, not a
  // closure over references: the calls below inline it).
  const PlaneHeight height{q.cx, q.cy, q.cz, q.nx, q.ny, q.nz};
  const PlaneHeights heights(height);
  const Pair tolerances{tolerance, tolerance};
  if (non_planar_face < 0 && !(both_at_most(pair_abs(heights(p0, p1)), tolerances) &&
                               both_at_most(pair_abs(heights(p2, p3)), tolerances)))
    non_planar_face = f;
  if (!convexity || any_reflex) return true;
  // Across the edge that ends at each corner (all four: the flag is the same, and the order
  // of the general path's early exit only decides where it stops).
  const int* across = cycles.across + b;
  any_reflex =
      reflex_across_small(m, cycles, height, heights, tolerances, across[0], i3, i0, 1, tolerance) |
      reflex_across_small(m, cycles, height, heights, tolerances, across[1], i0, i1, 2, tolerance) |
      reflex_across_small(m, cycles, height, heights, tolerances, across[2], i1, i2, 3, tolerance) |
      reflex_across_small(m, cycles, height, heights, tolerances, across[3], i2, i3, 0, tolerance);
  return true;
}

// Fills `geometry` for the later checks when the mesh passes; planarity is judged with
// `relative_tolerance` times the bounding-box diagonal. With `convexity` (only for a closed
// mesh), also whether any edge may be reflex, with each face's plane while it is at hand.
// `finite`: the caller has found every coordinate finite (the first test is skipped).
// `shortcuts`: triangles and quadrilaterals take their unrolled paths (off only in tests,
// which compare the two).
// kProveEdges: with geometry.unit, also whether the triangles' heights prove every edge strictly
// convex (geometry.edges_proven; without, none of this is compiled).
template <bool kProveEdges = false>
Finding nondegenerate(const MeshView& m, double relative_tolerance, Geometry& geometry,
                      bool convexity = false, bool finite = false, bool shortcuts = true) {
  for (int v = 0; v < m.n_vertices && !finite; ++v) {
    if (!m.live_vertex(v)) continue;
    const Point& p = m.points[v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      return fail(Verdict::invalid,
                  "vertex " + std::to_string(v) + " has a coordinate that is not finite");
  }
  geometry.extent = geometry.box ? extent_of(geometry.box->lo, geometry.box->hi) : bounding_box(m);
  const double diagonal = geometry.extent.diagonal;
  if (!(diagonal >= kMinSize && diagonal <= kMaxSize))
    return fail(Verdict::invalid, "the mesh's size (bounding-box diagonal " + number(diagonal) +
                                      ") is outside the supported range [" + number(kMinSize) +
                                      ", " + number(kMaxSize) + "]");
  const double tolerance = relative_tolerance * diagonal;
  if (!geometry.cycles.begin) geometry.cycles = face_cycles(m);  // unless the caller's
  const double zero_area = kZeroAreaRatio * diagonal * diagonal;
  // What the faces accumulate, kept in locals through the loop and stored at its end.
  FanVolumes volumes = geometry.volumes;
  int non_planar_face = geometry.non_planar_face;
  bool reflex = geometry.reflex;
  const Point centre = geometry.extent.centre;
  detail::UnitNormal* const unit = geometry.unit;
  bool unit_complete = geometry.unit_complete;
  // Every edge proven strictly convex by the triangles' heights (StrictBelow); any other face
  // leaves the edges to the caller.
  bool edges_proven = kProveEdges && unit && convexity && shortcuts;
  const StrictBelow strict(geometry.extent);
  // The faces in blocks: every live triangle's and quadrilateral's plane in the block first
  // (triangle_plane() and quad_plane() change nothing; only these faces' entries are read),
  // then each face's checks in order. Blocks, not every face's plane at once, keep the
  // scratch small (a plane per face was 31 MB for an operand of 327,680 triangles, and
  // stayed resident in the heap) at the same speed.
  constexpr int kPlaneBlock = 256;
  std::unique_ptr<SmallPlane[]> planes;
  if (shortcuts) planes.reset(new SmallPlane[std::min(m.n_faces, kPlaneBlock)]);
  for (int block = 0; block < m.n_faces; block += kPlaneBlock) {
    const int block_end = std::min(m.n_faces, block + kPlaneBlock);
    if (shortcuts) {
      // Two faces at once where two triangles or two quadrilaterals follow each other.
      for (int f = block; f < block_end; ++f) {
        SmallPlane& q = planes[f - block];
        const int n = geometry.cycles.degree(f);
        const bool two =
            f + 1 < block_end && geometry.cycles.degree(f + 1) == n && m.live_face(f + 1);
        if (n == 3 && m.live_face(f)) {
          if (two) {
            triangle_planes(m, geometry.cycles.corners(f), geometry.cycles.corners(f + 1), centre,
                            unit, q, planes[f + 1 - block]);
            ++f;
          } else {
            q = triangle_plane(m, geometry.cycles.corners(f), centre, unit);
          }
        } else if (n == 4 && m.live_face(f)) {
          if (two) {
            quad_planes(m, geometry.cycles.corners(f), geometry.cycles.corners(f + 1), centre, unit,
                        q, planes[f + 1 - block]);
            ++f;
          } else {
            q = quad_plane(m, geometry.cycles.corners(f), centre, unit);
          }
        } else {
          q.ok = false;
        }
      }
      for (int f = block; f < block_end; ++f)
        plane_root(planes[f - block], zero_area, unit ? unit + f : nullptr, unit_complete);
    }
    for (int f = block; f < block_end; ++f) {
      if (!m.live_face(f)) continue;
      const int n = geometry.cycles.degree(f);
      if (n == 3 && shortcuts &&
          triangle_passes<kProveEdges>(m, geometry.cycles, f, planes[f - block], tolerance,
                                       convexity, volumes, non_planar_face, reflex, unit, strict,
                                       edges_proven))
        continue;
      if constexpr (kProveEdges) edges_proven = false;
      if (n == 4 && shortcuts &&
          quad_passes(m, geometry.cycles, f, planes[f - block], tolerance, convexity, volumes,
                      non_planar_face, reflex))
        continue;
      const int* ids = geometry.cycles.corners(f);
      const auto face = [&] { return "face " + std::to_string(f); };
      if (n < 3)
        return fail(Verdict::invalid,
                    face() + " has " + std::to_string(n) + " vertices; a face needs at least 3");
      if (has_equal_pair(n, [&](int i) { return ids[i]; })) {
        std::vector<int> sorted(ids, ids + n);
        std::sort(sorted.begin(), sorted.end());
        const auto twice = std::adjacent_find(sorted.begin(), sorted.end());
        return fail(Verdict::invalid,
                    face() + " uses vertex " + std::to_string(*twice) + " more than once");
      }
      FacePlane plane = newell_plane(m.points, ids, n);
      if (has_equal_pair(n, [&](int i) -> const Point& { return m.points[ids[i]]; }))
        return fail(Verdict::invalid, face() + " has two vertices at the same position");
      const double length = plane.normal.norm();
      if (!(length > zero_area)) {
        double longest = 0;  // squared
        for (int k = 0; k < n; ++k)
          longest = std::max(longest, (m.points[ids[k]] - m.points[ids[(k + 1) % n]]).sqrnorm());
        if (!(length > kZeroAreaRatio * diagonal * std::sqrt(longest)))
          return fail(Verdict::invalid, face() + " has zero area (its vertices are collinear)");
      }
      if (unit) {
        // The corners relative to the centroid, as newell_plane() computed them.
        double magnitude = 0, first = 0, previous = 0;
        for (int k = 0; k < n; ++k) {
          const Point a = m.points[ids[k]] - plane.centroid;
          const double l = norm1(a[0], a[1], a[2]);
          if (k == 0)
            first = l;
          else
            magnitude += previous * l;
          previous = l;
        }
        magnitude += previous * first;
        unit_normal(unit[f], plane.normal[0], plane.normal[1], plane.normal[2], length,
                    1.0 / length, magnitude, n, unit_complete);
      }
      plane.normal *= 1.0 / length;
      volumes.add_face(m.points, ids, n, centre);
      for (int k = 0; k < n && non_planar_face < 0; ++k)
        if (!(std::abs(height(plane, m.points[ids[k]])) <= tolerance)) non_planar_face = f;
      if (convexity && !reflex) {
        const int* across = geometry.cycles.across + geometry.cycles.begin[f];
        for (int k = 0; k < n && !reflex; ++k)
          reflex = reflex_across(m, geometry.cycles, plane, across[k], ids[k == 0 ? n - 1 : k - 1],
                                 ids[k], tolerance);
      }
    }
  }
  geometry.volumes = volumes;
  geometry.non_planar_face = non_planar_face;
  geometry.reflex = reflex;
  geometry.unit_complete = unit_complete;
  geometry.edges_proven = edges_proven;
  return {};
}

Finding outward(const FanVolumes& volumes) {
  // OpenMesh links the two halfedges of every edge in opposite directions, so the faces
  // of a closed mesh are consistently oriented by construction; what remains is the sign.
  const double volume = volumes.total / 6;
  if (!(std::abs(volume) > kFlatVolumeRatio * (volumes.absolute / 6)))
    return fail(Verdict::invalid,
                "the mesh encloses no volume (signed volume " + number(volume) + "): it is flat");
  if (volume < 0)
    return {Verdict::inverted,
            "the faces are oriented inwards (signed volume " + number(volume) + " < 0)", volume};
  return {Verdict::ok, {}, volume};
}

// Planarity, then edge convexity (both found by nondegenerate(); here the first offender
// in the rule's order is named).
Finding planar_and_convex(const MeshView& m, double relative_tolerance, const Geometry& geometry) {
  const double tolerance = relative_tolerance * geometry.extent.diagonal;
  const FaceCycles& cycles = geometry.cycles;
  if (const int f = geometry.non_planar_face; f >= 0) {
    const FacePlane plane = unit_plane(m, cycles, f);
    const int* corners = cycles.corners(f);
    int k = 0;
    while (std::abs(height(plane, m.points[corners[k]])) <= tolerance) ++k;
    return fail(Verdict::not_convex, "face " + std::to_string(f) + " is not planar: vertex " +
                                         std::to_string(corners[k]) + " is " +
                                         number(std::abs(height(plane, m.points[corners[k]]))) +
                                         " from its plane (tolerance " + number(tolerance) + ")");
  }
  if (!geometry.reflex) return {};
  for (int e = 0; e < m.n_edges; ++e) {
    if (!m.live_edge(e)) continue;
    for (int side = 0; side < 2; ++side) {
      const int h = 2 * e + side;
      const int f = m.face(h), g = m.face(h ^ 1);
      const FacePlane plane = unit_plane(m, cycles, f);
      // The edge's own vertices belong to f and passed the planarity check: their height
      // is at most the tolerance, so only g's other vertices can fail.
      const int from = m.from(h), to = m.to(h);
      const int* corners = cycles.corners(g);
      for (int k = 0; k < cycles.degree(g); ++k) {
        const int v = corners[k];
        if (v == from || v == to) continue;
        const double above = height(plane, m.points[v]);
        if (!(above <= tolerance))
          return fail(Verdict::not_convex,
                      "edge " + std::to_string(e) + " (vertices " + vertex_pair(m, e) +
                          ") is reflex: vertex " + std::to_string(v) + " of face " +
                          std::to_string(g) + " is " + number(above) + " above the plane of face " +
                          std::to_string(f) + " (tolerance " + number(tolerance) + ")");
      }
    }
  }
  return {};
}

// The full rule; stops at the first problem. An inverted mesh is reported as such
// before the geometric checks (which assume outward normals).
Finding convex_polyhedron(const Mesh& mesh, double relative_tolerance, bool shortcuts = true) {
  const MeshView m(mesh);
  if (Finding found = closed_manifold(m); found.verdict != Verdict::ok) return found;
  Geometry geometry;
  if (Finding found = nondegenerate(m, relative_tolerance, geometry, true, false, shortcuts);
      found.verdict != Verdict::ok)
    return found;
  if (Finding found = outward(geometry.volumes); found.verdict != Verdict::ok) return found;
  return planar_and_convex(m, relative_tolerance, geometry);
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

CheckResult check_closed_manifold(const Mesh& mesh) {
  return to_result(closed_manifold(MeshView(mesh)));
}

CheckResult check_outward_oriented(const Mesh& mesh) {
  const MeshView m(mesh);
  if (Finding found = closed_manifold(m); found.verdict != Verdict::ok)
    return {"orientation is undefined: " + found.problem, {}};
  return to_result(outward(fan_volumes(m, face_cycles(m), bounding_box(m).centre)));
}

CheckResult check_nondegenerate(const Mesh& mesh) {
  Geometry geometry;
  return to_result(nondegenerate(MeshView(mesh), kPlanarityTolerance, geometry));
}

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

namespace {

// A Geometry to be filled, on the caller's face cycles.
Geometry on_cycles(const FaceCycleView& cycles) {
  Geometry geometry;
  geometry.cycles.begin = cycles.begin;
  geometry.cycles.vertex = cycles.vertex;
  geometry.cycles.across = cycles.across;
  return geometry;
}

// geometry_passes() once `geometry` holds the face cycles.
// `prove_edges`: see nondegenerate (worth it only when every face is a triangle).
bool geometry_of_cycles_passes(const MeshView& m, Geometry& geometry, double planarity_tolerance,
                               bool prove_edges = false) {
  const Finding found = prove_edges
                            ? nondegenerate<true>(m, planarity_tolerance, geometry, true, true)
                            : nondegenerate(m, planarity_tolerance, geometry, true, true);
  if (found.verdict != Verdict::ok) return false;
  if (outward(geometry.volumes).verdict != Verdict::ok) return false;
  // A reflex flag means planar_and_convex() finds a reflex edge (the same test on the same
  // face, edge and vertex): no need to look for it.
  return geometry.non_planar_face < 0 && !geometry.reflex;
}

}  // namespace

bool geometry_passes(const Mesh& mesh, const FaceCycleView& cycles, double planarity_tolerance) {
  // convex_polyhedron() after closed_manifold(), on the caller's cycles: the same checks on
  // the same values, without building the messages of a failure.
  const MeshView m(mesh, true);  // the caller's precondition
  Geometry geometry = on_cycles(cycles);
  return geometry_of_cycles_passes(m, geometry, planarity_tolerance);
}

bool geometry_passes(const Mesh& mesh, const FaceCycleView& cycles, UnitNormal* unit_normals,
                     bool& complete, bool& edges_convex, const PointBox* box) {
  const MeshView m(mesh, true);  // the caller's precondition
  Geometry geometry = on_cycles(cycles);
  geometry.unit = unit_normals;
  geometry.box = box;
  // The proof needs every face a triangle (it gives up at any other): only then is it tried.
  const bool triangles = cycles.begin[m.n_faces] == 3LL * m.n_faces;
  const bool passes = geometry_of_cycles_passes(m, geometry, kPlanarityTolerance, triangles);
  complete = geometry.unit_complete;
  edges_convex = geometry.edges_proven;
  return passes;
}

std::string convex_polyhedron_problem(const Mesh& mesh, double planarity_tolerance,
                                      bool shortcuts) {
  return convex_polyhedron(mesh, planarity_tolerance, shortcuts).problem;
}

bool geometry_passes(const Mesh& mesh, double planarity_tolerance) {
  // The same on check_operand's own face cycles, read here; safe on any mesh the caller
  // describes (the geometric checks follow only links to faces).
  const MeshView m(mesh, true);
  Geometry geometry;
  try {
    geometry.cycles = face_cycles(m);
  } catch (const error&) {  // a face that is not a closed cycle
    return false;
  }
  const int corners = geometry.cycles.begin[m.n_faces];
  if (std::any_of(geometry.cycles.across, geometry.cycles.across + corners,
                  [](int g) { return g < 0; }))
    return false;  // an edge with one face: the mesh is open
  return geometry_of_cycles_passes(m, geometry, planarity_tolerance);
}

}  // namespace detail

double signed_volume(const Mesh& mesh) {
  const MeshView m(mesh);
  return fan_volumes(m, face_cycles(m), bounding_box(m).centre).total / 6;
}

}  // namespace morph
