// Private: the kernel's view of a convex polyhedron.
//
// A Polytope is built from a validated Mesh (or produced by an operation) and carries
// what the exact algorithms need: facet cycles, edges with their two facets, the fan of
// facets around each vertex, unit (and, lazily, precise and exact) facet normals, and
// exact vertex positions when they are not doubles (results of an erosion chained into a
// dilation).
//
// Canonical form: adjacent facets whose common edge is not strictly convex (exactly
// coplanar, or within the validation tolerance) are merged into one polygon, and
// vertices left with fewer than three distinct facets around them (in the middle of an
// edge or of a facet) are removed. The normal of a facet is Newell's normal of its
// exact vertex cycle, so every decision made on normals is exact and consistent.
//
// The Gauss map of a polytope: facet f -> point N_f on the sphere; edge -> the arc from
// N_left to N_right; vertex v -> the convex spherical polygon of the normals of the facets
// around it, listed counter-clockwise (seen from outside) in its fan.
#pragma once

#include <morph/mesh.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "exact.h"
#include "run_once.h"

namespace morph::detail {

/// A facet normal's direction rounded to a unit vector of doubles, and a bound on the
/// Euclidean distance from it to the exact normal's unit vector (infinite when the
/// normal's enclosure is too wide to tell its direction).
struct UnitNormal {
  double x, y, z, error;
};

/// |x| + |y| + |z|.
inline double norm1(double x, double y, double z) {
  return std::abs(x) + std::abs(y) + std::abs(z);
}

/// A facet's unit normal from its Newell sum n = (nx, ny, nz) computed in doubles relative to
/// the rounded centroid c of its d corners (Newell's sum is translation invariant: the exact
/// sum relative to c is the facet's exact normal), over the rounded corners a_k = fl(p_k - c),
/// summed from zero in corner order; length = sqrt(n.n) and inverse = 1 / length as rounded,
/// and magnitude = sum over the edges a-b of |a|_1 |b|_1 (rounded). The bound: each a_k is
/// within one ulp of p_k - c, so each term a_j b_l - a_l b_j of a cross product is within 4
/// ulps of |a_j b_l| + |a_l b_j| (two inputs, the product, the difference), and each of the
/// d - 1 rounded additions (the first adds to zero) within one ulp of the sum of those: (d + 3)
/// ulps of M in all components together, where M = sum over the edges of
/// sum_(j != l) |a_j| |b_l| <= magnitude; taken as d + 4 with margins for the rounding of M,
/// plus an absolute term for underflow. Then, as normalised() in polytope.cpp, n * inverse
/// lies within 2 radius / |n| (plus a few ulps) of the direction of any vector within radius
/// of n. Any rounding mode (ulps of 2^-52). False (nothing set) when |n| lies where n.n could
/// overflow or underflow (normalised() scales n first). The operand check computes these values
/// beside its own (see geometry_passes) and Polytope::compute_normals() the same.
inline bool centroid_unit_normal(double nx, double ny, double nz, double length, double inverse,
                                 double magnitude, int d, UnitNormal& out) {
  if (!(length > 1e-100 && length < 1e100)) return false;
  const double radius = ((d + 4) * 0x1p-52 * 1.01 * magnitude + 3 * d * 0x1p-1000) * 1.01;
  double error = 2 * radius * inverse * (1 + 1e-10) + 4e-15;
  if (!std::isfinite(error) || error > 1) error = std::numeric_limits<double>::infinity();
  out = {nx * inverse, ny * inverse, nz * inverse, error};
  return true;
}

/// A facet normal in double-double arithmetic (component i is hi[i] + lo[i]), times some
/// power of two, within error[i] of the exact normal times that power in component i (a
/// component that is exactly zero has error 0). Not `valid` when the facet's points (or
/// its given normal) do not scale exactly.
struct PreciseNormal {
  double hi[3], lo[3];
  double error[3];
  bool valid;
  bool exactly_zero(int i) const { return error[i] == 0 && hi[i] == 0; }
};

/// A vertex X / W (W > 0) in double-double arithmetic, times some unknown positive factor:
/// X.x is within error.x of the exact X.x times that factor (and so on), W within w_error.
/// Not `valid` when the precise stage could not represent the vertex. `doubles`: X / W is
/// exactly the vertex's double point (then nothing else is set).
struct PrecisePoint {
  V3<DD> X{};
  DD W{};
  V3<double> error{};
  double w_error = 0;
  bool valid = false;
  bool doubles = false;
};

/// Exact vertex coordinates computed on demand: an erosion chained into a dilation reads
/// them only where the precise stage cannot round a sum (see ExactPoints::lazy).
class LazyExactPoints {
 public:
  virtual ~LazyExactPoints() = default;
  /// Vertex v's exact homogeneous coordinates (thread-safe; each computed at most once,
  /// the same values whichever thread asks first).
  virtual void get(int v, const V3<ExactN>*& X, const ExactN*& W) const = 0;
};

/// Exact vertex positions that are not doubles (an erosion's vertices), in homogeneous
/// dyadic coordinates: vertex v is numerator[v] / denominator[v] (denominator > 0), within
/// the interval box enclosure[v]. Rationals would cost three gcds per vertex to build and
/// more to add; these are exactly what the intersection computed. When `lazy` is set,
/// numerator and denominator are empty and `lazy` computes them on demand: read them
/// through X(v) and W(v), which work in both cases.
struct ExactPoints {
  std::vector<V3<ExactN>> numerator;
  std::vector<ExactN> denominator;
  std::vector<V3<Interval>> enclosure;
  // Optional (empty: none): the vertices in double-double, for roundings that need not
  // read the exact coordinates (sums with double points, see sum_mesh).
  std::vector<PrecisePoint> precise;
  std::shared_ptr<const LazyExactPoints> lazy;
  bool empty() const { return denominator.empty() && !lazy; }
  void resize(std::size_t n) {
    numerator.resize(n);
    denominator.resize(n);
    enclosure.resize(n);
  }
  const V3<ExactN>& X(int v) const {
    if (!lazy) return numerator[v];
    const V3<ExactN>* x;
    const ExactN* w;
    lazy->get(v, x, w);
    return *x;
  }
  const ExactN& W(int v) const {
    if (!lazy) return denominator[v];
    const V3<ExactN>* x;
    const ExactN* w;
    lazy->get(v, x, w);
    return *w;
  }
  V3<Exact> rational(int v) const {
    const V3<ExactN>& x = X(v);
    const Exact w(W(v));
    return {Exact(x.x) / w, Exact(x.y) / w, Exact(x.z) / w};
  }
};

/// A polytope's exact facet normals when they are given (Polytope::given_normals): held, or
/// read from a source that makes each on first read (an erosion's half-spaces, which the
/// source keeps: no copy of a quarter of a million Mpzf normals, 109 ms of an opening of an
/// icosphere of 327,680 facets, most of them never read exactly).
class GivenNormals {
 public:
  /// Normal f, made on first read by whichever thread reads first (safe to read from any
  /// thread), the same reference on every read.
  class Source {
   public:
    virtual ~Source() = default;
    virtual const V3<ExactN>& normal(int f) const = 0;
    /// Normal f's precise copy, when the source has one at hand without exact arithmetic
    /// (false: none; `out` is then unset).
    virtual bool precise(int /*f*/, PreciseNormal& /*out*/) const { return false; }
  };
  GivenNormals() = default;
  explicit GivenNormals(std::vector<V3<ExactN>> held) : held_(std::move(held)) {}
  GivenNormals(std::shared_ptr<const Source> source, std::size_t size)
      : source_(std::move(source)), size_(size) {}
  bool empty() const { return size() == 0; }
  bool has_source() const { return source_ != nullptr; }
  std::size_t size() const { return source_ ? size_ : held_.size(); }
  const V3<ExactN>& operator[](std::size_t f) const {
    return source_ ? source_->normal(static_cast<int>(f)) : held_[f];
  }
  /// Normal f's precise copy from the source, when it has one (Source::precise).
  bool precise(std::size_t f, PreciseNormal& out) const {
    return source_ && source_->precise(static_cast<int>(f), out);
  }

 private:
  std::vector<V3<ExactN>> held_;
  std::shared_ptr<const Source> source_;
  std::size_t size_ = 0;
};

struct Polytope {
  struct Edge {
    int from = -1, to = -1;     // vertices; `left` contains the directed edge from -> to
    int left = -1, right = -1;  // facets
  };

  // Vertices: rounded positions, and exact ones when they are not doubles.
  std::vector<V3<double>> points;
  ExactPoints exact_points;  // empty when `points` are exact
  // Exact facet normals when `exact_points` is used (the normal of the plane the facet was
  // built on); empty otherwise, the normals being Newell's of the double points.
  GivenNormals given_normals;

  // Facets: counter-clockwise vertex cycles about the outward normal.
  std::vector<int> face_begin;     // size F + 1
  std::vector<int> corner_vertex;  // corner k of facet f: corner_vertex[face_begin[f] + k]
  std::vector<int> corner_edge;    // edge from corner k to corner k + 1 (index into `edges`)

  std::vector<Edge> edges;

  // Fans: facets around vertex v counter-clockwise seen from outside. Slot s lies
  // between fan_face[s] and fan_face[s + 1] (cyclically) and is the edge fan_edge[s]
  // from v to fan_vertex[s]; crossing that arc of the Gauss map leads to fan_vertex[s].
  std::vector<int> fan_begin;  // size V + 1
  std::vector<int> fan_face, fan_edge, fan_vertex;

  // The facet normals as unit double vectors with error bounds: the fast filter of every
  // predicate on normals (see orient_normals).
  std::vector<UnitNormal> unit_normals;

  // A sum made by sum_polytope(X, Y, ...): vertex v is X's vertex pair_first(sum_pairs[
  // vertex_source[v]]) plus Y's pair_second(...) (pair_key, fims.h). Empty otherwise.
  std::vector<std::uint64_t> sum_pairs;

  // Where each element came from in the operand mesh (labels): a representative face,
  // the vertex, a representative edge. -1 when not from a mesh.
  std::vector<int> face_source, vertex_source, edge_source;

  int num_vertices() const { return static_cast<int>(points.size()); }
  int num_faces() const { return static_cast<int>(face_begin.size()) - 1; }
  int num_edges() const { return static_cast<int>(edges.size()); }
  int degree(int f) const { return face_begin[f + 1] - face_begin[f]; }
  int corner(int f, int k) const { return corner_vertex[face_begin[f] + k]; }
  /// The edge between vertices u and w (either direction), or -1: a scan of u's fan.
  int edge_between(int u, int w) const {
    for (int s = fan_begin[u]; s < fan_begin[u + 1]; ++s)
      if (fan_vertex[s] == w) return fan_edge[s];
    return -1;
  }

  V3<Exact> exact_point(int v) const {
    return exact_points.empty() ? to_exact(points[v]) : exact_points.rational(v);
  }
  V3<Interval> interval_point(int v) const {
    return exact_points.empty() ? to_interval(points[v]) : exact_points.enclosure[v];
  }

  /// Exact normal of facet f: given, or Newell's of its points, computed on first use and
  /// kept (thread-safe: racing threads may both compute it, all get the one kept).
  const V3<ExactN>& exact_normal(int f) const;

  /// Computes `unit_normals` and resets the caches of exact and precise normals; call
  /// after the facets are final. `units_known`: `unit_normals` already holds every facet's
  /// (make_operand's check computed them, see geometry_passes): only the caches are reset.
  void compute_normals(bool units_known = false);

  /// Facet f's exact normal (the given one, or Newell's of the double points) in
  /// double-double arithmetic, scaled by a power of two, with an error bound: the second
  /// stage of the normal predicates. Computed on first use and kept, as exact_normal.
  const PreciseNormal& precise_normal(int f) const;

 private:
  // One slot per facet, filled on first use (thread-safe: racing threads may both compute
  // a value, all get the one kept): few facets ever need these, so nothing is allocated
  // for the others.
  template <class T>
  struct LazySlots {
    explicit LazySlots(int n) : slot(std::make_unique<std::atomic<const T*>[]>(n)), size(n) {}
    ~LazySlots() {
      if (!filled.load(std::memory_order_relaxed)) return;  // usually: skip the scan
      for (int f = 0; f < size; ++f) delete slot[f].load(std::memory_order_relaxed);
    }
    template <class Compute>
    const T& get(int f, const Compute& compute) {
      if (const T* known = slot[f].load(std::memory_order_acquire)) return *known;
      auto computed = std::make_unique<const T>(compute());
      const T* expected = nullptr;  // the first to publish wins
      if (slot[f].compare_exchange_strong(expected, computed.get(), std::memory_order_acq_rel,
                                          std::memory_order_acquire)) {
        filled.store(true, std::memory_order_relaxed);
        return *computed.release();
      }
      return *expected;
    }
    std::unique_ptr<std::atomic<const T*>[]> slot;
    int size;
    std::atomic<bool> filled{false};
  };
  // Precise normals are small and trivially copyable, and a sum of two fine spheres needs
  // a hundred or so: one flat array instead of an allocation each. Each slot is made once,
  // by the first reader to claim it (run_once); a reader that comes meanwhile waits for it.
  template <class T>
  struct FlatSlots {
    explicit FlatSlots(int n)
        : value(std::make_unique_for_overwrite<T[]>(n)),
          state(std::make_unique<std::atomic<unsigned char>[]>(n)) {}
    template <class Compute>
    const T& get(int f, const Compute& compute) {
      std::atomic<unsigned char>& s = state[f];
      if (s.load(std::memory_order_acquire) != once_state::kDone)
        run_once(s, [&] { value[f] = compute(); });
      return value[f];
    }
    /// Slot f's value, set before any reader comes (the polytope being built).
    void set(int f, const T& v) {
      value[f] = v;
      state[f].store(once_state::kDone, std::memory_order_release);
    }
    std::unique_ptr<T[]> value;
    std::unique_ptr<std::atomic<unsigned char>[]> state;  // value-initialised: kNone
  };
  mutable std::shared_ptr<LazySlots<V3<ExactN>>> exact_cache_;
  mutable std::shared_ptr<FlatSlots<PreciseNormal>> precise_cache_;
};

/// A facet normal as a predicate argument.
struct NormalRef {
  const Polytope* polytope;
  int face;
  const UnitNormal& unit() const { return polytope->unit_normals[face]; }
  const V3<ExactN>& exact() const { return polytope->exact_normal(face); }
};

// Predicates on facet normals, the decisions of the FIMS kernel. Each is a semi-static
// filter: evaluated in doubles on the unit normals, whose error bounds (plus the rounding
// of the evaluation itself, in any rounding mode) bound the error of the value. When that
// cannot decide the sign, each tries again in double-double arithmetic on precise
// normals (nearly parallel facets of two fine spheres need it), and only then evaluates
// exactly on the exact normals. Signs are those of the exact normals (positive scalings
// do not change them).

/// Bound on the rounding error of det or cross_dot of vectors of length at most
/// 1 + 1e-15, evaluated in doubles with any rounding mode (each operation within one
/// ulp): about 7e-15, doubled for safety.
inline constexpr double kUnitPredicateRounding = 2e-14;

/// What a stage of a predicate returns when it cannot tell the sign.
inline constexpr int kUndecided = 2;

/// The later stages, for what the double filter leaves undecided: double-double, then
/// exact.
int orient_normals_undecided(const NormalRef& a, const NormalRef& b, const NormalRef& c);
int cross_dot_normals_undecided(const NormalRef& a, const NormalRef& b, const NormalRef& c,
                                const NormalRef& d);
/// Each stage alone (for callers with shortcuts of their own between them, gauss_map.h):
/// the double-double stage returns the sign or kUndecided; the exact stage, the sign.
int orient_normals_precise(const NormalRef& a, const NormalRef& b, const NormalRef& c);
/// orient_normals_precise without its nearly parallel pair's step, for callers that tried that
/// step already (gauss_map.cpp's kept cross products): det on the three precise normals.
int orient_normals_precise_full(const NormalRef& a, const NormalRef& b, const NormalRef& c);
int orient_normals_exact(const NormalRef& a, const NormalRef& b, const NormalRef& c);
int cross_dot_normals_precise(const NormalRef& a, const NormalRef& b, const NormalRef& c,
                              const NormalRef& d);
int cross_dot_normals_exact(const NormalRef& a, const NormalRef& b, const NormalRef& c,
                            const NormalRef& d);
/// The nearly parallel pair's stage: N_x x N_y times a positive factor, as doubles w within
/// eps (Euclidean) of it, from the double-double cross product of x's and y's precise normals;
/// false when a precise normal is not valid. Needs round-to-nearest (the caller's guard).
bool precise_cross(const NormalRef& x, const NormalRef& y, double w[3], double& eps);

/// The double filter of orient_normals alone: the sign, or kUndecided.
inline int orient_normals_filter(const NormalRef& a, const NormalRef& b, const NormalRef& c) {
  const UnitNormal &p = a.unit(), &q = b.unit(), &r = c.unit();
  const double d =
      p.x * (q.y * r.z - q.z * r.y) + p.y * (q.z * r.x - q.x * r.z) + p.z * (q.x * r.y - q.y * r.x);
  // det is 1-Lipschitz in each unit argument.
  const double bound = p.error + q.error + r.error + kUnitPredicateRounding;
  if (d > bound) return 1;
  if (d < -bound) return -1;
  return kUndecided;
}

/// Sign of det(N_a, N_b, N_c).
inline int orient_normals(const NormalRef& a, const NormalRef& b, const NormalRef& c) {
  const int s = orient_normals_filter(a, b, c);
  return s != kUndecided ? s : orient_normals_undecided(a, b, c);
}

/// The double filter of cross_dot_normals alone: the sign, or kUndecided.
inline int cross_dot_normals_filter(const NormalRef& a, const NormalRef& b, const NormalRef& c,
                                    const NormalRef& d) {
  const UnitNormal &p = a.unit(), &q = b.unit(), &r = c.unit(), &s = d.unit();
  auto dot3 = [](const UnitNormal& u, const UnitNormal& v) {
    return u.x * v.x + u.y * v.y + u.z * v.z;
  };
  const double value = dot3(p, r) * dot3(q, s) - dot3(p, s) * dot3(q, r);
  // 2-Lipschitz in each unit argument; the second-order term covers errors up to 1.
  const double e = p.error + q.error + r.error + s.error;
  const double bound = 2 * e + 4 * e * e + kUnitPredicateRounding;
  if (value > bound) return 1;
  if (value < -bound) return -1;
  return kUndecided;
}

/// Sign of (N_a x N_b) . (N_c x N_d) = (N_a.N_c)(N_b.N_d) - (N_a.N_d)(N_b.N_c).
inline int cross_dot_normals(const NormalRef& a, const NormalRef& b, const NormalRef& c,
                             const NormalRef& d) {
  const int s = cross_dot_normals_filter(a, b, c, d);
  return s != kUndecided ? s : cross_dot_normals_undecided(a, b, c, d);
}

/// How make_polytope reads a mesh's faces: as given, or each reversed (an inverted mesh,
/// see check_operand).
enum class FaceOrder : bool { as_given, reversed };

/// Builds the canonical polytope of a mesh that passed check_convex_polyhedron(), or of
/// the mesh with every facet reversed (`order`, for an inverted mesh):
/// then each facet cycle is the reverse of the mesh face's. Labels name `mesh`'s elements.
/// Throws not_convex (prefixed with `name`) if the facets' exact normals do not form a
/// valid Gauss map (possible only for meshes convex merely within the tolerance).
/// Complexity: linear, straight from the mesh's halfedges when every edge is strictly
/// convex and every vertex has three facets; otherwise through the canonical merge.
Polytope make_polytope(const Mesh& mesh, const char* name, FaceOrder order = FaceOrder::as_given);

/// make_polytope(mesh, name, order) always through the canonical merge of facet cycles (the
/// general path); for tests, which check that both paths give the same polytope.
Polytope make_polytope_from_cycles(const Mesh& mesh, const char* name,
                                   FaceOrder order = FaceOrder::as_given);

/// Builds a polytope from facet cycles over the given vertices (exact positions when
/// `exact_points` is non-empty, and then one exact normal per facet in `given_normals`),
/// canonicalising it as make_polytope does. Vertices not used by any facet are dropped.
Polytope make_polytope(std::vector<V3<double>> points, ExactPoints exact_points,
                       const std::vector<std::vector<int>>& faces,
                       std::vector<V3<ExactN>> given_normals, const char* name);

/// An operand: checks `mesh` with prepare_convex_polyhedron (throwing invalid_mesh /
/// not_convex prefixed with `name`, flipping a fully inverted mesh) and builds its polytope.
/// A mesh that passes as it is is checked and built in one pass over its halfedges; any
/// other is checked with the build beside it when threads allow (same result and errors as
/// in sequence).
Polytope make_operand(const Mesh& mesh, const char* name);

/// make_operand(A, "A") and make_operand(B, "B"), side by side when threads allow; A's
/// error is reported when both are bad.
struct Operands {
  Polytope a, b;
};
Operands make_operands(const Mesh& A, const Mesh& B);

/// The mesh of a polytope (its rounded positions), with facets in polytope order.
Mesh to_mesh(const Polytope& p);

}  // namespace morph::detail
