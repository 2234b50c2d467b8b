// The oracle's exact machinery (CGAL). See oracle.h.
#include "support/oracle.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "support/polytopes.h"

namespace morph::test {
namespace {

using EK = CGAL::Epeck;  // exact constructions: hulls of exact sums
using IK = CGAL::Epick;  // exact predicates on double points: mesh checks
using EPoint = EK::Point_3;
using IPoint = IK::Point_3;
using Q = CGAL::Exact_rational;
using HullMesh = CGAL::Surface_mesh<EPoint>;

static_assert(std::is_same_v<CGAL::Exact_rational, std::decay_t<decltype(CGAL::exact(EK::FT()))>>,
              "Epeck's exact number type is expected to be CGAL::Exact_rational");

// ---------------------------------------------------------------------------------------
// Rounding

bool mantissa_even(double x) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &x, sizeof bits);
  return (bits & 1u) == 0;
}

// The double nearest to q (ties to even), as IEEE arithmetic rounds. CGAL::to_double
// does not promise this, so bracket q between two doubles and bisect exactly.
double round_nearest(const Q& q) {
  auto [lo, hi] = CGAL::to_interval(q);
  if (lo == hi) return lo;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  while (std::nextafter(lo, kInf) != hi) {
    const double mid = lo + (hi - lo) / 2;
    if (mid <= lo || mid >= hi) break;
    if (q < Q(mid)) {
      hi = mid;
    } else {
      lo = mid;
    }
  }
  if (Q(lo) == q) return lo;
  if (Q(hi) == q) return hi;
  const Q midpoint = (Q(lo) + Q(hi)) / Q(2);
  if (q < midpoint) return lo;
  if (q > midpoint) return hi;
  return mantissa_even(lo) ? lo : hi;
}

Position rounded(const EPoint& p) {
  return {round_nearest(CGAL::exact(p.x())), round_nearest(CGAL::exact(p.y())),
          round_nearest(CGAL::exact(p.z()))};
}

Position position(const Point& p) { return {p[0], p[1], p[2]}; }

bool representable(const EPoint& p) {
  const Position r = rounded(p);
  return Q(r[0]) == CGAL::exact(p.x()) && Q(r[1]) == CGAL::exact(p.y()) &&
         Q(r[2]) == CGAL::exact(p.z());
}

// The plane of a polygon by Newell's normal through its centroid; zero normal when the
// polygon has no area.
Plane newell_plane(const std::vector<Point>& p) {
  Point n(0, 0, 0), centroid(0, 0, 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Point& a = p[i];
    const Point& b = p[(i + 1) % p.size()];
    n += Point((a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]),
               (a[0] - b[0]) * (a[1] + b[1]));
    centroid += a;
  }
  centroid /= static_cast<double>(p.size());
  const double len = n.norm();
  if (len > 0) n /= len;
  return {{n[0], n[1], n[2]}, OpenMesh::dot(n, centroid)};
}

double signed_distance(const Plane& h, const Point& p) {
  return h.normal[0] * p[0] + h.normal[1] * p[1] + h.normal[2] * p[2] - h.offset;
}

// ---------------------------------------------------------------------------------------
// Exact convex hull with polygon facets

struct ExactHull {
  std::vector<EPoint> points;            // extreme points only
  std::vector<std::vector<int>> facets;  // cyclic, counter-clockwise from outside
  std::vector<Plane> planes;             // approximate, one per facet
  Q volume;
};

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

// 3 when the points span a solid, else their affine dimension (-1 when empty).
template <class P>
int affine_dimension(const std::vector<P>& pts) {
  if (pts.empty()) return -1;
  std::size_t i1 = 0;
  while (i1 < pts.size() && pts[i1] == pts[0]) ++i1;
  if (i1 == pts.size()) return 0;
  std::size_t i2 = 0;
  while (i2 < pts.size() && CGAL::collinear(pts[0], pts[i1], pts[i2])) ++i2;
  if (i2 == pts.size()) return 1;
  for (const P& p : pts) {
    if (!CGAL::coplanar(pts[0], pts[i1], pts[i2], p)) return 3;
  }
  return 2;
}

Plane approximate_plane(const EK::Plane_3& plane, const EPoint& on) {
  // Epeck's to_double is the centre of a lazy interval, which can be wide after a long
  // construction: round the exact values instead.
  const auto v = plane.orthogonal_vector();
  double n[3] = {CGAL::to_double(CGAL::exact(v.x())), CGAL::to_double(CGAL::exact(v.y())),
                 CGAL::to_double(CGAL::exact(v.z()))};
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  Plane out;
  for (int k = 0; k < 3; ++k) out.normal[k] = n[k] / len;
  out.offset = out.normal[0] * CGAL::to_double(CGAL::exact(on.x())) +
               out.normal[1] * CGAL::to_double(CGAL::exact(on.y())) +
               out.normal[2] * CGAL::to_double(CGAL::exact(on.z()));
  return out;
}

ExactHull exact_hull(const std::vector<EPoint>& input) {
  if (affine_dimension(input) != 3)
    throw std::invalid_argument("exact_hull: points do not span a solid");
  HullMesh sm;
  CGAL::convex_hull_3(input.begin(), input.end(), sm);

  // Group exactly coplanar adjacent triangles.
  UnionFind groups(sm.number_of_faces());
  for (auto e : sm.edges()) {
    const auto h = sm.halfedge(e);
    const auto f = sm.face(h);
    const auto g = sm.face(sm.opposite(h));
    const auto far = sm.target(sm.next(sm.opposite(h)));
    if (CGAL::coplanar(sm.point(sm.source(h)), sm.point(sm.target(h)),
                       sm.point(sm.target(sm.next(h))), sm.point(far))) {
      groups.unite(static_cast<int>(f.idx()), static_cast<int>(g.idx()));
    }
  }

  // A hull point is a vertex of the polytope iff it touches >= 3 facet groups.
  std::vector<int> new_index(sm.number_of_vertices(), -1);
  ExactHull hull;
  for (auto v : sm.vertices()) {
    std::set<int> around;
    for (auto f : CGAL::faces_around_target(sm.halfedge(v), sm))
      around.insert(groups.find(f.idx()));
    if (around.size() >= 3) {
      new_index[v.idx()] = static_cast<int>(hull.points.size());
      hull.points.push_back(sm.point(v));
    }
  }

  // Each group's boundary is one cycle (a convex polygon); walk it.
  std::map<int, std::map<int, int>> boundary;  // group -> source vertex -> target vertex
  std::map<int, EK::Plane_3> group_plane;
  std::map<int, EPoint> group_point;
  for (auto h : sm.halfedges()) {
    const int g = groups.find(sm.face(h).idx());
    if (!group_plane.count(g)) {
      group_plane.emplace(g, EK::Plane_3(sm.point(sm.source(h)), sm.point(sm.target(h)),
                                         sm.point(sm.target(sm.next(h)))));
      group_point.emplace(g, sm.point(sm.source(h)));
    }
    if (groups.find(sm.face(sm.opposite(h)).idx()) != g) {
      boundary[g][static_cast<int>(sm.source(h).idx())] = static_cast<int>(sm.target(h).idx());
    }
  }
  for (auto& [g, next] : boundary) {
    std::vector<int> cycle;
    const int start = next.begin()->first;
    int v = start;
    do {
      if (new_index[v] >= 0) cycle.push_back(new_index[v]);
      v = next.at(v);
      if (cycle.size() > next.size())
        throw std::logic_error("exact_hull: facet boundary is not a cycle");
    } while (v != start);
    hull.facets.push_back(std::move(cycle));
    hull.planes.push_back(approximate_plane(group_plane.at(g), group_point.at(g)));
  }

  hull.volume = Q(0);
  for (auto f : sm.faces()) {
    std::vector<const EPoint*> p;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) p.push_back(&sm.point(v));
    const Q x0 = CGAL::exact(p[0]->x()), y0 = CGAL::exact(p[0]->y()), z0 = CGAL::exact(p[0]->z());
    const Q x1 = CGAL::exact(p[1]->x()), y1 = CGAL::exact(p[1]->y()), z1 = CGAL::exact(p[1]->z());
    const Q x2 = CGAL::exact(p[2]->x()), y2 = CGAL::exact(p[2]->y()), z2 = CGAL::exact(p[2]->z());
    hull.volume += x0 * (y1 * z2 - z1 * y2) - y0 * (x1 * z2 - z1 * x2) + z0 * (x1 * y2 - y1 * x2);
  }
  hull.volume /= Q(6);
  return hull;
}

Description describe_hull(const ExactHull& hull) {
  Description d;
  std::vector<Position> pos;
  pos.reserve(hull.points.size());
  for (const EPoint& p : hull.points) pos.push_back(rounded(p));
  d.vertices = pos;
  std::sort(d.vertices.begin(), d.vertices.end());
  std::vector<std::pair<std::vector<Position>, Plane>> facets;
  std::size_t degrees = 0;
  for (std::size_t f = 0; f < hull.facets.size(); ++f) {
    std::vector<Position> facet;
    for (int v : hull.facets[f]) facet.push_back(pos[v]);
    std::sort(facet.begin(), facet.end());
    degrees += facet.size();
    facets.emplace_back(std::move(facet), hull.planes[f]);
  }
  std::sort(facets.begin(), facets.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [facet, plane] : facets) {
    d.facets.push_back(std::move(facet));
    d.planes.push_back(plane);
  }
  d.vertex_count = d.vertices.size();
  d.facet_count = d.facets.size();
  d.edge_count = degrees / 2;
  d.volume = round_nearest(hull.volume);
  d.exact_positions = std::all_of(hull.points.begin(), hull.points.end(), representable);
  return d;
}

// ---------------------------------------------------------------------------------------
// Exact half-space intersection (double description)

struct QVec {
  Q x, y, z;
};
QVec sub(const QVec& a, const QVec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
QVec cross(const QVec& a, const QVec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Q dot(const QVec& a, const QVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
bool is_zero(const QVec& a) {
  return CGAL::is_zero(a.x) && CGAL::is_zero(a.y) && CGAL::is_zero(a.z);
}
QVec qvec(const Point& p) { return {Q(p[0]), Q(p[1]), Q(p[2])}; }

struct QPlane {  // n.x <= d
  QVec n;
  Q d;
};

// Scale so that the first non-zero normal coordinate is +-1: equal half-spaces compare equal.
QPlane normalized(QPlane h) {
  const Q& lead = !CGAL::is_zero(h.n.x) ? h.n.x : !CGAL::is_zero(h.n.y) ? h.n.y : h.n.z;
  const Q s = CGAL::abs(lead);
  h.n = {h.n.x / s, h.n.y / s, h.n.z / s};
  h.d /= s;
  return h;
}
bool same(const QPlane& a, const QPlane& b) {
  return a.n.x == b.n.x && a.n.y == b.n.y && a.n.z == b.n.z && a.d == b.d;
}

struct DDVertex {
  QVec p;
  std::vector<int> tight;  // sorted ids of the planes through p
};

int normal_rank(const std::vector<int>& ids, const std::vector<QPlane>& planes) {
  if (ids.empty()) return 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    for (std::size_t j = i + 1; j < ids.size(); ++j) {
      const QVec c = cross(planes[ids[i]].n, planes[ids[j]].n);
      if (is_zero(c)) continue;
      for (int k : ids) {
        if (!CGAL::is_zero(dot(c, planes[k].n))) return 3;
      }
      return 2;
    }
  }
  return 1;
}

// Outward plane of a face of A through three of its vertices, chosen far apart (for an
// exactly planar face any non-collinear triple gives the same plane).
QPlane face_plane(const Mesh& A, Mesh::FaceHandle f) {
  std::vector<Point> p;
  for (auto v : A.fv_range(f)) p.push_back(A.point(v));
  std::size_t bi = 1, bj = 2;
  double best = -1;
  for (std::size_t i = 1; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const double a = OpenMesh::cross(p[i] - p[0], p[j] - p[0]).sqrnorm();
      if (a > best) best = a, bi = i, bj = j;
    }
  }
  const QVec q0 = qvec(p[0]);
  const QVec n = cross(sub(qvec(p[bi]), q0), sub(qvec(p[bj]), q0));
  if (is_zero(n)) throw std::invalid_argument("exact_erosion: a face of A has zero area");
  return {n, dot(n, q0)};
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Public

std::vector<std::size_t> Description::facet_degrees() const {
  std::vector<std::size_t> out;
  for (const auto& f : facets) out.push_back(f.size());
  std::sort(out.begin(), out.end());
  return out;
}

Mesh convex_hull_mesh(const std::vector<Point>& points) {
  std::vector<EPoint> pts;
  pts.reserve(points.size());
  for (const Point& p : points) pts.emplace_back(p[0], p[1], p[2]);
  const ExactHull hull = exact_hull(pts);
  std::vector<Point> out;
  for (const EPoint& p : hull.points) {
    // Input points are doubles, so the conversion is exact.
    out.emplace_back(CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z()));
  }
  return mesh_from_polygons(out, hull.facets);
}

Description exact_hull_of_sums(const Mesh& A, const Mesh& B) {
  std::vector<EPoint> sums;
  sums.reserve(A.n_vertices() * B.n_vertices());
  for (auto va : A.vertices()) {
    const Point& a = A.point(va);
    for (auto vb : B.vertices()) {
      const Point& b = B.point(vb);
      sums.emplace_back(EK::FT(Q(a[0]) + Q(b[0])), EK::FT(Q(a[1]) + Q(b[1])),
                        EK::FT(Q(a[2]) + Q(b[2])));
    }
  }
  return describe_hull(exact_hull(sums));
}

Description describe(const Mesh& mesh) {
  Description d;
  for (auto v : mesh.vertices()) d.vertices.push_back(position(mesh.point(v)));
  std::sort(d.vertices.begin(), d.vertices.end());
  std::vector<std::pair<std::vector<Position>, Plane>> facets;
  std::size_t degrees = 0;
  double volume = 0.0;
  for (auto f : mesh.faces()) {
    std::vector<Point> p;
    for (auto v : mesh.fv_range(f)) p.push_back(mesh.point(v));
    for (std::size_t i = 1; i + 1 < p.size(); ++i)
      volume += OpenMesh::dot(p[0], OpenMesh::cross(p[i], p[i + 1]));
    Plane plane = newell_plane(p);
    {
      // Newell's vector is twice the area; below ~1e-12 of the face's extent squared its
      // direction is rounding noise (a degenerate face, reported by the clean check).
      Point lo = p[0], hi = p[0];
      for (const Point& q : p) lo.minimize(q), hi.maximize(q);
      Point n(0, 0, 0);
      for (std::size_t i = 0; i < p.size(); ++i) n += OpenMesh::cross(p[i], p[(i + 1) % p.size()]);
      plane.reliable = n.norm() > 1e-12 * (hi - lo).sqrnorm();
    }
    std::vector<Position> facet;
    for (const Point& q : p) facet.push_back(position(q));
    std::sort(facet.begin(), facet.end());
    degrees += facet.size();
    facets.emplace_back(std::move(facet), plane);
  }
  std::sort(facets.begin(), facets.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [facet, plane] : facets) {
    d.facets.push_back(std::move(facet));
    d.planes.push_back(plane);
  }
  d.vertex_count = mesh.n_vertices();
  d.facet_count = mesh.n_faces();
  d.edge_count = degrees / 2;
  d.volume = volume / 6.0;
  return d;
}

namespace {

// The exact vertices of A (-) B (empty when B fits nowhere).
std::vector<EPoint> erosion_points(const Mesh& A, const Mesh& B) {
  if (A.n_vertices() == 0 || B.n_vertices() == 0)
    throw std::invalid_argument("exact_erosion: empty operand");
  std::vector<QVec> b_points;
  for (auto v : B.vertices()) b_points.push_back(qvec(B.point(v)));

  // A bounding box far larger than A, then A's moved planes (distinct ones).
  Point lo = A.point(*A.vertices_begin()), hi = lo;
  for (auto v : A.vertices()) {
    lo.minimize(A.point(v));
    hi.maximize(A.point(v));
  }
  const double margin = (hi - lo).norm() + 1.0;
  const QVec qlo = qvec(lo - Point(margin, margin, margin)),
             qhi = qvec(hi + Point(margin, margin, margin));
  std::vector<QPlane> planes = {
      normalized({{Q(-1), Q(0), Q(0)}, -qlo.x}), normalized({{Q(1), Q(0), Q(0)}, qhi.x}),
      normalized({{Q(0), Q(-1), Q(0)}, -qlo.y}), normalized({{Q(0), Q(1), Q(0)}, qhi.y}),
      normalized({{Q(0), Q(0), Q(-1)}, -qlo.z}), normalized({{Q(0), Q(0), Q(1)}, qhi.z})};
  const int box_planes = 6;
  for (auto f : A.faces()) {
    QPlane h = face_plane(A, f);
    Q support = dot(h.n, b_points[0]);
    for (const QVec& b : b_points) support = CGAL::max(support, dot(h.n, b));
    h.d -= support;
    h = normalized(h);
    if (std::none_of(planes.begin(), planes.end(), [&](const QPlane& g) { return same(g, h); }))
      planes.push_back(h);
  }

  std::vector<DDVertex> verts;
  for (int corner = 0; corner < 8; ++corner) {
    DDVertex v;
    v.p = {corner & 1 ? qhi.x : qlo.x, corner & 2 ? qhi.y : qlo.y, corner & 4 ? qhi.z : qlo.z};
    v.tight = {corner & 1 ? 1 : 0, corner & 2 ? 3 : 2, corner & 4 ? 5 : 4};
    verts.push_back(std::move(v));
  }

  for (int id = box_planes; id < static_cast<int>(planes.size()) && !verts.empty(); ++id) {
    const QPlane& h = planes[id];
    std::vector<Q> value;
    std::vector<int> sign;
    bool any_out = false;
    for (const DDVertex& v : verts) {
      value.push_back(dot(h.n, v.p) - h.d);
      sign.push_back(CGAL::sign(value.back()));
      any_out = any_out || sign.back() > 0;
    }
    std::vector<DDVertex> next;
    for (std::size_t i = 0; i < verts.size(); ++i) {
      if (sign[i] > 0) continue;
      DDVertex v = verts[i];
      if (sign[i] == 0) v.tight.push_back(id);  // ids grow, so `tight` stays sorted
      next.push_back(std::move(v));
    }
    if (any_out) {
      for (std::size_t i = 0; i < verts.size(); ++i) {
        if (sign[i] >= 0) continue;
        for (std::size_t j = 0; j < verts.size(); ++j) {
          if (sign[j] <= 0) continue;
          std::vector<int> common;
          std::set_intersection(verts[i].tight.begin(), verts[i].tight.end(),
                                verts[j].tight.begin(), verts[j].tight.end(),
                                std::back_inserter(common));
          if (common.size() < 2 || normal_rank(common, planes) != 2) continue;  // not an edge
          const Q t = value[i] / (value[i] - value[j]);
          const QVec& u = verts[i].p;
          const QVec& w = verts[j].p;
          DDVertex nv;
          nv.p = {u.x + t * (w.x - u.x), u.y + t * (w.y - u.y), u.z + t * (w.z - u.z)};
          nv.tight = std::move(common);
          nv.tight.push_back(id);
          next.push_back(std::move(nv));
        }
      }
    }
    verts = std::move(next);
  }

  std::vector<EPoint> pts;
  for (const DDVertex& v : verts) {
    if (v.tight.front() < box_planes)
      throw std::logic_error("exact_erosion: result touches the bounding box");
    pts.emplace_back(EK::FT(v.p.x), EK::FT(v.p.y), EK::FT(v.p.z));
  }
  return pts;
}

}  // namespace

ExactSet exact_erosion(const Mesh& A, const Mesh& B) {
  const std::vector<EPoint> pts = erosion_points(A, B);
  ExactSet out;
  for (const EPoint& p : pts) out.vertices.push_back(rounded(p));
  std::sort(out.vertices.begin(), out.vertices.end());
  out.dimension = affine_dimension(pts);
  if (out.dimension == 3) out.description = describe_hull(exact_hull(pts));
  return out;
}

ExactSet exact_opening(const Mesh& A, const Mesh& B) {
  const std::vector<EPoint> pts = erosion_points(A, B);
  ExactSet out;
  out.dimension = affine_dimension(pts);
  if (out.dimension < 0) return out;
  std::vector<EPoint> sums;
  for (const EPoint& p : pts) {
    for (auto vb : B.vertices()) {
      const Point& b = B.point(vb);
      sums.emplace_back(p.x() + EK::FT(b[0]), p.y() + EK::FT(b[1]), p.z() + EK::FT(b[2]));
    }
  }
  const ExactHull hull = exact_hull(sums);
  for (const EPoint& p : hull.points) out.vertices.push_back(rounded(p));
  std::sort(out.vertices.begin(), out.vertices.end());
  if (out.dimension == 3) out.description = describe_hull(hull);
  return out;
}

namespace {

std::string text(const Position& p) {
  std::ostringstream s;
  s.precision(17);
  s << "(" << p[0] << ", " << p[1] << ", " << p[2] << ")";
  return s.str();
}

std::string first_difference(const std::vector<Position>& got, const std::vector<Position>& want) {
  std::vector<Position> extra, missing;
  std::set_difference(got.begin(), got.end(), want.begin(), want.end(), std::back_inserter(extra));
  std::set_difference(want.begin(), want.end(), got.begin(), got.end(),
                      std::back_inserter(missing));
  std::ostringstream s;
  if (!extra.empty()) s << extra.size() << " unexpected, e.g. " << text(extra.front()) << "; ";
  if (!missing.empty()) s << missing.size() << " missing, e.g. " << text(missing.front());
  return s.str();
}

bool volume_close(double got, double want, double rel) {
  return std::abs(got - want) <= rel * std::max(std::abs(want), std::numeric_limits<double>::min());
}

double excess(const Position& v, const std::vector<Plane>& planes) {
  double worst = -std::numeric_limits<double>::infinity();
  for (const Plane& h : planes) {
    if (h.reliable)
      worst =
          std::max(worst, h.normal[0] * v[0] + h.normal[1] * v[1] + h.normal[2] * v[2] - h.offset);
  }
  return worst;
}

}  // namespace

std::string compare_exact(const Description& got, const Description& want, double volume_rel_tol) {
  std::ostringstream s;
  s.precision(17);
  if (got.vertex_count != want.vertex_count || got.facet_count != want.facet_count ||
      got.edge_count != want.edge_count) {
    s << "counts V/E/F " << got.vertex_count << "/" << got.edge_count << "/" << got.facet_count
      << ", expected " << want.vertex_count << "/" << want.edge_count << "/" << want.facet_count
      << ". ";
  }
  if (got.vertices != want.vertices)
    s << "vertices differ: " << first_difference(got.vertices, want.vertices) << ". ";
  if (got.facets != want.facets) {
    std::vector<std::vector<Position>> extra, missing;
    std::set_difference(got.facets.begin(), got.facets.end(), want.facets.begin(),
                        want.facets.end(), std::back_inserter(extra));
    std::set_difference(want.facets.begin(), want.facets.end(), got.facets.begin(),
                        got.facets.end(), std::back_inserter(missing));
    s << "facets differ: " << extra.size() << " unexpected, " << missing.size() << " missing";
    if (!missing.empty())
      s << " (e.g. a " << missing.front().size() << "-gon at " << text(missing.front().front())
        << ")";
    s << ". ";
  }
  if (!volume_close(got.volume, want.volume, volume_rel_tol)) {
    s << "volume " << got.volume << ", expected " << want.volume << ". ";
  }
  return s.str();
}

double max_excess(const Description& inner, const Description& outer) {
  double worst = -std::numeric_limits<double>::infinity();
  for (const Position& v : inner.vertices) worst = std::max(worst, excess(v, outer.planes));
  return worst;
}

std::string compare_close(const Description& got, const Description& want, double dist_tol,
                          double volume_rel_tol) {
  std::ostringstream s;
  s.precision(17);
  if (got.vertices.empty() || want.vertices.empty()) {
    if (got.vertices.size() != want.vertices.size()) s << "one of the bodies is empty. ";
    return s.str();
  }
  const double out = max_excess(got, want);
  const double in = max_excess(want, got);
  if (out > dist_tol) s << "a vertex lies " << out << " outside the expected body. ";
  if (in > dist_tol) s << "an expected vertex lies " << in << " outside the body. ";
  if (!volume_close(got.volume, want.volume, volume_rel_tol)) {
    s << "volume " << got.volume << ", expected " << want.volume << ". ";
  }
  return s.str();
}

std::string subresolution_feature(const Description& d, double tol) {
  auto sub = [](const Position& a, const Position& b) {
    return Position{a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  };
  auto dot3 = [](const Position& a, const Position& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  };
  auto length = [&](const Position& a) { return std::sqrt(dot3(a, a)); };
  std::map<Position, std::vector<std::size_t>> facets_at;
  for (std::size_t f = 0; f < d.facets.size(); ++f)
    for (const Position& p : d.facets[f]) facets_at[p].push_back(f);
  // Close vertices are found through a grid of cells of size tol.
  std::map<std::array<long long, 3>, std::vector<Position>> grid;
  for (const Position& p : d.vertices) {
    const std::array<long long, 3> cell{static_cast<long long>(std::floor(p[0] / tol)),
                                        static_cast<long long>(std::floor(p[1] / tol)),
                                        static_cast<long long>(std::floor(p[2] / tol))};
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          auto it = grid.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (it == grid.end()) continue;
          for (const Position& q : it->second)
            if (length(sub(p, q)) < tol) return "two vertices closer than the feature size";
        }
    grid[cell].push_back(p);
  }
  for (std::size_t f = 0; f < d.facets.size(); ++f) {
    const auto& fp = d.facets[f];
    std::size_t a = 0, b = 1;
    double far = -1;
    for (std::size_t i = 0; i < fp.size(); ++i)
      for (std::size_t j = i + 1; j < fp.size(); ++j)
        if (length(sub(fp[i], fp[j])) > far) far = length(sub(fp[i], fp[j])), a = i, b = j;
    const Position axis = sub(fp[b], fp[a]);
    double width = 0;
    for (const Position& p : fp) {
      const Position r = sub(p, fp[a]);
      const double along = dot3(r, axis) / dot3(axis, axis);
      width = std::max(width,
                       length(sub(r, Position{along * axis[0], along * axis[1], along * axis[2]})));
    }
    if (width < tol) return "a facet thinner than the feature size";
  }
  for (std::size_t f = 0; f < d.facets.size(); ++f) {
    std::map<std::size_t, int> shared;
    for (const Position& p : d.facets[f])
      for (std::size_t g : facets_at[p])
        if (g != f) ++shared[g];
    for (const auto& [g, count] : shared) {
      if (count < 2 || !d.planes[f].reliable) continue;
      const Plane& h = d.planes[f];
      const bool flat = std::all_of(d.facets[g].begin(), d.facets[g].end(), [&](const Position& p) {
        return std::abs(dot3(h.normal, p) - h.offset) <= tol;
      });
      if (flat) return "two neighbouring facets coplanar to within the feature size";
    }
  }
  return {};
}

bool exactly_planar(const Mesh& mesh) {
  for (auto f : mesh.faces()) {
    std::vector<IPoint> p;
    for (auto v : mesh.fv_range(f))
      p.emplace_back(mesh.point(v)[0], mesh.point(v)[1], mesh.point(v)[2]);
    if (affine_dimension(p) != 2) return false;
  }
  return true;
}

double bbox_diagonal(const Mesh& mesh) {
  if (mesh.n_vertices() == 0) return 0.0;
  Point lo = mesh.point(*mesh.vertices_begin()), hi = lo;
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  return (hi - lo).norm();
}

bool identical(const Mesh& a, const Mesh& b) {
  if (a.n_vertices() != b.n_vertices() || a.n_faces() != b.n_faces()) return false;
  for (auto v : a.vertices()) {
    if (a.point(v) != b.point(b.vertex_handle(v.idx()))) return false;
  }
  for (auto f : a.faces()) {
    std::vector<int> fa, fb;
    for (auto v : a.fv_range(f)) fa.push_back(v.idx());
    for (auto v : b.fv_range(b.face_handle(f.idx()))) fb.push_back(v.idx());
    if (fa != fb) return false;
  }
  return true;
}

std::string clean_mesh_problem(const Mesh& mesh, const CleanOptions& options) {
  if (mesh.n_vertices() == 0 || mesh.n_faces() == 0) return "the mesh is empty";
  for (auto h : mesh.halfedges()) {
    if (mesh.is_boundary(h))
      return "not closed: a boundary halfedge at vertex " +
             std::to_string(mesh.from_vertex_handle(h).idx());
  }
  for (auto e : mesh.edges()) {
    if (mesh.face_handle(mesh.halfedge_handle(e, 0)) ==
        mesh.face_handle(mesh.halfedge_handle(e, 1))) {
      return "edge " + std::to_string(e.idx()) + " has the same face on both sides";
    }
  }
  // Vertex manifoldness: the fan reached by the circulator holds every outgoing halfedge.
  std::vector<int> outgoing(mesh.n_vertices(), 0);
  for (auto h : mesh.halfedges()) ++outgoing[mesh.from_vertex_handle(h).idx()];
  for (auto v : mesh.vertices()) {
    int fan = 0;
    for (auto h : mesh.voh_range(v)) (void)h, ++fan;
    if (fan != outgoing[v.idx()]) return "vertex " + std::to_string(v.idx()) + " is not manifold";
  }
  // Connected, Euler characteristic 2 (a sphere).
  std::vector<char> seen(mesh.n_faces(), 0);
  std::vector<Mesh::FaceHandle> stack = {*mesh.faces_begin()};
  seen[stack.front().idx()] = 1;
  std::size_t reached = 1;
  while (!stack.empty()) {
    const auto f = stack.back();
    stack.pop_back();
    for (auto g : mesh.ff_range(f)) {
      if (!seen[g.idx()]) seen[g.idx()] = 1, ++reached, stack.push_back(g);
    }
  }
  if (reached != mesh.n_faces()) return "not connected";
  const long euler = static_cast<long>(mesh.n_vertices()) - static_cast<long>(mesh.n_edges()) +
                     static_cast<long>(mesh.n_faces());
  if (euler != 2) return "Euler characteristic " + std::to_string(euler) + ", expected 2";

  // No duplicate positions.
  std::vector<Position> pos;
  for (auto v : mesh.vertices()) pos.push_back(position(mesh.point(v)));
  std::sort(pos.begin(), pos.end());
  if (std::adjacent_find(pos.begin(), pos.end()) != pos.end()) {
    return "duplicate vertex position " + text(*std::adjacent_find(pos.begin(), pos.end()));
  }

  const Description d = describe(mesh);
  if (!(d.volume > 0)) return "not outward: volume " + std::to_string(d.volume);

  const double tol = options.tolerance * bbox_diagonal(mesh);
  auto ipoint = [&](Mesh::VertexHandle v) {
    const Point& p = mesh.point(v);
    return IPoint(p[0], p[1], p[2]);
  };
  // Per face: three vertices spanning its plane, counter-clockwise, and the Newell plane.
  std::vector<std::array<IPoint, 3>> triple(mesh.n_faces());
  std::vector<Plane> plane(mesh.n_faces());
  for (auto f : mesh.faces()) {
    std::vector<Mesh::VertexHandle> fv;
    for (auto v : mesh.fv_range(f)) fv.push_back(v);
    const std::string name = "face " + std::to_string(f.idx());
    if (fv.size() < 3) return name + " has fewer than 3 vertices";
    std::vector<IPoint> p;
    std::vector<Point> pts;
    for (auto v : fv) p.push_back(ipoint(v)), pts.push_back(mesh.point(v));
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (std::size_t j = i + 1; j < p.size(); ++j) {
        if (p[i] == p[j]) return name + " repeats a vertex position";
      }
    }
    std::size_t j = 2;
    while (j < p.size() && CGAL::collinear(p[0], p[1], p[j])) ++j;
    if (j == p.size()) return name + " has zero area";
    triple[f.idx()] = {p[0], p[1], p[j]};
    const Plane h = newell_plane(pts);
    const Point n(h.normal[0], h.normal[1], h.normal[2]);
    if (!(n.norm() > 0)) return name + " has zero area";
    plane[f.idx()] = h;
    for (auto v : fv) {
      if (options.exact) {
        if (!CGAL::coplanar(p[0], p[1], p[j], ipoint(v))) return name + " is not exactly planar";
      } else if (std::abs(signed_distance(h, mesh.point(v))) > tol) {
        return name + " is not planar within the tolerance";
      }
    }
    {
      // The spanning triple must turn the way the face does (counter-clockwise from outside).
      const Point& a = mesh.point(fv[0]);
      const Point t = OpenMesh::cross(mesh.point(fv[1]) - a, mesh.point(fv[j]) - a);
      if (!(OpenMesh::dot(t, n) > 0)) return name + " is not convex (a reflex corner)";
    }
  }
  auto above = [&](Mesh::FaceHandle f, Mesh::VertexHandle v) {
    if (options.exact) {
      const auto& t = triple[f.idx()];
      return CGAL::orientation(t[0], t[1], t[2], ipoint(v)) == CGAL::POSITIVE;
    }
    return signed_distance(plane[f.idx()], mesh.point(v)) > tol;
  };
  auto coplanar_faces = [&](Mesh::FaceHandle f, Mesh::FaceHandle g) {
    const auto& t = triple[f.idx()];
    for (auto v : mesh.fv_range(g)) {
      if (!CGAL::coplanar(t[0], t[1], t[2], ipoint(v))) return false;
    }
    return true;
  };
  for (auto f : mesh.faces()) {
    for (auto v : mesh.vertices()) {
      if (above(f, v))
        return "not convex: vertex " + std::to_string(v.idx()) + " above face " +
               std::to_string(f.idx());
    }
  }
  if (!options.exact) {
    for (auto v : mesh.vertices()) {
      if (mesh.valence(v) < 3)
        return "not minimal: vertex " + std::to_string(v.idx()) + " has fewer than 3 faces";
    }
    return {};
  }
  for (auto e : mesh.edges()) {
    const auto f = mesh.face_handle(mesh.halfedge_handle(e, 0));
    const auto g = mesh.face_handle(mesh.halfedge_handle(e, 1));
    if (coplanar_faces(f, g)) {
      return "not minimal: adjacent faces " + std::to_string(f.idx()) + " and " +
             std::to_string(g.idx()) + " are coplanar";
    }
  }
  for (auto v : mesh.vertices()) {
    std::vector<Mesh::FaceHandle> classes;
    for (auto f : mesh.vf_range(v)) {
      if (std::none_of(classes.begin(), classes.end(),
                       [&](auto g) { return coplanar_faces(g, f); }))
        classes.push_back(f);
    }
    if (classes.size() < 3) {
      return "not minimal: vertex " + std::to_string(v.idx()) + " has " +
             std::to_string(classes.size()) + " distinct face planes around it";
    }
  }
  return {};
}

CleanOptions clean_options_for(const Description& exact_reference) {
  CleanOptions options;
  options.exact = exact_reference.exact_positions;
  return options;
}

}  // namespace morph::test
