// Fuzz target: the FIMS kernel and the four morphological operations on random convex
// polyhedra. The input is decoded into two point sets (4..36 points each) whose exact
// convex hulls (CGAL, tests/support) are A and B, then one operation runs and its result
// is checked against the contract of morphology.h / minkowski_sum.h:
//   - closed: every halfedge has a face; 2-manifold (check_closed_manifold);
//   - convex: every vertex on or below every face plane (to 1e-9 of the scale);
//   - dilation (and the dilation inside open/close) contains A + b for every vertex b of B;
//   - erosion and opening lie inside A; erosion + b lies inside A for every vertex b of B;
//   - closing of a convex A is A (each inside the other).
// Only morph::error may be thrown; a hull that is not a solid is skipped.
#include <morph/error.h>
#include <morph/minkowski_sum.h>
#include <morph/morphology.h>
#include <morph/validate.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "support/oracle.h"
#include "support/polytopes.h"

namespace {

using morph::Mesh;
using morph::Point;

// Relative tolerance of the containment and convexity checks (of the largest diagonal).
constexpr double kRelativeTolerance = 1e-9;

class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  std::int16_t int16() { return static_cast<std::int16_t>(byte() | (byte() << 8)); }
  bool empty() const { return pos_ >= size_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

// Point coordinates: small integers (many exact coplanarities), a fine grid, or the grid
// rotated by a quaternion from the input (coordinates no longer on any grid).
std::vector<Point> decode_points(Bytes& in, int mode) {
  const int n = 4 + in.byte() % 33;
  std::vector<Point> points;
  double q[4];
  for (double& c : q) c = in.int16() / 32768.0;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int i = 0; i < n && !in.empty(); ++i) {
    Point p;
    for (int k = 0; k < 3; ++k) p[k] = mode == 0 ? in.byte() % 9 - 4 : in.int16() / 4096.0;
    if (mode == 2 && norm > 1e-3) {
      const double w = q[0] / norm, x = q[1] / norm, y = q[2] / norm, z = q[3] / norm;
      const double m[9] = {
          1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
      p = Point(m[0] * p[0] + m[1] * p[1] + m[2] * p[2], m[3] * p[0] + m[4] * p[1] + m[5] * p[2],
                m[6] * p[0] + m[7] * p[1] + m[8] * p[2]);
    }
    points.push_back(p);
  }
  return points;
}

double diagonal(const Mesh& mesh) {
  Point lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  return mesh.n_vertices() ? (hi - lo).norm() : 0.0;
}

struct Plane {
  Point normal;  // unit, outward
  Point origin;  // centroid of the face
};

std::vector<Plane> planes(const Mesh& mesh) {
  std::vector<Plane> out;
  for (auto f : mesh.faces()) {
    Point normal(0, 0, 0), centroid(0, 0, 0);
    int n = 0;
    for (auto h : mesh.fh_range(f)) {  // Newell's normal
      const Point& a = mesh.point(mesh.from_vertex_handle(h));
      const Point& b = mesh.point(mesh.to_vertex_handle(h));
      normal += Point((a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]),
                      (a[0] - b[0]) * (a[1] + b[1]));
      centroid += a;
      ++n;
    }
    const double length = normal.norm();
    if (length > 0) out.push_back({normal / length, centroid / n});
  }
  return out;
}

[[noreturn]] void violated(const char* what) {
  std::fprintf(stderr, "kernel fuzzer: invariant violated: %s\n", what);
  std::abort();
}

// Every point of `points` (each translated by every vertex of `by`, if given) lies on
// or below every plane of `hull`.
void require_inside(const std::vector<Point>& points, const std::vector<Point>& by,
                    const std::vector<Plane>& hull, double tolerance, const char* what) {
  const std::vector<Point> none{Point(0, 0, 0)};
  for (const Plane& plane : hull)
    for (const Point& p : points)
      for (const Point& b : by.empty() ? none : by)
        if (OpenMesh::dot(p + b - plane.origin, plane.normal) > tolerance) violated(what);
}

std::vector<Point> vertices(const Mesh& mesh) {
  std::vector<Point> out;
  for (auto v : mesh.vertices()) out.push_back(mesh.point(v));
  return out;
}

void require_closed_convex(const Mesh& mesh, double tolerance, const char* what) {
  if (mesh.n_faces() < 4) violated(what);
  for (auto h : mesh.halfedges())
    if (mesh.is_boundary(h)) violated(what);
  if (!morph::check_closed_manifold(mesh).ok()) violated(what);
  require_inside(vertices(mesh), {}, planes(mesh), tolerance, what);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Bytes in(data, size);
  const std::uint8_t control = in.byte();
  const int op = control % 5;  // 0 minkowski_sum, 1 dilate, 2 erode, 3 open, 4 close
  const int mode = (control / 5) % 3;
  Mesh A, B;
  try {
    const auto points_b = decode_points(in, mode);  // B first: small inputs make B, not A
    const auto points_a = decode_points(in, mode);
    A = morph::test::convex_hull_mesh(points_a);
    B = morph::test::convex_hull_mesh(points_b);
  } catch (const std::invalid_argument&) {
    return 0;  // not a solid
  }
  const auto va = vertices(A), vb = vertices(B);
  const auto planes_a = planes(A);
  const morph::MorphologyOptions options{.threads = 1};
  try {
    morph::MorphResult result;
    if (op == 0) {
      auto sum = morph::minkowski_sum(A, B, {.threads = 1});
      if (sum.origins.size() != sum.mesh.n_faces()) violated("one origin per facet");
      result.mesh = std::move(sum.mesh);
    } else if (op == 1) {
      result = morph::dilate(A, B, options);
    } else if (op == 2) {
      result = morph::erode(A, B, options);
    } else if (op == 3) {
      result = morph::open(A, B, options);
    } else {
      result = morph::close(A, B, options);
    }
    if (result.is_empty()) {
      if (op <= 1 || op == 4) violated("dilation and closing are never empty");
      if (result.mesh.n_vertices() != 0) violated("an empty result has no vertices");
      return 0;
    }
    const Mesh& S = result.mesh;
    const double scale = std::max({diagonal(A), diagonal(B), diagonal(S)});
    const double tolerance = kRelativeTolerance * scale;
    require_closed_convex(S, tolerance, "result closed and convex");
    const auto vs = vertices(S);
    const auto planes_s = planes(S);
    switch (op) {
      case 0:
      case 1:
        require_inside(va, vb, planes_s, tolerance, "A + b inside A (+) B");
        break;
      case 2:
        // x + B inside A for every x of the erosion (not x itself: B need not hold the origin,
        // and A (-) {b} is A - b).
        require_inside(vs, vb, planes_a, tolerance, "erosion + b inside A");
        break;
      case 3:
        require_inside(vs, {}, planes_a, tolerance, "opening inside A");
        break;
      case 4:
        require_inside(vs, {}, planes_a, tolerance, "closing inside A");
        require_inside(va, {}, planes_s, tolerance, "A inside its closing");
        break;
    }
  } catch (const morph::error&) {
  }
  return 0;
}
