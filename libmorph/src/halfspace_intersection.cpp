// Exact half-space intersection by duality: with a point o strictly inside, the
// half-space <n, x> <= d maps to the dual point n / (d - <n, o>); the facets of the
// intersection are the dual points that are vertices of their convex hull, and its
// vertices are the hull's facets.
//
// Main route: an exact randomised incremental hull built on the planes themselves (every
// test is on the planes as dyadic homogeneous coordinates, Mpzf without gcd, interval-
// filtered), so exact degeneracies such as four planes through a vertex need no fallback.
// Its result is then checked exactly (Mehlhorn et al., "Checking geometric programs or
// verification of geometric structures", 1999): a closed triangulated surface around o,
// locally convex at every edge, that a ray from o crosses once, is the boundary of its
// convex hull; the hull holds every other dual point iff its plane does not cut the
// candidate polytope, which a walk on the (convex) candidate decides. If a check fails,
// the exact route computes the dual hull on exact rational points (CGAL). Both routes end
// in the same exact, canonical construction; vertices are rounded exactly from their
// homogeneous coordinates, and rationals are formed only for a polytope chained further.
// Incidences the caller knows (KnownPoints: an erosion's facets of A around a vertex moved
// by one vertex of B) make vertices without exact constructions and zero tests free, and
// an expected result (ExpectedVertices: A's vertices, opened up by exact flips where the
// moved planes around one no longer meet in a point; a closing's A) replaces the hull when it
// passes the check, or, when only some of its edges fail, once flips have repaired those.
#include "halfspace_intersection.h"

#include <CGAL/Lazy_kernel.h>
#include <CGAL/QP_functions.h>
#include <CGAL/QP_models.h>
#include <CGAL/Quotient.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>
#include <morph/error.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>
#include <thread>

#include "fims.h"
#include "gauss_map.h"
#include "huge_pages.h"
#include "parallel.h"

namespace morph::detail {

namespace {

// Exact constructions on fractions of dyadic floats, never reduced: no gcd (CGAL's Epeck
// normalises Gmpq after every operation, which dominated the erosion's profile).
using ExactKernel = CGAL::Lazy_kernel<CGAL::Simple_cartesian<CGAL::Quotient<ExactN>>>;

Exact abs_value(const Exact& x) { return x < 0 ? -x : x; }

/// An integer as Mpzf (CGAL's Mpzf(Gmpz) drops the sign and mishandles zero).
ExactN integer_n(const CGAL::Gmpz& z) {
  if (CGAL::sign(z) == 0) return ExactN(0);
  const ExactN magnitude(CGAL::abs(z));
  return CGAL::sign(z) < 0 ? ExactN(0) - magnitude : magnitude;
}

/// Runs of the incremental hull, each with a reach 2^20 times larger, before the exact route.
constexpr int kReachAttempts = 3;

/// A plane's exact normal and offset, where they are not a HalfSpace's own.
struct ExactPlane {
  V3<ExactN> n;
  ExactN d;
};

/// A half-space as the homogeneous plane <*n, x> <= *d (the HalfSpace times its
/// denominator, so both are dyadic), with interval copies for the filters. n and d point
/// at the HalfSpace's normal and offset when its denominator is 1 (the usual case: no Mpzf
/// copied per plane, where the filters decide nearly everything), else at `scaled`.
struct Plane {
  // The exact normal and offset, read through n() and d(): null for a lazy half-space's,
  // which are made on first read (HalfSpace::make_exact) and read from `source`.
  const V3<ExactN>* n_exact = nullptr;
  const ExactN* d_exact = nullptr;
  const V3<ExactN>& n() const { return n_exact ? *n_exact : source->exact_normal(); }
  const ExactN& d() const { return d_exact ? *d_exact : source->exact_offset(); }
  std::shared_ptr<const ExactPlane> scaled;
  V3<Interval> ni;
  Interval di;
  // Its normal's or offset's double-double copy, when it has one (denominator 1).
  const HalfSpace* source = nullptr;
  // The double filter's copy (see kMeetError): each component within one ulp of the exact
  // one (plus the gap to zero of a subnormal); na() and da() their absolute values (not
  // kept: the planes are read in scattered order, and a smaller one costs fewer cache
  // misses). `fast` when all are at most kFastRange (no overflow; underflow then stays
  // below kDoubleFloor).
  V3<double> nd{};
  double dd = 0;
  bool fast = false;
  V3<double> na() const { return {std::abs(nd.x), std::abs(nd.y), std::abs(nd.z)}; }
  double da() const { return std::abs(dd); }
};
/// A plane per half-space, made afresh for each intersection (huge_pages.h).
using Planes = std::vector<Plane, HugePageAllocator<Plane>>;

// The double filter. A vertex's X and W (Cramer's rule, meet_of_crosses) are evaluated in
// doubles from the planes' doubles, each coordinate with its magnitude M: the same
// polynomial on the absolute values of the inputs with every subtraction turned into an
// addition. In any rounding mode an operation errs by at most one ulp, v = 2^-52 of its
// result (while no underflow), and each input double by at most 2v of itself (an interval
// end, a double-double's hi). Counting the relative error factors (1 + v) along each
// monomial (Higham's theta_k): an input 2, a cross product 2 (product, difference), then
// the product and two additions of W = <n_a, bc> or X = d_a bc + d_b ca + d_c ab, so
// |computed - exact| <= gamma_k M with k = 3 * 2 + 2 + 3 = 11 for X and W (gamma_k =
// k v / (1 - k v)); the computed magnitude is within (1 + v)^11 of M's exact value. A
// side <h, X> - d W adds h's 2, a product and three additions: k = 17; a comparison
// <n, Xu> Wv - <n, Xv> Wu: 2 + 11 + 1 + 2 for <n, X>, then 11 + 1 for the product and 1
// for the difference: k = 29. The bounds below take 16 v, 32 v and 64 v of the computed
// magnitude: above gamma_k M with room for the magnitude's own rounding.
// Underflow: an operation that underflows (or an input that is subnormal) errs by at most
// 2^-1074 absolutely (a subnormal's spacing, any mode). That error moves the result by at
// most its derivative with respect to that value, a polynomial in the inputs of degree 6 at
// most with fewer than 2^10 monomials (the comparison's 648), each of them below 2^360 with
// every input at most kFastRange = 2^60 in absolute value: fewer than 2^8 operations then
// move it by less than 2^(-1074 + 360 + 10 + 8): kDoubleFloor = 2^-600 covers them all (and
// the magnitudes' own underflow). No overflow: every value stays below 2^(420 + 10).
constexpr double kFastRange = 0x1p60;
constexpr double kDoubleFloor = 0x1p-600;
constexpr double kMeetError = 0x1p-48;     // X, W: 16 v of their magnitude
constexpr double kSideError = 0x1p-47;     // <h, X> - d W: 32 v
constexpr double kCompareError = 0x1p-46;  // <n, Xu> Wv - <n, Xv> Wu: 64 v

/// Sets a plane's double filter copy (the normal and offset already set as intervals).
void set_doubles(Plane& p) {
  const HalfSpace* h = p.source;
  const auto pick = [](const Interval& i, const DD* dd) { return dd ? dd->hi : i.inf(); };
  const bool nd = h && h->has_normal_dd, od = h && h->has_offset_dd;
  p.nd = {pick(p.ni.x, nd ? &h->normal_dd[0] : nullptr),
          pick(p.ni.y, nd ? &h->normal_dd[1] : nullptr),
          pick(p.ni.z, nd ? &h->normal_dd[2] : nullptr)};
  p.dd = pick(p.di, od ? &h->offset_dd : nullptr);
  const V3<double> na = p.na();
  p.fast = na.x <= kFastRange && na.y <= kFastRange && na.z <= kFastRange &&
           p.da() <= kFastRange;  // (false for NaN)
}

/// The magnitude of a cross product: |a| x |b| with its subtraction an addition.
V3<double> magnitude_cross(const V3<double>& a, const V3<double>& b) {
  return {a.y * b.z + a.z * b.y, a.z * b.x + a.x * b.z, a.x * b.y + a.y * b.x};
}

/// The enclosure of a double-double copy (HalfSpace::normal_dd, offset_dd: the value lies
/// within half the gap to a neighbour of hi, plus 2^-101 |hi|, of hi): hi's two neighbours,
/// from its bit pattern. No rounded operation, so the same in any rounding mode (also under
/// valgrind, which keeps round-to-nearest: hi + lo + [-e, e] rounded would collapse there).
Interval neighbours_interval(const DD& c) {
  if (c.hi == 0) return Interval(0);  // then the value is zero
  std::uint64_t bits;
  std::memcpy(&bits, &c.hi, sizeof bits);
  double away, toward;  // |away| > |hi| > |toward|, same signs (toward may be zero)
  const std::uint64_t up = bits + 1, down = bits - 1;
  std::memcpy(&away, &up, sizeof away);
  std::memcpy(&toward, &down, sizeof toward);
  return c.hi > 0 ? Interval(toward, away) : Interval(away, toward);
}

/// The planes' dual points about an interior point o, p = n / (d - <n, o>), in doubles, each
/// coordinate within `error` of the exact one (negative: no copy): a filter for the tests
/// of four planes that flips make. The side of plane i at the vertex of planes a, b, c is
/// the sign of det(p_b - p_i, p_a - p_i, p_c - p_i) (with o at the origin, the plane through
/// p_a, p_b, p_c is {q : <q, y> = 1} for their vertex y, and det(p_a, p_b, p_c) > 0), and
/// det(n_a, n_b, n_c) has the sign of det(p_a, p_b, p_c) (each p a positive multiple of its
/// n). It reads 32 bytes a plane, where the exact tests read a Plane (about 150 bytes) and
/// make a 208-byte vertex per triangle, most of them dropped again by the next flip.
struct DualPoint {
  V3<double> p;
  double error = -1;
};
using DualPoints = std::vector<DualPoint>;  // (one array: one cache line a point)

/// Plane q's dual point about o, or none (error -1). The error bound (any rounding mode; u = 2^-52
/// an operation, 2 u an input: nd and dd are within an ulp of the exact n and d, as for the double
/// filter): e = d - <n, o> is computed within E = 8 u (|dd| + <|nd|, |o|> + |e|) (two u for dd,
/// seven for the dot product and its inputs, one for the difference); each coordinate n_j / e is
/// then within (2 u + u + E / e) of itself relative, taken as 1.25 times that, plus 2^-1073 / e for
/// a normal component below the subnormal range. A plane gets a copy only when e > 0 with E <=
/// 2^-20 e and |n|, d and p within [2^-300, 2^300] or 0: a determinant of the points or their
/// differences (below 2^301) then stays below 2^910 (no overflow), and what its products lose to
/// underflow (2^-1074 each, times at most 2^301) is within kDoubleFloor.
DualPoint dual_point(const Plane& q, const V3<double>& o) {
  constexpr double u = 0x1p-52, kLow = 0x1p-300, kHigh = 0x1p300;
  const V3<double> na = q.na();
  const auto sane = [&](double x) { return x == 0 || (x >= kLow && x <= kHigh); };
  if (!q.fast || !sane(na.x) || !sane(na.y) || !sane(na.z) || !sane(q.da())) return {};
  const double m = na.x * std::abs(o.x) + na.y * std::abs(o.y) + na.z * std::abs(o.z);
  const double e = q.dd - dot(q.nd, o);
  const double E = 8 * u * (q.da() + m + std::abs(e));
  if (!(e > 0) || E > 0x1p-20 * e) return {};
  const V3<double> p{q.nd.x / e, q.nd.y / e, q.nd.z / e};
  const double big = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  if (!sane(std::abs(p.x)) || !sane(std::abs(p.y)) || !sane(std::abs(p.z))) return {};
  return {p, 1.25 * (2 * u + u + E / e) * big + 0x1p-1073 / e};
}

/// A plane per half-space; with `dual`, also each one's dual point about *about (made here,
/// while the plane is at hand, rather than in a second pass over all of them).
Planes planes_of(const HalfSpaces& hs, const V3<double>* about = nullptr,
                 DualPoints* dual = nullptr) {
  Planes planes(hs.size());
  if (dual) dual->resize(hs.size());
  parallel_chunks(static_cast<int>(hs.size()), 256, [&](int begin, int end) {
    RoundingGuard guard;
    for (int i = begin; i < end; ++i) {
      Plane& p = planes[i];
      const HalfSpace& h = hs[i];
      const bool unit = h.unit_denominator();
      if (unit) {
        // (A lazy half-space's values have no address yet: read from `source`, set below.)
        if (!h.lazy) {
          p.n_exact = &h.exact_normal();
          p.d_exact = &h.exact_offset();
        }
      } else {
        // (The offset is the numerator: the plane is the HalfSpace times q.)
        const ExactN& q = h.denominator();
        const V3<ExactN>& n = h.exact_normal();
        p.scaled = std::make_shared<const ExactPlane>(
            ExactPlane{{n.x * q, n.y * q, n.z * q}, h.exact_offset()});
        p.n_exact = &p.scaled->n;
        p.d_exact = &p.scaled->d;
      }
      if (unit && (h.has_normal_dd || h.has_offset_dd)) p.source = &h;
      if (unit && h.has_normal_dd) {
        // The normal's enclosure from its double-double copy (cheaper than from Mpzf).
        const auto& c = h.normal_dd;
        p.ni = {neighbours_interval(c[0]), neighbours_interval(c[1]), neighbours_interval(c[2])};
      } else {
        p.ni = to_interval_n(p.n());
      }
      p.di = unit && h.has_offset_dd ? neighbours_interval(h.offset_dd) : to_interval_n(p.d());
      set_doubles(p);
      if (dual) (*dual)[i] = dual_point(p, *about);
    }
  });
  return planes;
}

Exact rational_offset(const HalfSpace& h) {
  return Exact(h.exact_offset()) / Exact(h.denominator());
}

/// Chebyshev-like centre for the L1 norm: maximise t subject to
/// <n_i, x> + |n_i|_1 t <= d_i, t <= 1. t* > 0: a solid (x* strictly inside);
/// t* = 0: flat; t* < 0: empty.
struct CentreResult {
  Exact t;
  V3<Exact> x;
};
CentreResult exact_centre(const HalfSpaces& hs) {
  using Program = CGAL::Quadratic_program<Exact>;
  Program lp(CGAL::SMALLER, false, 0, false, 0);
  for (int i = 0; i < static_cast<int>(hs.size()); ++i) {
    const V3<Exact> n = to_rational(hs[i].exact_normal());
    lp.set_a(0, i, n.x);
    lp.set_a(1, i, n.y);
    lp.set_a(2, i, n.z);
    lp.set_a(3, i, abs_value(n.x) + abs_value(n.y) + abs_value(n.z));
    lp.set_b(i, rational_offset(hs[i]));
  }
  lp.set_u(3, true, Exact(1));
  lp.set_c(3, Exact(-1));
  const auto solution = CGAL::solve_linear_program(lp, Exact());
  if (!solution.is_optimal())
    throw error("internal error: the centre of an erosion could not be found");
  std::vector<Exact> value;
  for (auto it = solution.variable_values_begin(); it != solution.variable_values_end(); ++it)
    value.push_back(it->numerator() / it->denominator());
  return {value[3], {value[0], value[1], value[2]}};
}

/// o strictly inside every half-space? (interval filter, exact when undecided)
bool strictly_inside(const Planes& planes, const V3<double>& o) {
  const V3<Interval> oi = to_interval(o);
  std::atomic<bool> inside = true;
  parallel_chunks(static_cast<int>(planes.size()), 512, [&](int begin, int end) {
    RoundingGuard guard;
    const V3<ExactN> oe = to_exact_n(o);
    for (int i = begin; i < end && inside; ++i) {
      int s = interval_sign(planes[i].di - dot(planes[i].ni, oi));
      if (s == 2) s = CGAL::sign(planes[i].d() - dot(planes[i].n(), oe));
      if (s <= 0) inside = false;
    }
  });
  return inside;
}

/// Exact homogeneous coordinates of a vertex.
struct ExactCoordinates {
  V3<ExactN> X;
  ExactN W;
};

/// A vertex of the intersection in homogeneous coordinates: X / W with W > 0, the meet
/// of three of the planes. The exact coordinates are computed only where the filters
/// (intervals, then double-double) cannot decide, or for a polytope chained further.
struct HVertex {
  // User-provided: a value-initialised HVertex (VertexStore::add_range's, by the thousand)
  // is then built by its member initialisers alone, not first zeroed whole (rep stos per
  // vertex: up to 1.6% of an erosion).
  HVertex() {}
  std::array<int, 3> planes{};
  int known = -1;  // the known point it is (KnownPoints), if any
  // Read only where `intervals` or `fast` is set.
  V3<Interval> Xi{Interval(0), Interval(0), Interval(0)};
  Interval Wi{0};  // (X / W as Xi / Wi where needed: quotient, not kept)
  // The exact coordinates, once known (X not null): a known point's are KnownPoints' own
  // (not copied: most are never read), another's are made on first need into `made`. Off
  // the vertex itself (four Mpzf are 350 bytes), which the flips and the check create,
  // move and reset by the thousand while exact values are rarely read at all.
  const V3<ExactN>* X = nullptr;
  const ExactN* W = nullptr;
  std::unique_ptr<ExactCoordinates> made;
  // X and W times some positive factor in double-double, within ex and ew of the exact
  // ones times that factor (make_precise); only when `precise`.
  V3<DD> px{};
  DD pw{};
  V3<double> ex{};
  double ew = 0;
  bool precise = false;
  bool precise_tried = false;  // make_precise was called (it may have left it out)
  // A known point with W = 1 whose X is exactly px (hi + lo), pw = 1: its rounding is
  // hi + lo in one rounded addition, and its exact X is made from px where X is null (a
  // point of KnownPoints::dd; set_precise_known).
  bool exact_dd = false;
  bool doubles = false;  // a known point X / 1 with X exactly doubles: its rounding is X
  // Xi and Wi are set (`intervals`), or only the double filter's X and W with their
  // magnitudes (`fast`, made from fast planes: kMeetError), the intervals then made where
  // that filter cannot decide (make_intervals), most vertices never needing them. Those
  // doubles are kept in Xi and Wi (X and W as inf, their magnitudes as sup, unchecked): no
  // room of their own in a vertex that the flips and the checks move by the thousand.
  bool intervals = false;
  bool fast = false;
  V3<double> Xd() const { return {Xi.x.inf(), Xi.y.inf(), Xi.z.inf()}; }
  V3<double> MX() const { return {Xi.x.sup(), Xi.y.sup(), Xi.z.sup()}; }
  double Wd() const { return Wi.inf(); }
  double MW() const { return Wi.sup(); }
};
/// Vertices by the hundred thousand, made afresh for each intersection (huge_pages.h).
using HVertices = std::vector<HVertex, HugePageAllocator<HVertex>>;

/// The vertices a candidate surface has made, each at a stable index (a triangle keeps the
/// index of its own: DualSurface::slot). Most triangles never need theirs: a guess of an
/// icosphere of 327,680 facets eroded by a small icosphere makes 19,456 of its 655,356
/// triangles' vertices, where one per triangle mapped 136 MB whose first touch (page
/// zeroing) was a quarter of the erosion's time on one run. Storage grows in segments
/// that double (256 vertices, then 256, 512, ...; the large ones huge_pages.h's), made
/// when first needed and never moved, so a reference stays valid while others are added.
/// `add` and `add_range` may run on several threads at once (a new segment is made under a
/// lock; `reserve` makes them beforehand). A vertex is read and written by the thread that
/// added it, or after a synchronisation with it. Indices a caller no longer uses it may
/// give out again from its own list (add_reusing).
class VertexStore {
 public:
  VertexStore() = default;
  VertexStore(const VertexStore&) = delete;
  VertexStore& operator=(const VertexStore&) = delete;
  VertexStore(VertexStore&& o) noexcept { take(o); }
  VertexStore& operator=(VertexStore&& o) noexcept {
    if (this != &o) {
      clear();
      take(o);
    }
    return *this;
  }
  ~VertexStore() { clear(); }

  int size() const { return static_cast<int>(size_.load(std::memory_order_relaxed)); }
  HVertex& operator[](int i) { return at(static_cast<std::size_t>(i)); }
  const HVertex& operator[](int i) const { return const_cast<VertexStore&>(*this).at(i); }

  /// Room for `count` more vertices, so that adding them needs no new segment.
  void reserve(std::size_t count) { make_segments(size_.load() + count); }
  /// `count` new default vertices in a row; the first's index.
  int add_range(int count) {
    const std::size_t first = size_.fetch_add(count, std::memory_order_relaxed);
    make_segments(first + count);  // (nothing to do after `reserve`)
    for (std::size_t i = first; i < first + count; ++i) new (&at(i)) HVertex();
    return static_cast<int>(first);
  }
  int add(HVertex&& v) {
    const int i = add_range(1);
    (*this)[i] = std::move(v);
    return i;
  }
  /// v at an index taken from `free` (the caller's indices no longer used), else a new one.
  int add_reusing(HVertex&& v, std::vector<int>& free) {
    if (free.empty()) return add(std::move(v));
    const int i = free.back();
    free.pop_back();
    (*this)[i] = std::move(v);
    return i;
  }

 private:
  static constexpr int kBaseBits = 8;  // the first segments' 256 vertices
  static constexpr int kMaxSegments = 64 - kBaseBits;
  using Allocator = HugePageAllocator<HVertex>;
  // Segment k >= 1 holds indices [256 * 2^(k-1), 256 * 2^k), segment 0 the first 256.
  static int segment_of(std::size_t i) {
    const std::size_t q = i >> kBaseBits;
    return q == 0 ? 0 : 64 - __builtin_clzll(q);
  }
  static std::size_t segment_start(int k) {
    return k == 0 ? 0 : std::size_t{1} << (kBaseBits + k - 1);
  }
  static std::size_t segment_size(int k) {
    return std::size_t{1} << (k == 0 ? kBaseBits : kBaseBits + k - 1);
  }
  HVertex& at(std::size_t i) {
    const int k = segment_of(i);
    return segment_[k].load(std::memory_order_acquire)[i - segment_start(k)];
  }
  void make_segments(std::size_t count) {
    if (count == 0) return;
    const int last = segment_of(count - 1);
    if (segment_[last].load(std::memory_order_acquire)) return;  // (each made in order)
    const std::lock_guard<std::mutex> lock(grow_);
    for (int k = 0; k <= last; ++k)
      if (!segment_[k].load(std::memory_order_relaxed))
        segment_[k].store(Allocator().allocate(segment_size(k)), std::memory_order_release);
  }
  void take(VertexStore& o) {
    for (int k = 0; k < kMaxSegments; ++k)
      segment_[k].store(o.segment_[k].exchange(nullptr, std::memory_order_relaxed),
                        std::memory_order_relaxed);
    size_ = o.size_.exchange(0, std::memory_order_relaxed);
  }
  void clear() {
    const std::size_t n = size_.load(std::memory_order_relaxed);
    for (std::size_t i = 0; i < n; ++i) at(i).~HVertex();
    for (int k = 0; k < kMaxSegments; ++k)
      if (HVertex* p = segment_[k].exchange(nullptr, std::memory_order_relaxed))
        Allocator().deallocate(p, segment_size(k));
    size_ = 0;
  }

  std::array<std::atomic<HVertex*>, kMaxSegments> segment_{};
  std::atomic<std::size_t> size_{0};
  std::mutex grow_;
};

/// A candidate dual hull: triangles over plane indices, counter-clockwise seen from
/// outside, and the triangle across each edge (edge k runs from corner k to corner k + 1).
/// The vertex of a triangle's three planes (vertex_of, in the corners' order) may come
/// with it, when the candidate's construction computed it already (has_vertex(t)).
struct DualSurface {
  std::vector<std::array<int, 3>> corner;
  std::vector<std::array<int, 3>> across;
  // Empty (no vertices kept), or per triangle the index of its vertex in `vertices`, -1
  // where it has none yet.
  std::vector<int> slot;
  VertexStore vertices;
  // Empty, or per plane: a triangle near the plane's dual point, for one that is not on the
  // surface (removed by a repair), where the check's climb starts; -1 where none is known.
  std::vector<int> near;
  // Set by a repair, or for a guess of A's own fans (certify): every triangle is known
  // positively oriented. far_side (3 per triangle, or empty): the check's far-plane signs
  // where known, else 2; a guess knows those of its polygons' diagonals
  // (triangulate_polygon), a repair those of the triangles it left, with the same
  // neighbours.
  bool oriented = false;
  std::vector<signed char> far_side;
  // Empty, or per plane: 1 where a repair removed it from the surface (a 3-1 flip, or a fan
  // of its neighbours where a flip would fold). Its dual point then lay strictly beneath
  // the triangle of three of its neighbours' planes, in that triangle's cone:
  // strictly inside the hull of o and dual points that end on the surface or inside its
  // hull, and o is strictly inside that hull; so its plane neither cuts nor touches the
  // result, and the check does not walk to it (see SurfaceRepair::remove).
  std::vector<char> inside;
  // The planes' dual points about the interior point the candidate was built about, when
  // it has them: the first filter of the check's and the repair's tests.
  std::shared_ptr<const DualPoints> dual;

  /// The far plane of triangle t's edge k: the corner of the triangle across it that is not
  /// on the edge (-1: none, a degenerate neighbour).
  bool keeps_vertices() const { return !slot.empty(); }
  bool has_vertex(int t) const { return slot[t] >= 0; }
  HVertex& vertex(int t) { return vertices[slot[t]]; }
  /// Triangle t's stored vertex (keeps_vertices), made now when it has none (needs a
  /// RoundingGuard), at an index from `free` when one is given (a repair's: see
  /// drop_vertex). Several threads may make the vertices of different triangles at once.
  HVertex& stored_vertex(int t, const Planes& planes, const KnownPoints& known,
                         std::vector<int>* free = nullptr);
  /// Triangle t's vertex dropped: its index goes to `free`, to be given out again.
  void drop_vertex(int t, std::vector<int>& free) {
    if (slot[t] >= 0) free.push_back(slot[t]);
    slot[t] = -1;
  }

  int far_corner(int t, int k) const {
    const int a = corner[t][k], b = corner[t][k == 2 ? 0 : k + 1];
    int far = -1;
    for (const int c : corner[across[t][k]])
      if (c != a && c != b) far = c;
    return far;
  }
};

/// The triangles of a hull computed by CGAL; empty when it is not a closed triangulated
/// sphere.
template <class HullMesh, class IndexOf>
DualSurface surface_of(const HullMesh& hull, const IndexOf& index_of) {
  DualSurface s;
  const auto nv = static_cast<long>(hull.number_of_vertices()),
             ne = static_cast<long>(hull.number_of_edges()),
             nf = static_cast<long>(hull.number_of_faces());
  if (nf < 4 || nv - ne + nf != 2 || !CGAL::is_closed(hull) || !CGAL::is_triangle_mesh(hull))
    return s;
  s.corner.resize(nf);
  s.across.resize(nf);
  for (auto f : hull.faces()) {
    auto h = hull.halfedge(f);
    for (int k = 0; k < 3; ++k) {
      s.corner[f.idx()][k] = index_of(hull.point(hull.target(h)));
      h = hull.next(h);
      s.across[f.idx()][k] = static_cast<int>(hull.face(hull.opposite(h)).idx());
    }
  }
  return s;
}

/// The point of three planes (Cramer's rule) from the cross products of their normals,
/// bc = n_b x n_c, ca = n_c x n_a, ab = n_a x n_b; W = det(n_a, n_b, n_c).
template <class T>
void meet_of_crosses(const V3<T>& na, const T& da, const T& db, const T& dc, const V3<T>& bc,
                     const V3<T>& ca, const V3<T>& ab, V3<T>& X, T& W) {
  W = dot(na, bc);
  X = {da * bc.x + db * ca.x + dc * ab.x, da * bc.y + db * ca.y + dc * ab.y,
       da * bc.z + db * ca.z + dc * ab.z};
}

/// The point of three planes (Cramer's rule); W = det(n_a, n_b, n_c).
template <class T>
void meet(const V3<T>& na, const T& da, const V3<T>& nb, const T& db, const V3<T>& nc, const T& dc,
          V3<T>& X, T& W) {
  meet_of_crosses(na, da, db, dc, cross(nb, nc), cross(nc, na), cross(na, nb), X, W);
}

/// The interval meet of a vertex's three planes, X and W (needs a RoundingGuard).
void interval_meet(const Planes& planes, const std::array<int, 3>& abc, V3<Interval>& Xi,
                   Interval& Wi) {
  const Plane &a = planes[abc[0]], &b = planes[abc[1]], &c = planes[abc[2]];
  meet(a.ni, a.di, b.ni, b.di, c.ni, c.di, Xi, Wi);
}
/// X / W of interval X and W (needs a RoundingGuard). Computed where it is read, rarely
/// (intervals of a vertex are mostly made for its sides), rather than kept in each vertex,
/// which the flips and the checks create, move and reset by the thousand.
V3<Interval> quotient(const V3<Interval>& Xi, const Interval& Wi) {
  return {Xi.x / Wi, Xi.y / Wi, Xi.z / Wi};
}
/// Gives v its intervals, when it has only doubles (needs a RoundingGuard).
void make_intervals(const Planes& planes, HVertex& v) {
  if (v.intervals) return;
  interval_meet(planes, v.planes, v.Xi, v.Wi);
  v.intervals = true;
  v.fast = false;  // (its doubles were in Xi and Wi)
}

/// The double filter's meet of fast planes a, b, c (kMeetError) from the doubles of their
/// normals' cross products bc, ca, ab and those products' magnitudes (magnitude_cross).
void double_meet(const Plane& a, const Plane& b, const Plane& c, const V3<double>& bc,
                 const V3<double>& ca, const V3<double>& ab, const V3<double>& mbc,
                 const V3<double>& mca, const V3<double>& mab, HVertex& v) {
  V3<double> X, MX;
  double W, MW;
  meet_of_crosses(a.nd, a.dd, b.dd, c.dd, bc, ca, ab, X, W);
  meet_of_crosses(a.na(), a.da(), b.da(), c.da(), mbc, mca, mab, MX, MW);  // (all additions)
  using Unchecked = Interval::no_check_t;
  v.Xi = {Interval(X.x, MX.x, Unchecked()), Interval(X.y, MX.y, Unchecked()),
          Interval(X.z, MX.z, Unchecked())};
  v.Wi = Interval(W, MW, Unchecked());
  v.fast = true;
  v.intervals = false;
}

/// The vertex of three planes: the double filter's when they are all fast, else intervals
/// (needs a RoundingGuard).
HVertex vertex_of(const Planes& planes, const std::array<int, 3>& abc) {
  HVertex v;
  v.planes = abc;
  const Plane &a = planes[abc[0]], &b = planes[abc[1]], &c = planes[abc[2]];
  if (a.fast && b.fast && c.fast) {
    double_meet(a, b, c, cross(b.nd, c.nd), cross(c.nd, a.nd), cross(a.nd, b.nd),
                magnitude_cross(b.na(), c.na()), magnitude_cross(c.na(), a.na()),
                magnitude_cross(a.na(), b.na()), v);
  } else {
    interval_meet(planes, abc, v.Xi, v.Wi);
    v.intervals = true;
  }
  return v;
}

/// An enclosure of X / W (needs a RoundingGuard): the vertex's Xi / Wi, or, for a vertex with
/// only doubles, X and W widened by kMeetError of their magnitudes when W > 0 is certain
/// (fewer operations than the interval meet), else the interval meet.
V3<Interval> enclosure_of(const Planes& planes, const HVertex& v);

/// Whether W > 0 is certain from the vertex's filter (false: undecided or not positive).
bool w_positive(const HVertex& v) {
  if (v.intervals) return v.Wi.inf() > 0;
  return v.fast && v.Wd() > kMeetError * v.MW() + kDoubleFloor;
}

V3<Interval> enclosure_of(const Planes& planes, const HVertex& v) {
  if (v.intervals) return quotient(v.Xi, v.Wi);
  if (!w_positive(v)) {
    V3<Interval> Xi;
    Interval Wi;
    interval_meet(planes, v.planes, Xi, Wi);
    return quotient(Xi, Wi);
  }
  const auto widened = [](double x, double m) {
    const double e = kMeetError * m + kDoubleFloor;  // (rounded up: the guard's mode)
    return Interval(x) + Interval(-e, e);
  };
  const Interval W = widened(v.Wd(), v.MW());
  const V3<double> X = v.Xd(), M = v.MX();
  return {widened(X.x, M.x) / W, widened(X.y, M.y) / W, widened(X.z, M.z) / W};
}

void set_precise_known(const V3<DD>& d, HVertex& v);

/// Makes v known point k, with its exact coordinates: KnownPoints' Mpzf, or its
/// double-double copy, which is then v's precise one and its exact value (exact_dd; X made
/// from it where it is read, make_exact).
void set_known(const KnownPoints& known, int k, HVertex& v) {
  v.known = k;
  v.Xi = known.Xi[k];
  v.Wi = known.Wi[k];
  v.intervals = true;
  v.fast = false;
  if (known.dd.empty()) {
    v.X = &known.X[k];
    v.W = &known.W[k];
    return;
  }
  v.X = nullptr;
  v.W = nullptr;
  v.made.reset();
  v.precise_tried = true;
  set_precise_known(known.dd[k], v);
}

/// A vertex of three planes taken from a known point when the three pass through one (and
/// their normals are independent: the meet is then that point).
void take_known(const KnownPoints& known, HVertex& v) {
  if (known.empty() || !w_positive(v)) return;
  const int k = known.common(v.planes[0], v.planes[1], v.planes[2]);
  if (k >= 0) set_known(known, k, v);
}

/// The vertex of three planes whose normals are known to be independent (det > 0, checked
/// exactly): a known point on all three is taken as it is, without the meet's intervals
/// (vertex_of needs those only to tell the normals independent).
HVertex independent_vertex_of(const Planes& planes, const std::array<int, 3>& abc,
                              const KnownPoints& known) {
  const int k = known.empty() ? -1 : known.common(abc[0], abc[1], abc[2]);
  if (k < 0) return vertex_of(planes, abc);  // (no known point: not looked for again)
  HVertex v;
  v.planes = abc;
  set_known(known, k, v);
  return v;
}

HVertex& DualSurface::stored_vertex(int t, const Planes& planes, const KnownPoints& known,
                                    std::vector<int>* free) {
  if (slot[t] < 0) {
    HVertex v = independent_vertex_of(planes, corner[t], known);
    slot[t] = free ? vertices.add_reusing(std::move(v), *free) : vertices.add(std::move(v));
  }
  return vertices[slot[t]];
}

/// Whether plane i is known to pass through vertex v (no arithmetic).
bool known_through(const KnownPoints& known, int i, const HVertex& v) {
  return v.known >= 0 && known.passes(i, v.known);
}

/// Gives v exact coordinates of its own (`made`).
void set_exact(HVertex& v, V3<ExactN> X, ExactN W) {
  v.made = std::make_unique<ExactCoordinates>(ExactCoordinates{std::move(X), std::move(W)});
  v.X = &v.made->X;
  v.W = &v.made->W;
}

/// Computes the exact coordinates of a vertex, once: from its double-double copy when that
/// is exact (a known point's, set_known), else as the meet of its planes.
void make_exact(const Planes& planes, HVertex& v) {
  if (v.X) return;
  if (v.exact_dd) {
    set_exact(v, exact_value(v.px), ExactN(1));
    return;
  }
  const Plane &a = planes[v.planes[0]], &b = planes[v.planes[1]], &c = planes[v.planes[2]];
  v.made = std::make_unique<ExactCoordinates>();
  meet(a.n(), a.d(), b.n(), b.d(), c.n(), c.d(), v.made->X, v.made->W);
  v.X = &v.made->X;
  v.W = &v.made->W;
}

// The precise stage. Every value below is a polynomial in precise components (a plane's
// n and d, a vertex's X and W), evaluated in double-double (round-to-nearest) along with
// its magnitude: the same polynomial on the |hi| of its inputs with every subtraction
// turned into an addition, which bounds every term and partial sum. Its error is bounded
// by (a) the inputs' errors: kPlaneRelative of |hi| per plane component (a monomial of
// degree k moves by at most k kPlaneRelative of its magnitude, to first order), and what a
// vertex's ex and ew move; (b) the evaluation: at most five levels of operations, each
// within 4 u^2 of its operands' magnitudes, so 20 u^2 of the magnitude, taken as 32 u^2;
// (c) underflow, an absolute term. A margin of 1% covers second-order terms and the
// rounding of the bound itself.

/// The magnitude arithmetic: subtraction adds.
struct Magnitude {
  double v;
  friend Magnitude operator+(Magnitude a, Magnitude b) { return {a.v + b.v}; }
  friend Magnitude operator-(Magnitude a, Magnitude b) { return {a.v + b.v}; }
  friend Magnitude operator*(Magnitude a, Magnitude b) { return {a.v * b.v}; }
};
Magnitude magnitude(const DD& x) { return {std::abs(x.hi)}; }
V3<Magnitude> magnitude(const V3<DD>& p) {
  return {magnitude(p.x), magnitude(p.y), magnitude(p.z)};
}

constexpr double kEvaluation = 32 * kU2;  // (b)

/// Relative error of each component of a precise plane (a).
constexpr double kPlaneRelative = 0x1p-100;

/// newton_meet's largest accepted bound, relative to the vertex's largest coordinate.
constexpr double kNewtonAccepted = 0x1p-80;

/// Four exact values in double-double, each within kPlaneRelative of |hi|, all scaled by
/// the power of two that brings the largest |c[k]|, k in [lead_begin, lead_end), into
/// [1, 2); false when a value is beyond 2^400 or a non-zero one below 2^-900 after that
/// (round-to-nearest).
/// `given`, when not null, holds c[0] .. c[2] already in double-double, each within
/// kPlaneRelative / 2 of its |hi| (HalfSpace::normal_dd); `given_last` c[3] alike
/// (HalfSpace::offset_dd).
bool precise_scaled(const std::array<const ExactN*, 4>& c, int lead_begin, int lead_end,
                    std::array<DD, 4>& out, const std::array<DD, 3>* given = nullptr,
                    const DD* given_last = nullptr) {
  std::array<DD, 4> v{};
  double largest = 0;
  for (int k = 0; k < 4; ++k) {
    if ((given && k < 3) || (given_last && k == 3)) {
      v[k] = k < 3 ? (*given)[k] : *given_last;
      if (k >= lead_begin && k < lead_end) largest = std::max(largest, std::abs(v[k].hi));
      continue;
    }
    if (CGAL::sign(*c[k]) == CGAL::ZERO) continue;
    double error;
    v[k] = to_dd(*c[k], error);
    // Half the allowed error: scaling may round a subnormal lo (by 2^-1075 at most).
    if (!(error <= kPlaneRelative / 2 * std::abs(v[k].hi))) return false;
    if (k >= lead_begin && k < lead_end) largest = std::max(largest, std::abs(v[k].hi));
  }
  if (!(largest >= 0x1p-1000 && largest < 0x1p1000)) return false;
  const double scale = std::ldexp(1.0, -std::ilogb(largest));  // exact products
  for (int k = 0; k < 4; ++k) {
    if (v[k].hi == 0) continue;
    v[k] = {v[k].hi * scale, v[k].lo * scale};
    if (!(std::abs(v[k].hi) >= 0x1p-900 && std::abs(v[k].hi) <= 0x1p400)) return false;
  }
  out = v;
  return true;
}

/// x exactly as a double-double hi + lo (round-to-nearest), or false when it is not one (or
/// out of range). to_dd's enclosure of x - hi may be loose where x spans two Mpzf limbs:
/// then an exact comparison tells whether x - hi is one of its ends.
bool split_exactly(const ExactN& x, DD& out) {
  if (CGAL::sign(x) == CGAL::ZERO) {
    out = {0, 0};
    return true;
  }
  const double hi = x.to_double();  // within an ulp of x
  if (!std::isfinite(hi)) return false;
  const ExactN rest = x - ExactN(hi);
  const std::pair<double, double> r = rest.to_interval();
  double lo = r.first;
  if (r.first != r.second) {
    if (rest == ExactN(r.second))
      lo = r.second;
    else if (!(rest == ExactN(r.first)))
      return false;
  }
  out = quick_two_sum(hi, lo);  // exact: |lo| is at most an ulp of hi
  return true;
}

/// A plane's n.x, n.y, n.z, d times a power of two (any positive factor leaves every sign
/// and every meet unchanged) in double-double: precise_scaled with the largest normal
/// component in [1, 2), so |d| <= 2^400 and every non-zero component is above 2^-900 (the
/// precise stage neither overflows nor loses a component). Not valid() out of that range.
/// One cache line: a vertex reads three planes, scattered (with a flag beside them, 72
/// bytes, each plane spanned two lines).
struct alignas(64) PrecisePlane {
  std::array<DD, 4> c{};  // all zero when not valid (precise_scaled leaves it)
  /// A valid plane's largest normal component is in [1, 2).
  bool valid() const { return c[0].hi != 0 || c[1].hi != 0 || c[2].hi != 0; }
};
static_assert(sizeof(PrecisePlane) == 64);
PrecisePlane precise_plane(const Plane& plane) {
  PrecisePlane p;
  const HalfSpace* h = plane.source;
  // (A lazy half-space has both copies: its exact values are not read here.)
  if (h && !(h->has_normal_dd && h->has_offset_dd)) h->make_exact();
  const V3<ExactN>* n = plane.n_exact;  // (null, and not read, where both copies are given)
  precise_scaled({n ? &n->x : nullptr, n ? &n->y : nullptr, n ? &n->z : nullptr, plane.d_exact}, 0,
                 3, p.c, h && h->has_normal_dd ? &h->normal_dd : nullptr,
                 h && h->has_offset_dd ? &h->offset_dd : nullptr);
  return p;
}
V3<DD> normal_dd(const PrecisePlane& p) { return {p.c[0], p.c[1], p.c[2]}; }
V3<Magnitude> normal_magnitude(const PrecisePlane& p) { return magnitude(normal_dd(p)); }

/// The precise meet of valid planes a, b, c (round-to-nearest): W = <n_a, bc> and
/// X = d_a bc + n_a x (d_c n_b - d_b n_c), which is Cramer's d_a bc + d_b ca + d_c ab
/// (n_a x (d_c n_b - d_b n_c) = d_c ab + d_b ca) with two cross products instead of three
/// (and no edge crosses to share between vertices). Expanded, it has Cramer's monomials, so
/// the same magnitude, computed here the same way on absolute values; and five levels of
/// operations as Cramer's (products, differences, products, differences, sums), so the same
/// evaluation bound.
[[gnu::flatten]] void precise_meet(const PrecisePlane& a, const PrecisePlane& b,
                                   const PrecisePlane& c, HVertex& v) {
  const V3<DD> na = normal_dd(a), nb = normal_dd(b), nc = normal_dd(c);
  const DD &da = a.c[3], &db = b.c[3], &dc = c.c[3];
  const V3<DD> bc = cross(nb, nc);
  const V3<DD> m{dc * nb.x - db * nc.x, dc * nb.y - db * nc.y, dc * nb.z - db * nc.z};
  const V3<DD> am = cross(na, m);
  v.pw = dot(na, bc);
  v.px = {da * bc.x + am.x, da * bc.y + am.y, da * bc.z + am.z};
  const V3<double> ma{std::abs(na.x.hi), std::abs(na.y.hi), std::abs(na.z.hi)},
      mb{std::abs(nb.x.hi), std::abs(nb.y.hi), std::abs(nb.z.hi)},
      mc{std::abs(nc.x.hi), std::abs(nc.y.hi), std::abs(nc.z.hi)};
  const double mda = std::abs(da.hi), mdb = std::abs(db.hi), mdc = std::abs(dc.hi);
  const V3<double> mbc = magnitude_cross(mb, mc);
  const V3<double> mm{mdc * mb.x + mdb * mc.x, mdc * mb.y + mdb * mc.y, mdc * mb.z + mdb * mc.z};
  const V3<double> mam = magnitude_cross(ma, mm);
  const double mw = ma.x * mbc.x + ma.y * mbc.y + ma.z * mbc.z;
  // Degree 3 in the planes' components; underflow in a product is multiplied by at most
  // |d| or |n| afterwards (no overflow: |n| < 2, |d| <= 2^400).
  constexpr double factor = (3 * kPlaneRelative + kEvaluation) * 1.01;
  const double absolute = 0x1p-960 * (1 + mda + mdb + mdc);
  v.ex = {factor * (mda * mbc.x + mam.x) + absolute, factor * (mda * mbc.y + mam.y) + absolute,
          factor * (mda * mbc.z + mam.z) + absolute};
  v.ew = factor * mw + 0x1p-960;
  v.precise = true;
}

/// The vertex of valid planes a, b, c as x = X / W itself (px = x, pw = 1, ew = 0: the
/// rounding is then one comparison per coordinate), by one Newton step from Cramer's rule in
/// doubles, fewer operations than precise_meet; false (v untouched) when its bound
/// is not small or a value out of range (round-to-nearest). With the normals' highs N_i (rows
/// of J), x0 = J^-1 d in doubles, s_i = d_i - <n_i, x0> in double-double, delta = J^-1 s in
/// doubles, x = x0 + delta (two_sum: exact). Nothing in the step needs analysing: the bound is
/// a posteriori, from the residual of x itself. With the exact (scaled) planes n*_i, d*_i,
/// x* = J*^-1 d*, so x - x* = -J*^-1 r* for r*_i = d*_i - <n*_i, x>, and J*^-1 has columns
/// bc*, ca*, ab* / W* (Cramer). Hence |x_k - x*_k| <= sum_i |cross*_i,k| |r*_i| / W*, where
///  - |cross*_i,k| <= |cross_i,k| + 2^-50 of its double magnitude: n* is within eta = 2^-53 +
///    2^-100 of |N| per component (lo and the plane's error), which moves the cross product
///    by 2.01 eta of its magnitude, and its evaluation errs by 2 u of it; plus underflow;
///  - W* >= w_low = W - 2^-48 MW - 2^-1000: W's evaluation errs by 5.01 u MW, the
///    perturbation of N by 3.01 eta MW (8.1 u in all, taken as 32 u), products underflow by
///    2^-1074 each; w_low > 0 is required (so W* > 0: pw = 1 is W times a positive factor);
///  - |r*_i| <= |t_i| + E_i, t_i = (p_i - <N_i, delta>) + q_i in doubles, s_i = p_i + q_i
///    (residual): p_i and the terms summed in q_i are exact but for the products of the
///    normal's lo (each within u^2 |N| |x0|), and those ten terms total at most 6.01 u M_i
///    (M_i = |d_i| + <|N_i|, |x0|>: each q, lo or two_prod rest is within u of a partial
///    sum, a product or d), so q_i errs by 56 u^2 M_i; then t_i by 2.01 u |s_i| + 6.02 u D_i
///    + 13 u^2 M_i more (D_i = <|N_i|, |delta|>; the normal's lo times delta is within u D_i;
///    |s_i| <= |p_i| + 7 u M_i), 8 u (|p_i| + D_i) + 128 u^2 M_i in all; the planes err by
///    2^-100 (M_i + D_i) (|x| <= |x0| + |delta|); underflow stays below 2^-950. E_i =
///    8 u (|p_i| + D_i) + (128 u^2 + 2^-100) (M_i + D_i) + 2^-950.
/// The factor 1.01 covers the rounding of the bound's own evaluation (and of 1 / w_low).
/// The ranges: |N| < 2 and |d| <= 2^400 (valid planes), |x0| <= 2^400 checked, so no
/// product overflows or loses its split; x's components are zero or in [2^-900, 2^400], as
/// precise_scaled's, for the tests that read px.
[[gnu::flatten]] bool newton_meet(const PrecisePlane& a, const PrecisePlane& b,
                                  const PrecisePlane& c, HVertex& v) {
  const V3<double> Na{a.c[0].hi, a.c[1].hi, a.c[2].hi}, Nb{b.c[0].hi, b.c[1].hi, b.c[2].hi},
      Nc{c.c[0].hi, c.c[1].hi, c.c[2].hi};
  const V3<double> bc = cross(Nb, Nc), ca = cross(Nc, Na), ab = cross(Na, Nb);
  const double W = dot(Na, bc);
  const auto absolute = [](const V3<double>& p) {
    return V3<double>{std::abs(p.x), std::abs(p.y), std::abs(p.z)};
  };
  const V3<double> Ma = absolute(Na), Mb = absolute(Nb), Mc = absolute(Nc);
  const V3<double> mbc = magnitude_cross(Mb, Mc), mca = magnitude_cross(Mc, Ma),
                   mab = magnitude_cross(Ma, Mb);
  const double w_low = W - 0x1p-48 * dot(Ma, mbc) - 0x1p-1000;
  if (!(w_low > 0)) return false;
  const double inverse = 1 / W;
  const double da = a.c[3].hi, db = b.c[3].hi, dc = c.c[3].hi;
  const V3<double> x0{(da * bc.x + db * ca.x + dc * ab.x) * inverse,
                      (da * bc.y + db * ca.y + dc * ab.y) * inverse,
                      (da * bc.z + db * ca.z + dc * ab.z) * inverse};
  if (!(std::abs(x0.x) <= 0x1p400 && std::abs(x0.y) <= 0x1p400 && std::abs(x0.z) <= 0x1p400))
    return false;
  // s = p + q unevaluated (Ogita, Rump and Oishi's Dot2): two_prod and two_sum exact, the
  // rest of them summed in q.
  const auto residual = [&](const PrecisePlane& p) {
    const DD h0 = two_prod(p.c[0].hi, x0.x), h1 = two_prod(p.c[1].hi, x0.y),
             h2 = two_prod(p.c[2].hi, x0.z);
    const DD s0 = two_sum(p.c[3].hi, -h0.hi), s1 = two_sum(s0.hi, -h1.hi),
             s2 = two_sum(s1.hi, -h2.hi);
    const double rest = (p.c[0].lo * x0.x + p.c[1].lo * x0.y) + p.c[2].lo * x0.z;
    const double q = (p.c[3].lo + ((s0.lo + s1.lo) + s2.lo)) - (((h0.lo + h1.lo) + h2.lo) + rest);
    return DD{s2.hi, q};
  };
  const DD sa = residual(a), sb = residual(b), sc = residual(c);
  const double ta = sa.hi + sa.lo, tb = sb.hi + sb.lo, tc = sc.hi + sc.lo;
  const V3<double> delta{(ta * bc.x + tb * ca.x + tc * ab.x) * inverse,
                         (ta * bc.y + tb * ca.y + tc * ab.y) * inverse,
                         (ta * bc.z + tb * ca.z + tc * ab.z) * inverse};
  const V3<DD> x{two_sum(x0.x, delta.x), two_sum(x0.y, delta.y), two_sum(x0.z, delta.z)};
  const auto in_range = [](double h) {
    return h == 0 || (std::abs(h) >= 0x1p-900 && std::abs(h) <= 0x1p400);
  };
  if (!(in_range(x.x.hi) && in_range(x.y.hi) && in_range(x.z.hi))) return false;
  const V3<double> ax0 = absolute(x0), adelta = absolute(delta);
  const auto bound = [&](const V3<double>& N, const V3<double>& M, double d, const DD& s) {
    const double D = dot(M, adelta), m = std::abs(d) + dot(M, ax0);
    const double t = (s.hi - dot(N, delta)) + s.lo;
    return std::abs(t) + 8 * 0x1p-53 * (std::abs(s.hi) + D) +
           (128 * kU2 + kPlaneRelative) * (m + D) + 0x1p-950;
  };
  const double ra = bound(Na, Ma, da, sa), rb = bound(Nb, Mb, db, sb), rc = bound(Nc, Mc, dc, sc);
  // |cross*| <= |cross| + 2^-50 of its magnitude (below).
  const auto adj = [](const V3<double>& p, const V3<double>& m) {
    return V3<double>{std::abs(p.x) + 0x1p-50 * m.x, std::abs(p.y) + 0x1p-50 * m.y,
                      std::abs(p.z) + 0x1p-50 * m.z};
  };
  const V3<double> Abc = adj(bc, mbc), Aca = adj(ca, mca), Aab = adj(ab, mab);
  const double scale = 1.01 / w_low, under = 0x1p-1000 * (ra + rb + rc);
  const V3<double> ex{(Abc.x * ra + Aca.x * rb + Aab.x * rc + under) * scale,
                      (Abc.y * ra + Aca.y * rb + Aab.y * rc + under) * scale,
                      (Abc.z * ra + Aca.z * rb + Aab.z * rc + under) * scale};
  // Else precise_meet, whose bound is not worse (ill-conditioned triples).
  const double largest = std::max({std::abs(x.x.hi), std::abs(x.y.hi), std::abs(x.z.hi)});
  if (!(std::max({ex.x, ex.y, ex.z}) <= kNewtonAccepted * largest)) return false;
  v.px = x;
  v.pw = {1, 0};
  v.ex = ex;
  v.ew = 0;
  v.precise = true;
  return true;
}

/// One-time initialisations by index: call(i, f) runs f once for each i, in whichever thread
/// asks first, the others waiting for it (run_once's atomic claim, halfspace_intersection.h).
class OnceFlags {
 public:
  explicit OnceFlags(std::size_t n) : state_(std::make_unique<std::atomic<unsigned char>[]>(n)) {}
  template <class F>
  void call(std::size_t i, const F& f) const {
    if (state_[i].load(std::memory_order_acquire) != once_state::kDone) run_once(state_[i], f);
  }
  /// Whether f has run for i already.
  bool done(std::size_t i) const {
    return state_[i].load(std::memory_order_acquire) == once_state::kDone;
  }
  /// Marks i done, before any call (its value made by the owner meanwhile).
  void set_done(std::size_t i) { state_[i].store(once_state::kDone, std::memory_order_relaxed); }

 private:
  std::unique_ptr<std::atomic<unsigned char>[]> state_;  // value-initialised: kNone
};

/// The planes' precise copies, each made when a filter first needs it, by whichever thread
/// needs it first (the copy does not depend on the thread, so neither does any decision).
/// Shared by every stage of an intersection: the flips, each check, the incremental hull.
class PrecisePlanes {
 public:
  /// The copies of planes with both double-double copies (HalfSpace::normal_dd, offset_dd)
  /// are made here, in order: a few operations on values read by then, where made on first
  /// use they cost a cache miss on the half-space each (scattered, and large).
  explicit PrecisePlanes(const Planes& planes)
      : planes_(planes), precise_(planes.size()), once_(planes.size()) {
    parallel_chunks(static_cast<int>(planes.size()), 512, [&](int begin, int end) {
      RoundingGuard nearest(CGAL_FE_TONEAREST);
      for (int i = begin; i < end; ++i) {
        // The half-spaces are large: the hardware does not fetch the next ones in time.
        if (i + kAhead < end) {
          if (const HalfSpace* ahead = planes[i + kAhead].source) {
            __builtin_prefetch(&ahead->normal_dd);
            __builtin_prefetch(&ahead->offset_dd);
          }
        }
        const HalfSpace* h = planes[i].source;
        if (!h || !h->has_normal_dd || !h->has_offset_dd) continue;
        precise_[i] = precise_plane(planes[i]);
        once_.set_done(i);
      }
    });
  }
  const PrecisePlane& operator[](int i) const {  // any rounding mode
    once_.call(i, [&] {
      RoundingGuard nearest(CGAL_FE_TONEAREST);
      precise_[i] = precise_plane(planes_[i]);
    });
    return precise_[i];
  }
  /// Whether plane i's copy is made already (a test that may use it costs no conversion).
  bool made(int i) const { return once_.done(i); }
  /// Fetches plane i's copy into the cache (no other effect).
  void prefetch(int i) const { __builtin_prefetch(&precise_[i]); }
  /// Planes this many ahead are prefetched in the loops over them.
  static constexpr int kAhead = 4;

 private:
  const Planes& planes_;
  mutable std::vector<PrecisePlane> precise_;  // each written once, under its flag in once_
  OnceFlags once_;
};

/// A known point's precise copy from its exact coordinates X = hi + lo, W = 1: the copy is
/// exact (exact_dd: it rounds by hi + lo, and its exact value is made from it), and `doubles`
/// when every lo is zero; precise (with precise_scaled's bound, for the scale 1) within
/// precise_scaled's range.
void set_precise_known(const V3<DD>& d, HVertex& v) {
  v.px = d;
  v.pw = {1, 0};
  v.ex = {kPlaneRelative * std::abs(d.x.hi), kPlaneRelative * std::abs(d.y.hi),
          kPlaneRelative * std::abs(d.z.hi)};
  v.ew = kPlaneRelative;
  v.exact_dd = true;
  v.doubles = d.x.lo == 0 && d.y.lo == 0 && d.z.lo == 0;
  bool in_range = true;
  for (const DD& x : {d.x, d.y, d.z})
    in_range = in_range && (x.hi == 0 || (std::abs(x.hi) >= 0x1p-900 && std::abs(x.hi) <= 0x1p400));
  v.precise = in_range;
}

/// The precise coordinates of a vertex (round-to-nearest): a known point's from its exact
/// ones (W in [1, 2)), another's as the meet of its precise planes. Left out when a plane is
/// not valid or a value out of range.
void make_precise(const PrecisePlanes& planes, HVertex& v) {
  v.precise_tried = true;
  if (v.known >= 0) {
    if (v.exact_dd) return;  // (set_known's, from the known point's double-double copy)
    // W = 1 (an erosion's v - b of double points, a closing's exact sums): X is usually
    // exactly hi + lo, often one bit beyond a double (a rounding tie, which the precise
    // rounding cannot settle).
    V3<DD> d;
    if (v.W->is_one() && split_exactly(v.X->x, d.x) && split_exactly(v.X->y, d.y) &&
        split_exactly(v.X->z, d.z)) {
      set_precise_known(d, v);
      return;
    }
    const auto is_double = [](const ExactN& x) {
      const double d = x.to_double();
      return std::isfinite(d) && x == ExactN(d);
    };
    v.doubles = v.W->is_one() && is_double(v.X->x) && is_double(v.X->y) && is_double(v.X->z);
    if (v.doubles) return;  // (a closing's vertices, A's own)
    std::array<DD, 4> c;
    if (!precise_scaled({&v.X->x, &v.X->y, &v.X->z, v.W}, 3, 4, c)) return;
    v.px = {c[0], c[1], c[2]};
    v.pw = c[3];
    v.ex = {kPlaneRelative * std::abs(c[0].hi), kPlaneRelative * std::abs(c[1].hi),
            kPlaneRelative * std::abs(c[2].hi)};
    v.ew = kPlaneRelative * c[3].hi;
    v.precise = true;
    return;
  }
  const PrecisePlane &a = planes[v.planes[0]], &b = planes[v.planes[1]], &c = planes[v.planes[2]];
  if (!a.valid() || !b.valid() || !c.valid()) return;
  if (!newton_meet(a, b, c, v)) precise_meet(a, b, c, v);
}

/// Sign of <n, X> - d W from the precise stage, or 2 (round-to-nearest; both precise).
[[gnu::flatten]] int precise_side(const PrecisePlane& p, const HVertex& v) {
  const DD value = dot(normal_dd(p), v.px) - p.c[3] * v.pw;
  const V3<Magnitude> n = normal_magnitude(p);
  const Magnitude m = dot(n, magnitude(v.px)) - magnitude(p.c[3]) * magnitude(v.pw);
  const double moved = n.x.v * v.ex.x + n.y.v * v.ex.y + n.z.v * v.ex.z +
                       std::abs(p.c[3].hi) * v.ew;  // by the vertex's errors
  const double bound = ((kPlaneRelative + kEvaluation) * m.v + moved) * 1.01 + 0x1p-1000;
  if (value.hi > bound) return 1;
  if (value.hi < -bound) return -1;
  return 2;
}

/// Sign of <n, Xu> Wv - <n, Xv> Wu from the precise stage, or 2 (round-to-nearest; all
/// precise). Each vertex's own factor is positive, so the sign is that of <n, u - v>.
[[gnu::flatten]] int precise_compare(const PrecisePlane& p, const HVertex& u, const HVertex& v) {
  const V3<DD> n = normal_dd(p);
  const DD value = dot(n, u.px) * v.pw - dot(n, v.px) * u.pw;
  const V3<Magnitude> nm = normal_magnitude(p);
  const double mu = dot(nm, magnitude(u.px)).v, mv = dot(nm, magnitude(v.px)).v;
  const double wu = std::abs(u.pw.hi), wv = std::abs(v.pw.hi);
  // <n, Xu> moves by du with u's errors (dv for v), so each product by that times W (with
  // its move) and <n, X> (with its move) times W's move.
  const double du = nm.x.v * u.ex.x + nm.y.v * u.ex.y + nm.z.v * u.ex.z,
               dv = nm.x.v * v.ex.x + nm.y.v * v.ex.y + nm.z.v * v.ex.z;
  const double moved = du * (wv + v.ew) + (mu + du) * v.ew + dv * (wu + u.ew) + (mv + dv) * u.ew;
  const double bound =
      ((kPlaneRelative + kEvaluation) * (mu * wv + mv * wu) + moved) * 1.01 + 0x1p-990;
  if (value.hi > bound) return 1;
  if (value.hi < -bound) return -1;
  return 2;
}

/// Sign of <h, X> - d W from the double filter (kSideError), or 2 (any rounding mode).
int double_side(const Plane& p, const HVertex& v) {
  if (!p.fast || !v.fast) return 2;
  const V3<double> X = v.Xd(), M = v.MX();
  const double value = p.nd.x * X.x + p.nd.y * X.y + p.nd.z * X.z - p.dd * v.Wd();
  const V3<double> na = p.na();
  const double bound =
      kSideError * (na.x * M.x + na.y * M.y + na.z * M.z + p.da() * v.MW()) + kDoubleFloor;
  if (value > bound) return 1;
  if (value < -bound) return -1;
  return 2;
}
/// Sign of <n, Xu> Wv - <n, Xv> Wu from the double filter (kCompareError), or 2 (any
/// rounding mode): with Wu, Wv > 0, the sign of <n, u - v>.
int double_compare(const Plane& p, const HVertex& u, const HVertex& v) {
  if (!p.fast || !u.fast || !v.fast) return 2;
  const double nu = dot(p.nd, u.Xd()), nv = dot(p.nd, v.Xd());
  const V3<double> na = p.na();
  const double mu = dot(na, u.MX()), mv = dot(na, v.MX());
  const double value = nu * v.Wd() - nv * u.Wd();
  const double bound = kCompareError * (mu * v.MW() + mv * u.MW()) + kDoubleFloor;
  if (value > bound) return 1;
  if (value < -bound) return -1;
  return 2;
}

/// The interval sign of <n, X> - d W, from v's intervals or, where it has none, ones made
/// here (not kept: v may be shared between threads).
int interval_side(const Planes& planes, const Plane& p, const HVertex& v) {
  if (v.intervals) return interval_sign(dot(p.ni, v.Xi) - p.di * v.Wi);
  V3<Interval> Xi;
  Interval Wi;
  interval_meet(planes, v.planes, Xi, Wi);
  return interval_sign(dot(p.ni, Xi) - p.di * Wi);
}

/// Sign of <n, x> - d at a vertex from the filters alone (the double filter, the precise
/// stage in round-to-nearest, then intervals), or 2: > 0 when the vertex violates the
/// half-space. A known point whose exact coordinates are there skips the precise stage: they
/// are small (in a closing the undecided tests are mostly exact zeros, planes touching the
/// result).
int side_filter(const Planes& planes, const PrecisePlanes& precise, int i, const HVertex& v) {
  const Plane& p = planes[i];
  const int s = double_side(p, v);
  if (s != 2) return s;
  // The precise stage before intervals (which a vertex with doubles would make here) when
  // the plane's precise copy is made already; after them otherwise (its conversion costs more).
  const bool stage = v.precise && (v.known < 0 || !v.X);
  const auto precise_sign = [&] {
    RoundingGuard nearest(CGAL_FE_TONEAREST);
    const PrecisePlane& q = precise[i];
    return q.valid() ? precise_side(q, v) : 2;
  };
  if (stage && precise.made(i)) {
    const int t = precise_sign();
    if (t != 2) return t;
    return interval_side(planes, p, v);
  }
  const int t = interval_side(planes, p, v);
  return t != 2 || !stage ? t : precise_sign();
}
int side_exact(const Plane& p, const HVertex& v) {
  return CGAL::sign(dot(p.n(), *v.X) - p.d() * *v.W);
}

/// Sign of <n, x> - d for plane i at a vertex: the double filter, then the precise stage
/// (the vertex made precise when first needed there; a known point skips it, as in
/// side_filter), then intervals, then exact coordinates (computed once). Planes nearly through one
/// point (the moved facets around a vertex of a nearly planar A) leave most of these tests to the
/// precise stage.
int side(const Planes& planes, const PrecisePlanes& precise, int i, HVertex& v) {
  const Plane& p = planes[i];
  int s = double_side(p, v);
  if (s != 2) return s;
  // A vertex the double filter cannot decide goes to the precise stage before intervals:
  // most of those the intervals cannot decide either, and the precise coordinates are
  // needed for the rounding anyway. (A known point goes there only when its exact
  // coordinates are not at hand: a double-double one, set_known.)
  if (v.known < 0 || !v.X) {
    RoundingGuard nearest(CGAL_FE_TONEAREST);
    if (!v.precise_tried) make_precise(precise, v);
    const PrecisePlane& q = precise[i];
    if (v.precise && q.valid()) {
      const int t = precise_side(q, v);
      if (t != 2) return t;
    }
  }
  make_intervals(planes, v);
  s = interval_sign(dot(p.ni, v.Xi) - p.di * v.Wi);
  if (s != 2) return s;
  make_exact(planes, v);
  return side_exact(p, v);
}

/// Sign of <n, u> - <n, v> from the filters alone (doubles, precise, intervals), or 2 (two
/// known points skip the precise stage, as in side_filter).
int compare_filter(const Planes& planes, const PrecisePlanes& precise, int i, const HVertex& u,
                   const HVertex& v) {
  const Plane& p = planes[i];
  const int s = double_compare(p, u, v);
  if (s != 2) return s;
  // As in side_filter: the precise stage first when the plane's copy is made.
  const bool stage = u.precise && v.precise && (u.known < 0 || v.known < 0);
  const auto precise_sign = [&] {
    RoundingGuard nearest(CGAL_FE_TONEAREST);
    const PrecisePlane& q = precise[i];
    return q.valid() ? precise_compare(q, u, v) : 2;
  };
  const auto interval_sign_of = [&] {
    // (Intervals made here where a vertex has none: not kept, the vertices are shared.)
    const auto enclosure = [&](const HVertex& x) {
      if (x.intervals) return quotient(x.Xi, x.Wi);
      V3<Interval> Xi;
      Interval Wi;
      interval_meet(planes, x.planes, Xi, Wi);
      return quotient(Xi, Wi);
    };
    return interval_sign(dot(p.ni, enclosure(u)) - dot(p.ni, enclosure(v)));
  };
  if (stage && precise.made(i)) {
    const int t = precise_sign();
    return t != 2 ? t : interval_sign_of();
  }
  const int t = interval_sign_of();
  return t != 2 || !stage ? t : precise_sign();
}
int compare_exact(const Plane& p, const HVertex& u, const HVertex& v) {
  return CGAL::sign(dot(p.n(), *u.X) * *v.W - dot(p.n(), *v.X) * *u.W);
}

/// The intersection's vertices: vertex g is store[index[g]], where a candidate's tests made
/// it or where it was added after them.
struct IndexedVertices {
  VertexStore store;
  std::vector<int> index;
  HVertex& operator[](int g) { return store[index[g]]; }
  const HVertex& operator[](int g) const { return store[index[g]]; }
  int size() const { return static_cast<int>(index.size()); }
};

/// Exact vertex coordinates made on first use, by whichever thread needs them first (each
/// at most once; they do not depend on the thread, so neither does any decision).
class LazyExact {
 public:
  LazyExact(const Planes& planes, IndexedVertices& vertex)
      : planes_(planes), vertex_(vertex), once_(vertex.size()) {}
  const HVertex& operator()(int v) {
    once_.call(v, [&] { make_exact(planes_, vertex_[v]); });
    return vertex_[v];
  }

 private:
  const Planes& planes_;
  IndexedVertices& vertex_;
  OnceFlags once_;
};

/// The double next to r (non-zero, finite, below the largest) away from zero when `away`,
/// else towards it: its bit pattern plus or minus one (no libm call in the rounding loops).
double step_away(double r, bool away) {
  std::uint64_t bits;
  std::memcpy(&bits, &r, sizeof bits);
  bits = away ? bits + 1 : bits - 1;
  std::memcpy(&r, &bits, sizeof bits);
  return r;
}

/// X / W rounded to nearest (ties to even) from precise coordinates, when their enclosure
/// lies strictly between two rounding midpoints (round-to-nearest); false otherwise (too
/// close to a midpoint, or out of range): the exact rounding decides. X is within ex of
/// the exact X, W within ew (both times the vertex's factor). `inverse` is 1 / W.hi rounded
/// (any double serves: it only proposes candidates, which are checked), computed once for a
/// vertex's three coordinates: multiplications instead of two divisions each, whose latency
/// showed in the rounding loop's profile.
[[gnu::flatten]] bool round_precise(const DD& X, double ex, const DD& W, double ew, double inverse,
                                    double& out) {
  if (W.hi == 1 && W.lo == 0 && ew == 0) {  // (newton_meet's) X itself, within ex
    // X.hi rounds X when X.lo +- ex stays strictly inside the half gaps to its neighbours
    // (powers of two: rounding is monotone, so the rounded sums compare as the exact ones).
    const double r = X.hi;
    if (!(std::abs(r) >= 0x1p-500 && std::abs(r) <= 0x1p500)) return false;
    const double up = step_away(r, r > 0) - r, down = r - step_away(r, r < 0);
    if (!(X.lo + ex < 0.5 * up && X.lo - ex > -0.5 * down)) return false;
    out = r;
    return true;
  }
  if (!(W.hi >= 0x1p-300 && W.hi <= 0x1p300) || !(ew <= 0x1p-60 * W.hi)) return false;
  // The residual R = X - r W in double-double: the product r W.hi is exact (Dekker), and
  // so is the cancelling X.hi - p.hi; what remains is small. `sum` bounds those small
  // terms, whose three additions and the last one err by 2^-53 of them each.
  double sum = 0;
  const auto residual = [&](double r) {
    const DD p = two_prod(r, W.hi), s = two_sum(X.hi, -p.hi);
    const double q = r * W.lo;
    sum = std::abs(s.lo) + std::abs(X.lo) + std::abs(p.lo) + std::abs(q);
    return s.hi + (((s.lo + X.lo) - p.lo) - q);
  };
  // X / W lies strictly between the midpoints to r's neighbours iff
  // -(r - down) / 2 < R / W < (up - r) / 2 for R = X - r W; the exact W >= W.hi - |W.lo| - ew
  // >= w_low > 0 (|W.lo| <= 2^-53 W.hi), and the half gaps are powers of two (products
  // exact: no underflow in this range). X / W - r = R / W up to the errors: those of X and
  // W, and of R's evaluation.
  const double w_low = W.hi * (1 - 0x1p-50);
  const auto rounds_to = [&](double r, double R) {
    const double error = (ex + std::abs(r) * ew + 0x1p-50 * (sum + std::abs(R))) * 1.01 + 0x1p-1000;
    const double up = step_away(r, r > 0) - r, down = r - step_away(r, r < 0);
    return R + error < 0.5 * up * w_low && R - error > -0.5 * down * w_low;
  };
  // X.hi / W.hi (as X.hi times the inverse) is within an ulp or two of X / W, q1; moved by
  // its residual, X / W to about 100 bits, r: the rounding, unless X / W is near a midpoint.
  // q1 alone is the rounding in only about a quarter of the calls (an opening's), so testing
  // it first cost a mispredicted branch in most; r is tested instead, with its residual
  // R1 - (r - q1) W from q1's (r - q1 exact: Sterbenz), q1 only where r fails.
  const double q1 = X.hi * inverse;
  if (!(std::abs(q1) >= 0x1p-490 && std::abs(q1) <= 0x1p490)) return false;
  const double R1 = residual(q1);
  const double sum1 = sum;
  const double r = q1 + R1 * inverse;
  const double ar = std::abs(r), aq = std::abs(q1);
  if (ar >= 0x1p-500 && ar <= 0x1p500 && (r > 0) == (q1 > 0) && ar <= 2 * aq && aq <= 2 * ar) {
    // delta exact; t = delta W.hi and t_lo = delta W.lo rounded (by at most u (1 + u) of
    // each, plus underflow in t_lo: rounds_to's 2^-1000), and two subtractions (u of each
    // exact result): within 2.01 u (|R1| + |t| + |t_lo| + |R2|) of the residual of the
    // double-double X and W, besides R1's own error (2^-50 (sum1 + |R1|)). rounds_to
    // counts 2^-50 (sum + |R2|): sum takes sum1, 2 |R1|, |t| and |t_lo|.
    const double delta = r - q1;
    const double t = delta * W.hi, t_lo = delta * W.lo;
    const double R2 = (R1 - t) - t_lo;
    sum = sum1 + 2 * std::abs(R1) + std::abs(t) + std::abs(t_lo);
    if (rounds_to(r, R2)) {
      out = r;
      return true;
    }
  } else if (ar >= 0x1p-500 && ar <= 0x1p500) {
    if (rounds_to(r, residual(r))) {  // (out of Sterbenz's range: not seen in practice)
      out = r;
      return true;
    }
  }
  sum = sum1;
  if (!rounds_to(q1, R1)) return false;
  out = q1;
  return true;
}

int det_sign(const Plane& a, const Plane& b, const Plane& c) {
  const int s = interval_sign(det(a.ni, b.ni, c.ni));
  return s != 2 ? s : CGAL::sign(det(a.n(), b.n(), c.n()));
}

/// Sign of det(n_a, n_b, n_c) from the precise stage, or 2 (round-to-nearest; valid planes):
/// the W of their precise meet, within ew of the determinant of the precise normals (each
/// n times a positive power of two: the same sign); hi decides beyond 1.01 ew (|lo| is
/// below 2^-53 |hi|).
int precise_det_sign(const PrecisePlane& a, const PrecisePlane& b, const PrecisePlane& c) {
  HVertex v;
  precise_meet(a, b, c, v);
  const double bound = 1.01 * v.ew;
  return v.pw.hi > bound ? 1 : v.pw.hi < -bound ? -1 : 2;
}

/// Sign of det(n_a, n_b, n_c) from the double filter, or 2 (any rounding mode): the W of
/// double_meet, <n_a, n_b x n_c> with its magnitude, so kMeetError as there (w_positive).
int double_det_sign(const Plane& a, const Plane& b, const Plane& c) {
  if (!a.fast || !b.fast || !c.fast) return 2;
  const double w = dot(a.nd, cross(b.nd, c.nd));
  const double bound = kMeetError * dot(a.na(), magnitude_cross(b.na(), c.na())) + kDoubleFloor;
  return w > bound ? 1 : w < -bound ? -1 : 2;
}

/// det_sign of planes a, b, c: the double filter, intervals, the precise stage (nearly
/// parallel normals: a fine mesh's facets around a vertex, which the repair's flips test),
/// then Mpzf. The double filter costs a few dozen instructions where the interval
/// determinant costs a few hundred (uvsphere_1600 erosion, the repair's and the check's
/// orientation tests: 0.77M to 0.45M instructions).
int det_sign(const Planes& planes, const PrecisePlanes& precise, int a, int b, int c) {
  const Plane &pa = planes[a], &pb = planes[b], &pc = planes[c];
  const int d = double_det_sign(pa, pb, pc);
  if (d != 2) return d;
  const int s = interval_sign(det(pa.ni, pb.ni, pc.ni));
  if (s != 2) return s;
  {
    RoundingGuard nearest(CGAL_FE_TONEAREST);
    const PrecisePlane &x = precise[a], &y = precise[b], &z = precise[c];
    const int t = x.valid() && y.valid() && z.valid() ? precise_det_sign(x, y, z) : 2;
    if (t != 2) return t;
  }
  return CGAL::sign(det(pa.n(), pb.n(), pc.n()));
}

/// The planes' dual points about o (planes_of makes them with the planes when o is known
/// then; otherwise made here, upward rounding).
DualPoints dual_points(const Planes& planes, const V3<double>& o) {
  DualPoints out(planes.size());
  parallel_chunks(static_cast<int>(planes.size()), 1024, [&](int begin, int end) {
    RoundingGuard guard;
    for (int k = begin; k < end; ++k) out[k] = dual_point(planes[k], o);
  });
  return out;
}

/// Sign of det(x, y, z) for vectors within dx, dy, dz of the computed x, y, z in every
/// coordinate, or 2: the evaluation errs by at most 8 u of the permanent (5 operations a
/// monomial and its sum), the inputs' errors by at most 6 ((X + dx)(Y + dy)(Z + dz) - XYZ)
/// for X = |x|_inf ..., written without cancellation; half again for second-order terms.
/// Needs upward rounding (the bound rounds up).
int det_filter(const V3<double>& x, const V3<double>& y, const V3<double>& z, double dx, double dy,
               double dz) {
  const V3<double> yz = cross(y, z);
  const double value = dot(x, yz);
  const double X = std::max({std::abs(x.x), std::abs(x.y), std::abs(x.z)});
  const double Y = std::max({std::abs(y.x), std::abs(y.y), std::abs(y.z)});
  const double Z = std::max({std::abs(z.x), std::abs(z.y), std::abs(z.z)});
  const double moved = dx * (Y + dy) * (Z + dz) + X * dy * (Z + dz) + X * Y * dz;
  const double bound = 1.5 * (6 * 0x1p-49 * X * Y * Z + 6 * moved) + kDoubleFloor;
  return value > bound ? 1 : value < -bound ? -1 : 2;
}

/// Sign of det(n_a, n_b, n_c) from the dual points, or 2 (upward rounding).
int dual_det_sign(const DualPoints& dual, int a, int b, int c) {
  const DualPoint &x = dual[a], &y = dual[b], &z = dual[c];
  if (x.error < 0 || y.error < 0 || z.error < 0) return 2;
  return det_filter(x.p, y.p, z.p, x.error, y.error, z.error);
}

/// det_sign with the dual points' filter first, when there are dual points (upward
/// rounding).
int det_sign(const DualPoints* dual, const Planes& planes, const PrecisePlanes& precise, int a,
             int b, int c) {
  const int d = dual ? dual_det_sign(*dual, a, b, c) : 2;
  return d != 2 ? d : det_sign(planes, precise, a, b, c);
}

/// Sign of plane i at the vertex of planes abc (det(n_a, n_b, n_c) > 0) from the dual
/// points, or 2 (none given, or undecided; upward rounding). Each difference errs by its
/// points' errors and one rounding.
int dual_side(const DualPoints* dual, const std::array<int, 3>& abc, int i) {
  constexpr double u = 0x1p-52;
  if (!dual) return 2;
  const DualPoint &pa = (*dual)[abc[0]], &pb = (*dual)[abc[1]], &pc = (*dual)[abc[2]],
                  &pi = (*dual)[i];
  const double ea = pa.error, eb = pb.error, ec = pc.error, ei = pi.error;
  if (ea < 0 || eb < 0 || ec < 0 || ei < 0) return 2;
  const V3<double>& q = pi.p;
  const V3<double> x = pb.p - q, y = pa.p - q, z = pc.p - q;
  const auto norm = [](const V3<double>& w) {
    return std::max({std::abs(w.x), std::abs(w.y), std::abs(w.z)});
  };
  return det_filter(x, y, z, eb + ei + u * norm(x), ea + ei + u * norm(y), ec + ei + u * norm(z));
}

}  // namespace

// A double within an ulp or two of X / W, moved until X / W lies between the midpoints to
// its neighbours (exact comparisons in Mpzf, no rational and no gcd). The same value as
// mpfr's round_to_nearest(X / W), which is used when the estimate is poor or out of range.
double round_quotient(const ExactN& X, const ExactN& W, const Interval& estimate) {
  constexpr double kNormalRange = 0x1p1000;  // far from overflow and from subnormals
  constexpr int kMaxSteps = 4;               // ulps from the estimate before giving up
  const auto exactly = [&] { return round_to_nearest(Exact(X) / Exact(W)); };
  double r = estimate.inf() / 2 + estimate.sup() / 2;
  if (!(estimate.sup() - estimate.inf() <= std::abs(r) * 0x1p-50))
    r = X.to_double() / W.to_double();
  if (!(std::abs(r) < kNormalRange && std::abs(r) > 1 / kNormalRange)) return exactly();
  const auto even = [](double a, double b) {
    std::uint64_t bits;
    std::memcpy(&bits, &a, sizeof bits);
    return (bits & 1) == 0 ? a : b;
  };
  const Interval Wi(W.to_interval());
  RoundingGuard guard;  // for the interval filter; the rest does not depend on the mode
  for (int step = 0; step < kMaxSteps; ++step) {
    const double up = std::nextafter(r, HUGE_VAL), down = std::nextafter(r, -HUGE_VAL);
    // X / W - (r + n) / 2 = (2 R - (n - r) W) / 2W with the residual R = X - r W (one exact
    // product per step) and n - r exact (neighbouring doubles): its sign, decided in
    // intervals unless X / W is within rounding of the midpoint.
    const ExactN R = X - ExactN(r) * W;
    const Interval Ri(R.to_interval());
    const auto versus_midpoint = [&](double n) {
      const double gap = n - r;
      const int s = interval_sign(Ri + Ri - Interval(gap) * Wi);
      return s != 2 ? s : CGAL::sign(R + R - ExactN(gap) * W);
    };
    const int above = versus_midpoint(up);
    if (above > 0) {
      r = up;
      continue;
    }
    if (above == 0) return even(r, up);
    const int below = versus_midpoint(down);
    if (below < 0) {
      r = down;
      continue;
    }
    if (below == 0) return even(r, down);
    return r;
  }
  return exactly();
}

namespace {

/// Whether the facet cycle `cyc` runs clockwise about `normal` (interval Newell normal of
/// the vertices, rationals when that cannot decide).
bool clockwise(const std::vector<int>& cyc, const IndexedVertices& vertex, const V3<ExactN>& normal,
               LazyExact& exact_vertex) {
  const int n = static_cast<int>(cyc.size());
  {
    RoundingGuard guard;
    std::vector<V3<Interval>> x(n);
    for (int i = 0; i < n; ++i) x[i] = quotient(vertex[cyc[i]].Xi, vertex[cyc[i]].Wi);
    const V3<Interval> nw =
        newell_normal<Interval>(n, [&](int i) -> const V3<Interval>& { return x[i]; });
    const int s = interval_sign(dot(nw, to_interval_n(normal)));
    if (s != 2) return s < 0;
  }
  std::vector<V3<Exact>> exact(n);
  for (int i = 0; i < n; ++i) {
    const HVertex& v = exact_vertex(cyc[i]);
    const Exact w(*v.W);
    exact[i] = {Exact(v.X->x) / w, Exact(v.X->y) / w, Exact(v.X->z) / w};
  }
  const V3<Exact> nw = newell_normal<Exact>(n, [&](int i) -> const V3<Exact>& { return exact[i]; });
  return CGAL::sign(dot(nw, to_rational(normal))) < 0;
}

/// An intersection's exact vertices, each computed on first use from its three planes (or
/// taken from its known point) by whichever thread needs it first, as LazyExact does: an
/// opening's sums are rounded from the precise points, and read these only where that
/// cannot decide.
class VertexExactPoints final : public LazyExactPoints {
 public:
  /// Vertex r is vertex[order[r]]. The polytope outlives the half-spaces and known points
  /// that `planes` and the vertices point at, unless `owner` keeps them (intersect_halfspaces):
  /// without it, the planes of the vertices still without exact coordinates are copied with
  /// their exact values (the others are never read), and so are the known points.
  VertexExactPoints(const Planes& planes, IndexedVertices vertex, std::vector<int> order,
                    std::shared_ptr<const void> owner)
      : planes_(owner ? planes : Planes(planes.size())),
        vertex_(std::move(vertex)),
        order_(std::move(order)),
        once_(order_.size()),
        owner_(std::move(owner)) {
    if (owner_) return;
    parallel_chunks(vertex_.size(), 256, [&](int begin, int end) {
      for (int i = begin; i < end; ++i) {
        HVertex& v = vertex_[i];
        if (v.X && !v.made) set_exact(v, *v.X, *v.W);
      }
    });
    for (int i = 0; i < vertex_.size(); ++i) {
      const HVertex& v = vertex_[i];
      if (v.X || v.exact_dd) continue;  // (exact_dd: made from its own copy)
      for (int i : v.planes) {
        if (planes_[i].n_exact) continue;
        const Plane& p = planes[i];
        planes_[i].scaled =
            p.scaled ? p.scaled : std::make_shared<const ExactPlane>(ExactPlane{p.n(), p.d()});
        planes_[i].n_exact = &planes_[i].scaled->n;
        planes_[i].d_exact = &planes_[i].scaled->d;
      }
    }
  }
  void get(int r, const V3<ExactN>*& X, const ExactN*& W) const override {
    HVertex& v = vertex_[order_[r]];
    once_.call(r, [&] { make_exact(planes_, v); });
    X = v.X;
    W = v.W;
  }

 private:
  Planes planes_;
  mutable IndexedVertices vertex_;  // each written once, under its flag in once_
  std::vector<int> order_;
  OnceFlags once_;
  std::shared_ptr<const void> owner_;  // of what planes_ and vertex_ point at, or null
};

/// The box of a vertex's precise X / W (hi + lo within the error bounds; under the caller's
/// RoundingGuard), when W's enclosure is positive: about an ulp wide where the meet's
/// intervals, for nearly parallel planes, are thousands (an erosion's vertices: 5e-11 on a
/// sphere of radius 1).
std::optional<V3<Interval>> precise_enclosure(const HVertex& v) {
  const auto enclose = [](const DD& x, double error) {
    return Interval(x.hi) + Interval(x.lo) + Interval(-error, error);
  };
  const Interval W = enclose(v.pw, v.ew);
  if (!(W.inf() > 0)) return std::nullopt;
  return V3<Interval>{enclose(v.px.x, v.ex.x) / W, enclose(v.px.y, v.ex.y) / W,
                      enclose(v.px.z, v.ex.z) / W};
}

/// The exact points of the intersection's polytope, whose vertex r is vertex[order[r]]
/// (`vertex` is moved away): computed on demand (VertexExactPoints), with the precise
/// coordinates, or, when `eager`, all computed now and without precise coordinates (the
/// route before, which tests compare with).
ExactPoints polytope_points(const Planes& planes, IndexedVertices& vertex,
                            const std::vector<int>& order, bool eager,
                            std::shared_ptr<const void> owner) {
  const int nv = static_cast<int>(order.size());
  ExactPoints exact;
  if (eager) {
    exact.resize(nv);
    parallel_chunks(nv, 128, [&](int begin, int end) {
      RoundingGuard guard;  // (make_intervals)
      for (int r = begin; r < end; ++r) {
        HVertex& v = vertex[order[r]];
        make_exact(planes, v);
        exact.numerator[r] = *v.X;
        exact.denominator[r] = *v.W;
        exact.enclosure[r] = enclosure_of(planes, v);
      }
    });
    return exact;
  }
  exact.enclosure.resize(nv);
  exact.precise.resize(nv);
  parallel_chunks(nv, 1024, [&](int begin, int end) {
    RoundingGuard guard;  // (make_intervals)
    for (int r = begin; r < end; ++r) {
      const HVertex& v = vertex[order[r]];
      const std::optional<V3<Interval>> tight =
          v.precise ? precise_enclosure(v) : std::optional<V3<Interval>>();
      exact.enclosure[r] = tight ? *tight : enclosure_of(planes, v);
      PrecisePoint& p = exact.precise[r];
      p.doubles = v.doubles;
      if (v.precise) {
        p.X = v.px;
        p.W = v.pw;
        p.error = v.ex;
        p.w_error = v.ew;
        p.valid = true;
      }
    }
  });
  exact.lazy =
      std::make_shared<VertexExactPoints>(planes, std::move(vertex), order, std::move(owner));
  return exact;
}

/// a, b, c in increasing order (min and max: no branches).
std::array<int, 3> sorted_triple(const std::array<int, 3>& x) {
  const int lo = std::min(x[0], x[1]), hi = std::max(x[0], x[1]);
  const int mid = std::max(lo, x[2]);
  return {std::min(lo, x[2]), std::min(hi, mid), std::max(hi, mid)};
}

/// Each row of `rows` sorted into out[3 t ..] (in parallel) when every row's three entries
/// are distinct and `keeps(t, a, b, c)` holds for each; false otherwise (out then unusable).
template <class Keeps>
bool sorted_triples(const std::vector<std::array<int, 3>>& rows, std::vector<int>& out,
                    const Keeps& keeps) {
  const int n = static_cast<int>(rows.size());
  out.resize(3 * static_cast<std::size_t>(n));
  std::atomic<bool> distinct = true;
  parallel_chunks(n, 2048, [&](int begin, int end) {
    bool here = true;
    for (int t = begin; t < end; ++t) {
      const auto [a, b, c] = sorted_triple(rows[t]);
      out[3 * t] = a;
      out[3 * t + 1] = b;
      out[3 * t + 2] = c;
      here &= (a < b) & (b < c) & keeps(t, a, b, c);
    }
    if (!here) distinct = false;
  });
  return distinct;
}

/// Sorts each list list[begin[i] .. begin[i + 1]) and drops repeats in it, compacting (the
/// lists are short: three elements by sorted_triple, as most are, others by insertion).
void sort_unique_lists(std::vector<int>& begin, std::vector<int>& list) {
  int kept = 0;
  for (std::size_t i = 0; i + 1 < begin.size(); ++i) {
    const int first = begin[i], last = begin[i + 1];
    if (last - first == 3) {
      const auto [a, b, c] = sorted_triple({list[first], list[first + 1], list[first + 2]});
      begin[i] = kept;
      list[kept++] = a;
      list[kept] = b;
      kept += b != a;
      list[kept] = c;
      kept += c != b;
      continue;
    }
    for (int j = first + 1; j < last; ++j) {
      const int x = list[j];
      int m = j;
      for (; m > first && list[m - 1] > x; --m) list[m] = list[m - 1];
      list[m] = x;
    }
    begin[i] = kept;
    for (int j = first; j < last; ++j)
      if (j == first || list[j] != list[j - 1]) list[kept++] = list[j];
  }
  begin.back() = kept;
  list.resize(kept);
}

/// An intersection's facet normals read from its half-spaces (facet f's is half-space
/// face_halfspace[f]'s), which `owner` keeps: a lazy one's made on first read, by whichever
/// thread reads first (HalfSpace::exact_normal).
class HalfSpaceNormals final : public GivenNormals::Source {
 public:
  HalfSpaceNormals(const HalfSpaces& hs, std::vector<int> face_halfspace,
                   std::shared_ptr<const void> owner)
      : hs_(hs), face_halfspace_(std::move(face_halfspace)), owner_(std::move(owner)) {}
  const V3<ExactN>& normal(int f) const override { return hs_[face_halfspace_[f]].exact_normal(); }
  /// The half-space's double-double copy, each component within 2^-101 of its |hi|
  /// (HalfSpace::normal_dd), scaled by a power of two to a largest |hi| in [1, 2): no Mpzf.
  bool precise(int f, PreciseNormal& out) const override {
    const HalfSpace& h = hs_[face_halfspace_[f]];
    if (!h.has_normal_dd) return false;
    double largest = 0;
    for (const DD& c : h.normal_dd) largest = std::max(largest, std::abs(c.hi));
    if (!(largest > 0) || !std::isfinite(largest)) return false;
    const int shift = -std::ilogb(largest);
    if (std::abs(shift) > 900) return false;  // (precise_given's range)
    out = {};
    // (Times 2^shift, a normal double: rounded as ldexp rounds, in one multiplication.)
    const double scale = std::ldexp(1.0, shift);
    for (int i = 0; i < 3; ++i) {
      const DD& c = h.normal_dd[i];
      if (c.hi == 0) continue;  // exactly zero (within 2^-101 of 0): hi = lo = error = 0
      out.hi[i] = c.hi * scale;
      out.lo[i] = c.lo * scale;
      // The bound scales exactly; so does lo, unless it comes out subnormal.
      out.error[i] = 0x1p-101 * std::abs(out.hi[i]);
      if (c.lo != 0 && std::abs(out.lo[i]) < std::numeric_limits<double>::min())
        out.error[i] += 0x1p-1000;
    }
    out.valid = true;
    return true;
  }

 private:
  const HalfSpaces& hs_;  // (owner_'s)
  std::vector<int> face_halfspace_;
  std::shared_ptr<const void> owner_;
};

/// The polytope of a verified intersection straight from its facet cycles (canonical
/// numbering, counter-clockwise), each facet with its half-space's normal: what
/// make_polytope builds from them, without its hash map, merge pass and checks. Those
/// could not act: the intersection is exact, its facets lie on distinct planes, each edge
/// joins two of them (strictly convex: the planes of a convex polytope's two facets along
/// an edge are not the same) and each vertex has three facets or more, so nothing merges
/// and the Gauss map is valid. The numbering is build_connectivity's: edges in the order
/// of their first corner, each fan from its vertex's last corner.
Polytope verified_polytope(std::vector<V3<double>> points, ExactPoints exact,
                           std::vector<int> face_begin, std::vector<int> corner_vertex,
                           GivenNormals normals) {
  Polytope p;
  p.points = std::move(points);
  p.exact_points = std::move(exact);
  p.given_normals = std::move(normals);
  p.face_begin = std::move(face_begin);
  p.corner_vertex = std::move(corner_vertex);
  const int nv = p.num_vertices(), nf = p.num_faces();
  const std::vector<int>& cv = p.corner_vertex;
  const int nc = static_cast<int>(cv.size());
  std::vector<int> corner_face(nc), next(nc), prev(nc);
  for (int f = 0; f < nf; ++f) {
    const int first = p.face_begin[f], last = p.face_begin[f + 1] - 1;
    for (int c = first; c <= last; ++c) {
      corner_face[c] = f;
      next[c] = c == last ? first : c + 1;
      prev[c] = c == first ? last : c - 1;
    }
  }
  // Corners by their vertex, in increasing order (a counting sort): the corner of the
  // directed edge u -> w is the one of u's whose next corner is at w.
  std::vector<int> out_begin(nv + 1, 0), out(nc);
  for (int c = 0; c < nc; ++c) ++out_begin[cv[c] + 1];
  std::partial_sum(out_begin.begin(), out_begin.end(), out_begin.begin());
  {
    std::vector<int> slot(out_begin.begin(), out_begin.end() - 1);
    for (int c = 0; c < nc; ++c) out[slot[cv[c]]++] = c;
  }
  // Each corner's twin: the corner of the same edge run the other way (w -> u for u -> w),
  // found once, in parallel; the fans below step through them without searching.
  std::vector<int> twin(nc);
  std::atomic<bool> closed = true;
  parallel_chunks(nc, 4096, [&](int begin, int end) {
    for (int c = begin; c < end; ++c) {
      const int u = cv[c], w = cv[next[c]];
      twin[c] = -1;
      for (int j = out_begin[w]; j < out_begin[w + 1]; ++j)
        if (cv[next[out[j]]] == u) {
          twin[c] = out[j];
          break;
        }
      if (twin[c] < 0) closed = false;
    }
  });
  if (!closed) throw error("internal error: an intersection's facets do not close up");
  p.corner_edge.assign(nc, -1);
  p.edges.reserve(nc / 2);
  for (int c = 0; c < nc; ++c) {
    if (p.corner_edge[c] >= 0) continue;
    const int t = twin[c];
    p.corner_edge[c] = p.corner_edge[t] = p.num_edges();
    p.edges.push_back({cv[c], cv[next[c]], corner_face[c], corner_face[t]});
  }
  // Fans: from facet f at v, the next facet counter-clockwise holds v -> u for the corner
  // u before v in f.
  p.fan_begin.resize(nv + 1);
  p.fan_face.reserve(nc);
  p.fan_edge.reserve(nc);
  p.fan_vertex.reserve(nc);
  for (int v = 0; v < nv; ++v) {
    p.fan_begin[v] = static_cast<int>(p.fan_face.size());
    if (out_begin[v] == out_begin[v + 1]) continue;
    const int start = out[out_begin[v + 1] - 1];
    int c = start;
    do {
      const int u = cv[prev[c]];
      p.fan_face.push_back(corner_face[c]);
      p.fan_edge.push_back(p.corner_edge[prev[c]]);
      p.fan_vertex.push_back(u);
      c = twin[prev[c]];  // v -> u: the twin of u -> v, the corner before c
    } while (c != start);
  }
  p.fan_begin[nv] = static_cast<int>(p.fan_face.size());
  p.compute_normals();
  p.vertex_source.resize(nv);
  std::iota(p.vertex_source.begin(), p.vertex_source.end(), 0);
  p.face_source.resize(nf);
  std::iota(p.face_source.begin(), p.face_source.end(), 0);
  p.edge_source.resize(p.num_edges());
  std::iota(p.edge_source.begin(), p.edge_source.end(), 0);
  return p;
}

/// Actions (flips and removals) per triangle after which a repair gives up: a guess that
/// needs more is far from the result, and the hull is then the cheaper route. (A UV
/// sphere of 320 x 320 facets eroded by a snub dodecahedron a quarter its size takes 0.97
/// per triangle, a third of its facets vanishing and its poles' fans flipped over.)
constexpr int kRepairsPerTriangle = 2;
/// The largest number of neighbours of a plane a repair lifts off its surface.
constexpr int kMaxLift = 16;

/// Walks from triangle u of s to the triangle whose cone from o holds n_x
/// (det(n_a, n_b, n_x) >= 0 for each of its edges a -> b), each step across an edge whose
/// determinant is negative. On a convex surface (every edge locally convex, every triangle
/// positive) the cones tile the directions and that triangle's vertex is the highest along
/// n_x (its planes' normals span n_x): found from the normals' orientations alone, without
/// the vertices a climb compares (UV 320 by cube(0.3): the repair's 4,372 insertions walk
/// 8.5 steps each from a near start). False, with u where it stopped, after kMaxWalk steps.
bool walk_to_cone(const DualSurface& s, const Planes& planes, const PrecisePlanes& precise,
                  const DualPoints* dual, int x, int& u, long& steps_out) {
  constexpr int kMaxWalk = 1 << 16;
  int from = -1;
  for (int steps = 0; steps < kMaxWalk; ++steps, ++steps_out) {
    int to = -1;
    // (The edge tested first turns with each step; the one just crossed is not tested.)
    for (int j = 0; j < 3 && to < 0; ++j) {
      const int k = (steps + j) % 3, w = s.across[u][k];
      if (w == from) continue;
      if (det_sign(dual, planes, precise, s.corner[u][k], s.corner[u][k == 2 ? 0 : k + 1], x) < 0)
        to = w;
    }
    if (to < 0) return true;
    from = u;
    u = to;
  }
  return false;
}

/// A repair's state per triangle slot and per plane, shared by its workers (SurfaceRepair):
/// each writes only its own triangles' and those of planes whose every triangle is its own.
struct RepairState {
  RepairState(int triangles, int planes)
      : dead(triangles, 0),
        changed(triangles, 0),
        tested_far(3 * static_cast<std::size_t>(triangles), -1),
        tested_sign(3 * static_cast<std::size_t>(triangles)),
        mark(triangles, 0),
        via(planes, -1) {}

  std::vector<char> dead, changed;
  // The far-plane signs of the repair's own tests, for the check after it: per slot, the
  // far plane tested (-1: none, or the triangle changed since) and its sign.
  std::vector<int> tested_far;
  std::vector<signed char> tested_sign;
  std::vector<unsigned> mark;  // per triangle: 2 stamp (cut off), 2 stamp + 1 (not)
  // Per plane taken off (removed or lifted): a neighbour it had then, on the surface at the
  // time, else -1. Where that one went too, its own leads on: a start near the plane's dual
  // point among those still on the surface. (Most lifted planes' own neighbours go later:
  // icosphere level 7 by icosphere(0.25, 1), 11,555 of 12,044 insertions started where the
  // last one ended, 21 steps each; 242,120 insertion steps to 70,173, on a UV sphere of
  // 512 x 512 by a quarter-size snub dodecahedron 336,156 to 77,283.)
  std::vector<int> via;
  // Empty (one region), or region r's triangle slots are [first[r], first[r + 1]) (see
  // group_regions): a slot keeps its region whatever triangle it holds.
  std::vector<int> first;
  // Whether a reflex edge's end strictly beneath the other three planes' triangle is taken
  // off at once whatever its number of neighbours (IntersectOptions::remove_beneath).
  bool remove_beneath = true;
};

/// Repairs a candidate dual surface (closed, oriented, every triangle positively oriented
/// about o) whose edges `reflex` (triangle, edge) are not locally convex: the far corner d
/// of the triangle across edge a -> c of triangle (a, c, b) cuts off that triangle's
/// vertex (side > 0, exactly). Such an edge is flipped to (b, d) when both new triangles
/// are positively oriented and b, d are not joined yet (a 2-2 flip: the enclosed region
/// grows by the tetrahedron a, b, c, d); otherwise an end of the edge with three
/// neighbours is removed (a 3-1 flip: the triangle of its neighbours replaces its three),
/// when that triangle is positively oriented. Where the flip would fold (a reflex corner of
/// the quadrilateral a, d, c, b), that corner's end lies strictly beneath the triangle of
/// the other three, whatever its number of neighbours: it is removed too, its neighbours'
/// polygon triangulated by a fan (lift with beneath_known; IntersectOptions::remove_beneath;
/// icosphere level 7 by icosphere(0.25, 1): 313K flips, 17.6K lifts and 12K insertions
/// before, 164K flips and none now). Each action is followed by the tests of the edges
/// around it; an edge that no action can repair yet waits until others have acted.
/// Lawson's flips for a convex hull need not finish: a reflex edge may have no valid
/// action (a UV sphere's row of quadrilaterals that vanish in an erosion: each has four
/// neighbours, and the flip across the row makes an inverted triangle of three nearly
/// collinear dual points). When every waiting edge is stuck, an end of one is lifted off
/// the surface: its neighbours' polygon is triangulated by ears (positively oriented, no
/// other neighbour inside, no diagonal an edge already), and the flips go on.
/// Once every edge is locally convex, the surface is the dual hull of the planes on it, and
/// each plane lifted is inserted again (the incremental hull's step: the triangles whose
/// vertices it cuts off replaced by a cone from it) or, when it cuts off none, left beneath
/// the surface; one whose ears all kept it beneath them needs neither (30% of the lifts of
/// an icosphere of 327,680 facets eroded by a small icosphere). (A plane removed by a 3-1
/// flip was beneath its neighbours' triangle; the check confirms it stays beneath the
/// result, as any plane off the surface.)
/// Every triangle made keeps det > 0, so the repaired surface still winds once around o.
/// False after kRepairsPerTriangle actions per triangle, or when nothing can act (the hull
/// is then computed). The result is checked exactly like any candidate (build_verified), so
/// the repair only has to be right where it acts, not complete.
/// Triangles removed are dropped from `s`; triangles changed have no vertex (has_vertex).
///
/// On a large surface and several threads the repair runs first in six regions
/// (repair_regions), in parallel: a region's worker acts only where every triangle it reads
/// or changes is its own, and leaves the other edges (across a region's border, or stuck
/// there) to a worker for the whole surface. The regions first flip and remove without
/// lifting; the whole surface's worker does the same for the edges they left, and hands
/// back what still waits; the regions go on with lifts; the whole surface's worker goes on
/// from what they left and inserts the planes lifted (repair_surface). The regions do not
/// depend on the number of threads, and each worker reads only its own triangles (and the
/// planes, the same for all), so neither do the decisions.
class SurfaceRepair {
 public:
  /// The worker of `region` (-1: the whole surface) of a repair of s.
  SurfaceRepair(const Planes& planes, const PrecisePlanes& precise, const KnownPoints& known,
                DualSurface& s, RepairState& state, RepairCounts& counts, int region = -1)
      : planes_(planes),
        precise_(precise),
        known_(known),
        s_(s),
        counts_(counts),
        dual_(s.dual.get()),
        dead_(state.dead),
        changed_(state.changed),
        tested_far_(state.tested_far),
        tested_sign_(state.tested_sign),
        mark_(state.mark),
        via_(state.via),
        remove_beneath_(state.remove_beneath),
        region_(region),
        begin_(region < 0 ? 0 : state.first[region]),
        end_(region < 0 ? std::numeric_limits<int>::max() : state.first[region + 1]) {}

  /// The edges to test first, (triangle, edge) (the worker's own triangles), and the
  /// actions it may take, for a surface of `triangles` triangles.
  void seed(const std::vector<std::pair<int, int>>& reflex, int triangles);
  /// Flips, removes and (`may_lift`) lifts until every edge is locally convex. A region's
  /// worker stops when none of its own can act, and keeps the edges it cannot act on for
  /// `absorb`; without lifts, it keeps those that wait, to test again in its next run. The whole
  /// surface's worker without lifts keeps the edges that wait for `hand_back`. False when the
  /// repair fails.
  bool relax(bool may_lift = true);
  /// Hands the edges it kept to the regions' workers, each to its triangle's region's
  /// (RepairState::first).
  void hand_back(std::vector<std::unique_ptr<SurfaceRepair>>& workers,
                 const std::vector<int>& first);
  /// Takes over what a region's worker left: its edges to test, its planes to insert again,
  /// its free slots and vertex indices.
  void absorb(SurfaceRepair& region);
  /// Inserts the planes lifted, and drops the triangles removed (the whole surface's worker,
  /// after relax).
  bool finish();
  /// Inserts planes that cut the surface, which is convex (every edge locally convex), each
  /// (plane, triangle) with a triangle whose vertex it cuts off (insert), and drops the
  /// triangles removed.
  bool insert_cutting(const std::vector<std::pair<int, int>>& cutting);

 private:
  using Edge = std::array<int, 3>;  // (t, a, c): the edge a -> c of triangle t
  static int next(int k) { return k == 2 ? 0 : k + 1; }
  static int prev(int k) { return k == 0 ? 2 : k - 1; }
  int size() const { return static_cast<int>(s_.corner.size()); }

  void record(int t, int k, int far, int sign) {
    tested_far_[3 * t + k] = far;
    tested_sign_[3 * t + k] = static_cast<signed char>(sign);
  }
  void forget(int t) {
    for (int k = 0; k < 3; ++k) tested_far_[3 * t + k] = -1;
  }
  int slot_of(int t, int a) const {
    for (int k = 0; k < 3; ++k)
      if (s_.corner[t][k] == a) return k;
    return -1;
  }
  HVertex& vertex_at(int t) { return s_.stored_vertex(t, planes_, known_, &free_vertices_); }
  /// Whether triangle t is this worker's to read and change (if not, the action asking is
  /// blocked: left to the whole surface's worker).
  bool mine(int t) {
    if (t >= begin_ && t < end_) return true;
    blocked_ = true;
    return false;
  }
  /// Sign of det(n_a, n_b, n_c): the dual points' filter, then det_sign.
  int orientation(int a, int b, int c) const {
    if (dual_) {
      const int d = dual_det_sign(*dual_, a, b, c);
      if (decided(d)) return d;
    }
    return det_sign(planes_, precise_, a, b, c);
  }
  /// Whether the dual points' filter decided a test (d: its sign, or 2), counted.
  bool decided(int d) const {
    ++(d != 2 ? counts_.dual_decided : counts_.dual_undecided);
    return d != 2;
  }
  bool positive(int a, int b, int c) const { return orientation(a, b, c) > 0; }
  /// Sign of plane i at the vertex of triangle t.
  int side_at(int i, int t) {
    if (dual_) {
      const int d = dual_side(dual_, s_.corner[t], i);
      if (decided(d)) return d;
    }
    HVertex& v = vertex_at(t);
    return known_through(known_, i, v) ? 0 : side(planes_, precise_, i, v);
  }
  /// Sets the across of triangle t's edge x -> y to `to`; false when t has no such edge.
  bool relink(int t, int x, int y, int to) {
    const int k = slot_of(t, x);
    if (k < 0 || s_.corner[t][next(k)] != y) return false;
    s_.across[t][k] = to;
    return true;
  }
  /// The triangles around corner a of triangle t, up to `limit` + 1 (the fan is followed
  /// through the triangle across each edge leaving a); `visit` sees each one's other corner
  /// along that edge.
  template <class Visit>
  int around(int t, int a, int limit, const Visit& visit) {
    int count = 0, u = t;
    do {
      if (!mine(u)) return limit + 1;
      const int k = slot_of(u, a);
      if (k < 0 || ++count > limit) return limit + 1;
      visit(s_.corner[u][next(k)]);
      u = s_.across[u][k];
    } while (u != t);
    return count;
  }
  void push_edges(int t) {
    for (int k = 2; k >= 0; --k) queue_.push_back({t, s_.corner[t][k], s_.corner[t][next(k)]});
  }
  /// Triangle t made anew with these corners (its links set by the caller): its vertex to
  /// compute, its tests forgotten.
  void make_triangle(int t, const std::array<int, 3>& corners) {
    s_.corner[t] = corners;
    s_.drop_vertex(t, free_vertices_);
    dead_[t] = 0;
    changed_[t] = 1;
    forget(t);
  }
  /// Triangle t removed: its slot free for a new one.
  void kill(int t) {
    dead_[t] = 1;
    s_.drop_vertex(t, free_vertices_);
    free_.push_back(t);
  }
  /// A slot for one more triangle (an insertion's cone has two more than it replaces): a
  /// removed triangle's, or a new one. (Growing the surface's arrays would move every vertex
  /// into new pages: tens of megabytes for one triangle.)
  int new_slot() {
    if (!free_.empty()) {
      const int t = free_.back();
      free_.pop_back();
      mark_[t] = 0;
      return t;
    }
    s_.corner.emplace_back();
    s_.across.emplace_back();
    s_.slot.push_back(-1);
    dead_.push_back(0);
    changed_.push_back(1);
    mark_.push_back(0);
    tested_far_.insert(tested_far_.end(), 3, -1);
    tested_sign_.insert(tested_sign_.end(), 3, 0);
    return size() - 1;
  }

  bool remove(int t, int i);
  bool lift(int t, int i, bool beneath_known = false);
  bool lift_waiting();
  bool insert(int x);
  bool compact();

  const Planes& planes_;
  const PrecisePlanes& precise_;
  const KnownPoints& known_;
  DualSurface& s_;
  RepairCounts& counts_;
  const DualPoints* dual_;  // null when the surface has none
  // RepairState's: see there.
  std::vector<char>&dead_, &changed_;
  std::vector<int>& tested_far_;
  std::vector<signed char>& tested_sign_;
  std::vector<unsigned>& mark_;
  std::vector<int>& via_;
  const bool remove_beneath_;
  const int region_;
  const int begin_, end_;  // its triangles' slots (RepairState::first)
  bool blocked_ = false;   // an action met another region's triangle
  std::vector<Edge> queue_, waiting_;
  std::vector<Edge> deferred_;      // a region's: the edges it left to the whole surface's worker
  std::vector<int> free_;           // the slots of removed triangles
  std::vector<int> free_vertices_;  // the vertex indices they and changed ones no longer use
  // Planes lifted, to insert again, each with a neighbour it had (whose triangles, when it
  // stays on the surface, start the climb: near the lifted dual point however the surface
  // changed since).
  std::vector<std::pair<int, int>> off_;
  int budget_ = 0;
  int last_ = -1;  // where the last insertion's walk ended (a start when x's own is gone)
  // Scratch of lift and insert.
  std::vector<int> fan_, link_, outer_, visible_;
  std::vector<int> rotated_, outer_rotated_;  // lift's fan: the neighbours from its apex on
  std::vector<char> clipped_, link_joined_;
  std::vector<std::array<int, 3>> ears_;
  std::vector<std::optional<HVertex>> ear_vertex_;  // computed where a test needed it
  std::vector<signed char> ear_state_;              // per neighbour: what lift knows of its ear
  std::vector<std::optional<HVertex>> ear_cache_;   // its vertex, where its test made it
  std::vector<std::pair<int, int>> horizon_;
  unsigned stamp_ = 0;
  static constexpr int kMaxDegree = 1 << 12;
  static constexpr int kMaxHops = 64;  // along via_
};

// Removes corner slot i of triangle t when it has three neighbours: t = (x, y, z),
// u = (y, x, d) across x -> y, w = (x, z, d) across z -> x become (y, z, d) in t.
bool SurfaceRepair::remove(int t, int i) {
  const int x = s_.corner[t][i], y = s_.corner[t][next(i)], z = s_.corner[t][prev(i)];
  const int u = s_.across[t][i], w = s_.across[t][prev(i)];
  if (!mine(u) || !mine(w)) return false;
  const int jx = slot_of(u, x), mx = slot_of(w, x);
  if (u == w || jx < 0 || mx < 0) return false;
  const int d = s_.corner[u][next(jx)];
  if (s_.corner[w][prev(mx)] != d || s_.across[u][jx] != w) return false;  // degree > 3
  const int Y = s_.across[u][next(jx)], Z = s_.across[w][next(mx)], X = s_.across[t][next(i)];
  for (int o : {X, Y, Z})
    if (o == t || o == u || o == w) return false;
  if (!mine(Y) || !mine(Z)) return false;
  if (!positive(y, z, d)) return false;
  if (!relink(Z, d, z, t) || !relink(Y, y, d, t)) return false;
  s_.near[x] = t;  // x's dual point lies beneath t
  via_[x] = y;
  // (Strictly: the reflex edge's test is x's, and the fan of three positive triangles about
  // x covers the cone of y, z, d once, x's dual point in it.)
  s_.inside[x] = 1;
  ++counts_.removals;
  make_triangle(t, {y, z, d});
  s_.across[t] = {X, Z, Y};
  kill(u);
  kill(w);
  push_edges(t);
  return true;
}

// Lifts corner slot i of triangle t, with 4 to kMaxLift neighbours z_0 .. z_{k-1}
// (counter-clockwise), off the surface: its k triangles become k - 2 ears of that polygon
// (in the first k - 2 of their slots), each positively oriented, with no other remaining
// neighbour inside or on it (det >= 0 against its three sides: the ears do not overlap),
// and no new diagonal an edge already. Ears that keep x's plane (x beneath them) first:
// those are on the dual hull of x and its neighbours, and leave fewer edges to flip.
// With beneath_known (relax: x's dual point lies strictly beneath the triangle of three of
// its neighbours' planes, inside the dual hull of all) x is removed for good, as remove's,
// and its polygon becomes a fan where one will do.
bool SurfaceRepair::lift(int t, int i, bool beneath_known) {
  const int x = s_.corner[t][i];
  fan_.clear();
  link_.clear();
  outer_.clear();
  for (int w = t;;) {
    if (!mine(w)) return false;
    const int m = slot_of(w, x);
    if (m < 0 || static_cast<int>(fan_.size()) == kMaxLift) return false;
    fan_.push_back(w);
    link_.push_back(s_.corner[w][next(m)]);
    outer_.push_back(s_.across[w][next(m)]);
    w = s_.across[w][prev(m)];  // the triangle after w counter-clockwise about x
    if (w == t) break;
  }
  const int k = static_cast<int>(fan_.size());
  if (k < 4) return false;
  for (const int o : outer_)
    if (!mine(o)) return false;
  for (int a = 0; a < k; ++a)
    for (int c = 0; c < k; ++c) {
      if (a != c && (link_[a] == link_[c] || fan_[a] == fan_[c])) return false;
      if (outer_[a] == fan_[c]) return false;
    }
  ears_.clear();
  ear_vertex_.clear();
  bool beneath = true;  // every ear keeps x's plane
  bool fanned = false;
  if (beneath_known) {
    // Any triangulation of the neighbours' polygon will do (the flips go on from it): a fan
    // from the first neighbour that gives one, its triangles positive (their rays from the
    // apex turn one way: the polygon is star-shaped from it, and the fan covers it once).
    // Its diagonals are not edges already, as a flip's new diagonal is not (see relax):
    // each is the minor arc between its ends, inside the polygon, where no other edge runs.
    // (Ears chosen one by one, as a lift's, walked around every neighbour and tested more:
    // icosphere level 7 by icosphere(0.25, 1), 4.58M tests in the repair against 1.97M,
    // and the erosion was slower than before this removal, 421 ms against 373.)
    // rotated_[j] is neighbour apex + j (mod k), outer_rotated_[j] the triangle across
    // the polygon's edge from it to the next.
    for (int apex = 0; apex < k && !fanned; ++apex) {
      rotated_.resize(k);
      for (int j = 0; j < k; ++j) rotated_[j] = link_[apex + j < k ? apex + j : apex + j - k];
      bool valid = true;
      for (int m = 1; m + 1 < k && valid; ++m)
        valid = positive(rotated_[0], rotated_[m], rotated_[m + 1]);
      if (!valid) continue;
      outer_rotated_.resize(k);
      for (int j = 0; j < k; ++j)
        outer_rotated_[j] = outer_[apex + j < k ? apex + j : apex + j - k];
      fanned = true;
    }
  }
  if (!fanned) {
    // Which neighbours are joined already (around each, away from x).
    link_joined_.assign(static_cast<std::size_t>(k) * k, 0);
    for (int a = 0; a < k; ++a) {
      const int degree = around(fan_[a], link_[a], kMaxDegree, [&](int w) {
        for (int c = 0; c < k; ++c)
          if (link_[c] == w) link_joined_[a * k + c] = link_joined_[c * k + a] = 1;
      });
      if (degree > kMaxDegree) return false;
    }
    clipped_.assign(k, 0);
    const auto next_left = [&](int a) {
      do a = a + 1 == k ? 0 : a + 1;
      while (clipped_[a]);
      return a;
    };
    const auto prev_left = [&](int a) {
      do a = a == 0 ? k - 1 : a - 1;
      while (clipped_[a]);
      return a;
    };
    // What is known of each neighbour b's ear (a, b, c), with a and c its neighbours left now
    // (each test depends on those three, and on which neighbours are left only through the
    // emptiness test; the choices are those of testing every ear each round, which made
    // a lift's ear tests cubic in its neighbours).
    enum : signed char { kUntested, kNoEar, kNotEmpty, kKeeps, kCuts };
    ear_state_.assign(k, kUntested);
    ear_cache_.clear();
    ear_cache_.resize(k);
    const auto test_ear = [&](int b, int left) {
      const int a = prev_left(b), c = next_left(b);
      if (left > 3 && link_joined_[a * k + c]) return kNoEar;
      const int za = link_[a], zb = link_[b], zc = link_[c];
      if (!positive(za, zb, zc)) return kNoEar;
      for (int j = next_left(c); j != a; j = next_left(j)) {
        const int z = link_[j];
        if (orientation(za, zb, z) >= 0 && orientation(zb, zc, z) >= 0 &&
            orientation(zc, za, z) >= 0)
          return kNotEmpty;
      }
      // (The ear's vertex only where the dual points cannot tell x's side: the check
      // computes it otherwise, once, if the ear lasts.)
      int sx = 2;
      if (dual_) {
        sx = dual_side(dual_, {za, zb, zc}, x);
        decided(sx);
      }
      if (sx == 2) {
        ear_cache_[b] = independent_vertex_of(planes_, {za, zb, zc}, known_);
        sx = known_through(known_, x, *ear_cache_[b]) ? 0
                                                      : side(planes_, precise_, x, *ear_cache_[b]);
      }
      return sx <= 0 ? kKeeps : kCuts;
    };
    for (int left = k; left >= 3; --left) {
      // The first valid ear that keeps x's plane, else the first valid ear. (The last ear
      // skips the diagonal test: all are tested again. A neighbour clipped may have been
      // inside an ear: those are tested again each round.)
      int chosen = -1, fallback = -1;
      for (int b = 0; b < k && chosen < 0; ++b) {
        if (clipped_[b]) continue;
        signed char& state = ear_state_[b];
        if (state == kUntested || state == kNotEmpty || left == 3) state = test_ear(b, left);
        if (state == kKeeps) chosen = b;
        if (state == kCuts && fallback < 0) fallback = b;
      }
      if (chosen < 0) {
        if (fallback < 0) return false;
        chosen = fallback;
        beneath = false;
      }
      const int a = prev_left(chosen), c = next_left(chosen);
      ears_.push_back({link_[a], link_[chosen], link_[c]});
      ear_vertex_.push_back(std::move(ear_cache_[chosen]));
      link_joined_[a * k + c] = link_joined_[c * k + a] = 1;
      clipped_[chosen] = 1;
      for (const int n : {a, c}) {  // (their ears change)
        ear_state_[n] = kUntested;
        ear_cache_[n].reset();
      }
    }
  }
  // The ears in the first k - 2 fan slots.
  const int made = k - 2;
  if (fanned) {
    // Triangle r is (apex, z_r+1, z_r+2) counting from the apex: across its first edge the
    // triangle before it, across its last the one after it, and the polygon's edges' outer
    // triangles across those.
    const std::vector<int>& z = rotated_;
    for (int r = 0; r < made; ++r) make_triangle(fan_[r], {z[0], z[r + 1], z[r + 2]});
    for (int r = 0; r < made; ++r) {
      const int before = r == 0 ? outer_rotated_[0] : fan_[r - 1];
      const int after = r == made - 1 ? outer_rotated_[k - 1] : fan_[r + 1];
      s_.across[fan_[r]] = {before, outer_rotated_[r + 1], after};
      if (!relink(outer_rotated_[r + 1], z[r + 2], z[r + 1], fan_[r])) return false;
    }
    if (!relink(outer_rotated_[0], z[1], z[0], fan_[0]) ||
        !relink(outer_rotated_[k - 1], z[0], z[k - 1], fan_[made - 1]))
      return false;
  } else {
    // Across a link edge z_m -> z_m+1 lies outer[m]; across a diagonal, the other ear along
    // it.
    for (int r = 0; r < made; ++r) {
      make_triangle(fan_[r], ears_[r]);
      if (ear_vertex_[r])
        s_.slot[fan_[r]] = s_.vertices.add_reusing(std::move(*ear_vertex_[r]), free_vertices_);
    }
    for (int r = 0; r < made; ++r) {
      for (int e = 0; e < 3; ++e) {
        const int p = ears_[r][e], q = ears_[r][next(e)];
        int to = -1;
        for (int m = 0; m < k && to < 0; ++m)
          if (link_[m] == p && link_[m + 1 == k ? 0 : m + 1] == q) {
            if (!relink(outer_[m], q, p, fan_[r])) return false;
            to = outer_[m];
          }
        for (int o = 0; o < made && to < 0; ++o) {
          const int j = slot_of(fan_[o], q);
          if (o != r && j >= 0 && ears_[o][next(j)] == p) to = fan_[o];
        }
        if (to < 0) return false;
        s_.across[fan_[r]][e] = to;
      }
    }
  }
  kill(fan_[k - 2]);
  kill(fan_[k - 1]);
  s_.near[x] = fan_[0];
  // Where every ear keeps x's plane, x's dual point lies in the cone of one ear (they tile
  // its neighbours' polygon, which winds around it) beneath that ear: inside the dual hull
  // of all the planes, so its plane bounds nothing (or touches), and it stays off.
  if (beneath_known) {
    s_.inside[x] = 1;
    ++counts_.removals;
    ++counts_.fan_removals;
  } else if (!beneath) {
    off_.emplace_back(x, link_[0]);
  }
  via_[x] = link_[0];
  for (int r = 0; r < made; ++r) push_edges(fan_[r]);
  return true;
}

// Lifts an end of each waiting edge it can off the surface (the one with fewer neighbours
// first; an edge that an earlier lift changed is left to test again): all are stuck, and
// one lift per round over the waiting edges made the rounds quadratic (an icosphere of
// 81,920 facets eroded by a small icosphere: 964 lifts, 7.2M edges tested again, 1.2 s).
// False when none can be.
bool SurfaceRepair::lift_waiting() {
  bool lifted = false;
  std::size_t kept = 0;
  for (const Edge& edge : waiting_) {
    const auto [t, a, c] = edge;
    if (dead_[t]) continue;
    const int i = slot_of(t, a);
    if (i < 0 || s_.corner[t][next(i)] != c) continue;
    blocked_ = false;
    const auto none = [](int) {};
    const bool c_first = around(t, c, kMaxLift, none) < around(t, a, kMaxLift, none);
    const int first = c_first ? next(i) : i, second = c_first ? i : next(i);
    if (lift(t, first) || lift(t, second)) {
      ++counts_.lifts;
      budget_ -= static_cast<int>(fan_.size());
      lifted = true;
    } else if (blocked_) {
      // (Another region's triangles are in the way: tested again here, it would wait
      // again after every round.)
      deferred_.push_back(edge);
      continue;
    }
    waiting_[kept++] = edge;
  }
  waiting_.resize(kept);
  return lifted;
}

// Inserts plane x into the surface, now the dual hull of the planes on it (every edge
// locally convex): from a triangle near x's dual point (or where the last insertion ended),
// a walk to the triangle whose vertex is highest along x's normal (walk_to_cone; where it
// does not arrive, a climb on from there, across plateaus of equal height: the same vertex
// of the intersection, in several triangles), which x cuts off exactly when it cuts off any. Then
// the triangles whose vertices it cuts off (connected, on a convex surface) are replaced by
// a cone from x over their boundary; otherwise x stays beneath the surface. False when the
// surface turns out not convex there (the cone would not close up).
bool SurfaceRepair::insert(int x) {
  // (Not the triangles a removed start's stale links lead to: their slots may have been
  // taken since, anywhere on the surface; 20 steps an insertion against 8 on UV 120 by a
  // cube.)
  int u = s_.near[x];
  if ((u < 0 || dead_[u]) && last_ >= 0 && !dead_[last_]) u = last_;
  if (u < 0 || dead_[u]) {
    u = 0;
    while (u < size() && dead_[u]) ++u;
    if (u == size()) return false;
  }
  const auto compare = [&](int w, int v) {  // sign of <n_x, vertex w> - <n_x, vertex v>
    HVertex& hw = vertex_at(w);
    HVertex& hv = vertex_at(v);
    int c = compare_filter(planes_, precise_, x, hw, hv);
    if (c != 2) return c;
    if (!hw.precise_tried || !hv.precise_tried) {
      // Nearby vertices compared along a normal nearly parallel to their facets': mostly
      // decided by the precise stage, which compare_filter uses once both vertices have it.
      {
        RoundingGuard nearest(CGAL_FE_TONEAREST);
        if (!hw.precise_tried) make_precise(precise_, hw);
        if (!hv.precise_tried) make_precise(precise_, hv);
      }
      c = compare_filter(planes_, precise_, x, hw, hv);
      if (c != 2) return c;
    }
    make_exact(planes_, hw);
    make_exact(planes_, hv);
    return compare_exact(planes_[x], hw, hv);
  };
  // The walk's end is the highest vertex: the climb only goes on where it did not arrive.
  ++counts_.insertions;
  const bool arrived = walk_to_cone(s_, planes_, precise_, dual_, x, u, counts_.insert_steps);
  last_ = u;
  constexpr int kMaxPlateau = 256;
  visible_.assign(1, u);  // (the plateau, here)
  int below = -1;         // the triangle the climb came from: lower than the plateau
  for (std::size_t q = arrived ? 1 : 0; q < visible_.size();) {
    const int v = visible_[q];
    int higher = -1;
    for (int k = 0; k < 3 && higher < 0; ++k) {
      const int w = s_.across[v][k];
      if (w == below || std::find(visible_.begin(), visible_.end(), w) != visible_.end()) continue;
      const int c = compare(w, v);
      if (c > 0) higher = w;
      if (c == 0) visible_.push_back(w);
    }
    if (higher >= 0) {
      below = v;
      u = higher;
      visible_.assign(1, u);
      q = 0;
      continue;
    }
    if (visible_.size() > kMaxPlateau) return false;
    ++q;
  }
  if (side_at(x, u) <= 0) {
    s_.near[x] = u;
    return true;
  }
  ++counts_.cuts;
  // The triangles x cuts off, and the edges around them.
  ++stamp_;
  const unsigned cut = 2 * stamp_, kept = 2 * stamp_ + 1;
  visible_.assign(1, u);
  mark_[u] = cut;
  horizon_.clear();
  for (std::size_t q = 0; q < visible_.size(); ++q) {
    const int v = visible_[q];
    for (int k = 0; k < 3; ++k) {
      const int w = s_.across[v][k];
      if (mark_[w] == cut) continue;
      if (mark_[w] != kept) {
        if (side_at(x, w) > 0) {
          mark_[w] = cut;
          visible_.push_back(w);
          continue;
        }
        mark_[w] = kept;
      }
      horizon_.emplace_back(v, k);
    }
  }
  // One triangle (a, b, x) per horizon edge a -> b, in the cut-off triangles' slots first
  // (a disk's boundary has two edges more than it has triangles).
  const int nh = static_cast<int>(horizon_.size()), nv = static_cast<int>(visible_.size());
  ears_.resize(nh);
  outer_.resize(nh);
  for (int h = 0; h < nh; ++h) {
    const auto [v, k] = horizon_[h];
    ears_[h] = {s_.corner[v][k], s_.corner[v][next(k)], x};
    outer_[h] = s_.across[v][k];
    if (!positive(ears_[h][0], ears_[h][1], x)) return false;
  }
  for (int g = 0; g < nh; ++g)
    for (int h = g + 1; h < nh; ++h)
      if (ears_[g][0] == ears_[h][0]) return false;  // not a simple cycle
  fan_.clear();
  for (int h = 0; h < nh; ++h) fan_.push_back(h < nv ? visible_[h] : new_slot());
  for (int h = nh; h < nv; ++h) kill(visible_[h]);
  for (int h = 0; h < nh; ++h) make_triangle(fan_[h], ears_[h]);
  for (int h = 0; h < nh; ++h) {
    const int r = fan_[h], a = ears_[h][0], b = ears_[h][1];
    if (!relink(outer_[h], b, a, r)) return false;
    int after = -1;  // the triangle (b, c, x)
    for (int g = 0; g < nh && after < 0; ++g)
      if (ears_[g][0] == b) after = fan_[g];
    if (after < 0) return false;
    s_.across[r][0] = outer_[h];
    s_.across[r][1] = after;
    s_.across[after][2] = r;
  }
  return true;
}

void SurfaceRepair::seed(const std::vector<std::pair<int, int>>& reflex, int triangles) {
  for (auto it = reflex.rbegin(); it != reflex.rend(); ++it)
    queue_.push_back(
        {it->first, s_.corner[it->first][it->second], s_.corner[it->first][next(it->second)]});
  budget_ += kRepairsPerTriangle * triangles + 16;
}

bool SurfaceRepair::relax(bool may_lift) {
  bool progress = false;
  while (true) {
    if (queue_.empty()) {
      if (waiting_.empty()) break;
      if (!progress && !(may_lift && lift_waiting())) {
        if (region_ < 0 && may_lift) return false;
        if (region_ >= 0 && !may_lift) {
          // They are tested again first in its next run (the whole surface's pass between
          // may have changed their neighbours).
          queue_.assign(waiting_.rbegin(), waiting_.rend());
          waiting_.clear();
          break;
        }
        deferred_.insert(deferred_.end(), waiting_.begin(), waiting_.end());
        waiting_.clear();
        break;
      }
      progress = false;
      // The waiting edges are tested again, after the edges of a lift (the stack's top).
      queue_.insert(queue_.begin(), waiting_.rbegin(), waiting_.rend());
      waiting_.clear();
      continue;
    }
    const Edge edge = queue_.back();
    const auto [t, a, c] = edge;
    queue_.pop_back();
    if (dead_[t]) continue;
    const int i = slot_of(t, a);
    if (i < 0 || s_.corner[t][next(i)] != c) continue;  // changed meanwhile
    const int u = s_.across[t][i];
    if (!mine(u)) {
      deferred_.push_back(edge);
      continue;
    }
    const int j = slot_of(u, c);
    if (j < 0 || s_.corner[u][next(j)] != a) return false;  // not a closed oriented surface
    const int b = s_.corner[t][prev(i)], d = s_.corner[u][prev(j)];
    // (W > 0: a known point, or the meet of positively oriented planes; independent_vertex_of
    // and the checks' side tests assume the same.)
    {
      // (Known where this edge, the same four planes, was tested from either side already:
      // an edge shared by two new triangles is queued by each.)
      const int sd = tested_far_[3 * t + i] == d ? tested_sign_[3 * t + i] : side_at(d, t);
      if (sd <= 0) {
        // (Plane b at u's vertex has the same sign: see build_verified's far-plane tests.)
        record(t, i, d, sd);
        record(u, j, b, sd);
        continue;
      }
    }
    if (--budget_ < 0) return false;
    const int X1 = s_.across[t][next(i)], X2 = s_.across[t][prev(i)], Y1 = s_.across[u][next(j)],
              Y2 = s_.across[u][prev(j)];
    if (!mine(X1) || !mine(Y1)) {  // (the flip relinks them)
      ++budget_;
      deferred_.push_back(edge);
      continue;
    }
    // The new diagonal b -> d is not an edge already: the surface covers the directions
    // about o once (the check's ray before the repair; flips that keep every triangle
    // positive keep that), so its triangles project to a spherical triangulation, each edge
    // a minor arc; with all four triangles positive, the quadrilateral a, d, c, b is convex
    // there and the arc from b to d runs inside it, where no other edge does. (Following
    // b's fan to make sure cost a dozen cache misses a flip.)
    bool outer_ok = b != d;
    for (int o : {X1, X2, Y1, Y2})
      if (o == t || o == u) outer_ok = false;
    // The flip's new triangles (a, d, b) and (d, c, b) (the second tested only when the first
    // is positive).
    int new_ab = 0, new_cb = 0;
    if (outer_ok) {
      new_ab = orientation(a, d, b);
      if (new_ab > 0) new_cb = orientation(d, c, b);
    }
    if (new_ab > 0 && new_cb > 0) {
      if (!relink(Y1, d, a, t) || !relink(X1, b, c, u)) return false;
      make_triangle(t, {a, d, b});
      s_.across[t] = {Y1, u, X2};
      make_triangle(u, {d, c, b});
      s_.across[u] = {Y2, X1, t};
      // The new diagonal's sign is the opposite of the test that flipped it (its four
      // planes in an odd order), as in triangulate_polygon.
      record(t, 1, c, -1);
      record(u, 2, a, -1);
      ++counts_.flips;
      queue_.push_back({t, b, a});
      queue_.push_back({u, c, b});
      queue_.push_back({u, d, c});
      queue_.push_back({t, a, d});
      progress = true;
      continue;
    }
    blocked_ = false;
    if (remove(t, i) || remove(t, next(i))) {
      progress = true;
      continue;
    }
    // The quadrilateral a, d, c, b has a reflex corner: at a when (a, d, b) is negative, at
    // c when (d, c, b) is. That end lies strictly inside the cone of the other three planes'
    // triangle and, the edge being reflex, strictly beneath it: remove's four points and
    // argument, whatever its number of neighbours. It is taken off now, its neighbours'
    // polygon triangulated, rather than waiting for flips elsewhere to leave it three
    // neighbours, or, when every edge is stuck, for a lift and an insertion.
    if (remove_beneath_ && (new_ab < 0 || (new_ab > 0 && new_cb < 0))) {
      if (lift(t, new_ab < 0 ? i : next(i), /*beneath_known=*/true)) {
        progress = true;
        continue;
      }
    }
    ++budget_;
    (blocked_ ? deferred_ : waiting_).push_back(edge);
  }
  return true;
}

void SurfaceRepair::hand_back(std::vector<std::unique_ptr<SurfaceRepair>>& workers,
                              const std::vector<int>& first) {
  for (const Edge& e : deferred_) {
    const auto r = std::upper_bound(first.begin(), first.end(), e[0]) - first.begin() - 1;
    workers[r]->queue_.push_back(e);
  }
  deferred_.clear();
}

void SurfaceRepair::absorb(SurfaceRepair& region) {
  counts_.handed_over += static_cast<long>(region.deferred_.size());
  // (Its edges then come off the stack in the order it left them.)
  queue_.insert(queue_.begin(), region.deferred_.rbegin(), region.deferred_.rend());
  region.deferred_.clear();
  off_.insert(off_.end(), region.off_.begin(), region.off_.end());
  free_.insert(free_.end(), region.free_.begin(), region.free_.end());
  free_vertices_.insert(free_vertices_.end(), region.free_vertices_.begin(),
                        region.free_vertices_.end());
}

bool SurfaceRepair::finish() {
  // Every edge is locally convex: the planes lifted go back where they cut it.
  if (!off_.empty()) {
    std::vector<int> triangle_at(planes_.size(), -1);
    for (int t = 0; t < size(); ++t)
      if (!dead_[t])
        for (const int p : s_.corner[t]) triangle_at[p] = t;
    for (const auto& [x, neighbour] : off_) {
      int p = neighbour;
      for (int hop = 0; triangle_at[p] < 0 && via_[p] >= 0 && hop < kMaxHops; ++hop) p = via_[p];
      if (triangle_at[p] >= 0 && !dead_[triangle_at[p]]) s_.near[x] = triangle_at[p];
      if (!insert(x)) return false;
    }
  }
  return compact();
}

bool SurfaceRepair::insert_cutting(const std::vector<std::pair<int, int>>& cutting) {
  RoundingGuard guard;
  s_.near.assign(planes_.size(), -1);
  for (const auto& [x, t] : cutting) {
    s_.near[x] = t;
    if (!insert(x)) return false;
  }
  return compact();
}

// Drops the removed triangles and carries the far-plane signs that still hold over to
// s_.far_side.
bool SurfaceRepair::compact() {
  const int nt = size();
  // The triangles beyond the kept count fill the removed ones' slots below it (fewer
  // vertex moves than shifting all later ones; the check's result does not depend on the
  // triangles' order).
  std::vector<int> index(nt, -1);
  int kept = 0;
  for (int t = 0; t < nt; ++t) kept += !dead_[t];
  for (int t = 0, hole = 0; t < nt; ++t) {
    if (dead_[t]) continue;
    if (t < kept) {
      index[t] = t;
    } else {
      while (!dead_[hole]) ++hole;
      index[t] = hole++;
    }
  }
  for (int& t : s_.near) {
    // (A triangle removed since: its dual point's neighbour, still near.)
    if (t >= 0 && dead_[t]) t = s_.across[t][0];
    if (t >= 0) t = dead_[t] ? -1 : index[t];
  }
  // The far-plane signs stay for the edges between unchanged triangles, and the repair's
  // own where the far plane is still the one tested (the same four planes).
  std::vector<signed char> far_side(3 * static_cast<std::size_t>(kept), 2);
  for (int t = 0; t < nt; ++t) {
    if (dead_[t]) continue;
    for (int k = 0; k < 3; ++k) {
      const int u = s_.across[t][k];
      if (!changed_[t] && !changed_[u]) {
        far_side[3 * index[t] + k] = s_.far_side[3 * t + k];
      } else if (tested_far_[3 * t + k] >= 0 && s_.far_corner(t, k) == tested_far_[3 * t + k]) {
        far_side[3 * index[t] + k] = tested_sign_[3 * t + k];
      }
    }
  }
  s_.far_side = std::move(far_side);
  s_.oriented = true;
  for (int t = 0; t < nt; ++t) {
    // (Each slot is written once, from itself or from a kept triangle beyond `kept`.)
    if (dead_[t]) continue;
    const int r = index[t];
    s_.corner[r] = s_.corner[t];
    s_.across[r] = {index[s_.across[t][0]], index[s_.across[t][1]], index[s_.across[t][2]]};
    s_.slot[r] = s_.slot[t];
  }
  s_.corner.resize(kept);
  s_.across.resize(kept);
  s_.slot.resize(kept);
  for (const auto& a : s_.across)
    for (int x : a)
      if (x < 0) return false;
  return kept >= 4;
}

/// The regions of a repair of s, per triangle: the face of a cube about o that its first
/// plane's normal points through (nearby triangles have nearby normals, on a fine surface),
/// numbered 0 to `count` - 1 without the empty ones; none (`count` 1) for a surface of fewer
/// than `from` triangles (or `from` 0). (Finer cells were slower: 96 of them at icosphere
/// level 7 lifted planes early, where flips after the other cells' would have done, and
/// made three times the tests a lift: 175 ms against 135 on one thread.)
std::vector<int> repair_regions(const Planes& planes, const DualSurface& s, int from, int& count) {
  const int nt = static_cast<int>(s.corner.size());
  count = 1;
  if (from <= 0 || nt < from) return {};
  std::vector<int> owner(nt);
  parallel_chunks(nt, 4096, [&](int begin, int end) {
    for (int t = begin; t < end; ++t) {
      const V3<double>& n = planes[s.corner[t][0]].nd;
      const double ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
      owner[t] = ax >= ay && ax >= az ? (n.x > 0 ? 0 : 1)
                 : ay >= az           ? (n.y > 0 ? 2 : 3)
                                      : (n.z > 0 ? 4 : 5);
    }
  });
  std::array<int, 6> number;
  number.fill(-1);
  count = 0;
  for (int& o : owner) {
    if (number[o] < 0) number[o] = count++;
    o = number[o];
  }
  return owner;
}

/// Renumbers the triangles of s (corners, links, vertex slots, far-plane signs) so that each
/// region's (`owner`) are in a row, in their order before; `edges` (triangle, edge) follow.
/// Returns where each region's begin, and where the last ends (RepairState::first). A
/// worker then tells its own triangles by a comparison (a region number per triangle cost a
/// cache miss a check), and finds them together in memory, where the guess had made them
/// per vertex of the operand, all over the surface's arrays. (96 regions at icosphere level
/// 7, one thread: 335 ms scattered, 305 in a row, 175 with the comparison.)
std::vector<int> group_regions(DualSurface& s, const std::vector<int>& owner, int regions,
                               std::vector<std::pair<int, int>>& edges) {
  const int nt = static_cast<int>(s.corner.size());
  std::vector<int> first(regions + 1, 0);
  for (const int o : owner) ++first[o + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<int> number(nt), at = first;
  for (int t = 0; t < nt; ++t) number[t] = at[owner[t]]++;
  std::vector<std::array<int, 3>> corner(nt), across(nt);
  std::vector<int> slot(s.slot.empty() ? 0 : nt);
  std::vector<signed char> far_side(s.far_side.empty() ? 0 : 3 * static_cast<std::size_t>(nt));
  parallel_chunks(nt, 4096, [&](int begin, int end) {
    for (int t = begin; t < end; ++t) {
      const int r = number[t];
      corner[r] = s.corner[t];
      for (int k = 0; k < 3; ++k) across[r][k] = number[s.across[t][k]];
      if (!slot.empty()) slot[r] = s.slot[t];
      if (!far_side.empty())
        for (int k = 0; k < 3; ++k) far_side[3 * r + k] = s.far_side[3 * t + k];
    }
  });
  s.corner = std::move(corner);
  s.across = std::move(across);
  s.slot = std::move(slot);
  s.far_side = std::move(far_side);
  for (auto& e : edges) e.first = number[e.first];
  return first;
}

bool repair_surface(const Planes& planes, const PrecisePlanes& precise, const KnownPoints& known,
                    DualSurface& s, const std::vector<std::pair<int, int>>& reflex,
                    int regions_from, bool remove_beneath, RepairCounts& counts) {
  const int nt = static_cast<int>(s.corner.size());
  RepairState state(nt, static_cast<int>(planes.size()));
  state.remove_beneath = remove_beneath;
  s.near.assign(planes.size(), -1);
  s.inside.assign(planes.size(), 0);
  int regions = 1;
  const std::vector<int> owner = repair_regions(planes, s, regions_from, regions);
  SurfaceRepair whole(planes, precise, known, s, state, counts);
  if (regions == 1) {
    RoundingGuard guard;
    whole.seed(reflex, nt);
    return whole.relax() && whole.finish();
  }
  std::vector<std::pair<int, int>> renumbered = reflex;
  state.first = group_regions(s, owner, regions, renumbered);
  std::vector<std::vector<std::pair<int, int>>> edges(regions);
  for (std::size_t e = 0; e < reflex.size(); ++e)
    edges[owner[reflex[e].first]].push_back(renumbered[e]);
  std::vector<RepairCounts> region_counts(regions);
  std::vector<std::unique_ptr<SurfaceRepair>> workers(regions);
  std::atomic<bool> ok = true;
  // First flips and removals alone: lifts in a region's first run, before the flips across
  // its borders, were often early (UV 120 by the snub: 510 lifts against 9 in one pass, 2.6
  // times the tests). The whole surface's pass then does the flips across the borders, and
  // the regions go on with lifts, then the whole surface's pass with what they left.
  parallel_chunks(regions, 1, [&](int begin, int end) {
    RoundingGuard guard;
    for (int r = begin; r < end && ok; ++r) {
      workers[r] =
          std::make_unique<SurfaceRepair>(planes, precise, known, s, state, region_counts[r], r);
      // (A region may take the whole surface's budget: the work gathers where the guess is
      // most wrong, a UV sphere's poles.)
      workers[r]->seed(edges[r], nt);
      if (!workers[r]->relax(/*may_lift=*/false)) ok = false;
    }
  });
  if (!ok) return false;
  RoundingGuard guard;
  counts.regions += regions;
  whole.seed({}, nt);
  for (int r = 0; r < regions; ++r) whole.absorb(*workers[r]);
  if (!whole.relax(/*may_lift=*/false)) return false;
  whole.hand_back(workers, state.first);
  parallel_chunks(regions, 1, [&](int begin, int end) {
    RoundingGuard guard;
    for (int r = begin; r < end && ok; ++r)
      if (!workers[r]->relax()) ok = false;
  });
  if (!ok) return false;
  for (int r = 0; r < regions; ++r) {
    whole.absorb(*workers[r]);
    counts += region_counts[r];
  }
  workers.clear();
  return whole.relax() && whole.finish();
}

/// The check's ray from o: r, with u = e_k x r and w = r x u exactly orthogonal to it, and
/// per plane the signs of its normal against them (`away`, see build_verified). Kept from a
/// check for the check after its repair: the planes are the same, and any ray from o serves
/// the test (it counts the triangles the ray crosses, whichever it is).
struct CheckRay {
  V3<ExactN> r, u, w;
  std::vector<unsigned char> away;
};

constexpr double kAwayRange = 0x1p400;

/// Sign of <g, n> for plane p, g enclosed by gi (any rounding mode; 2 where undecided): the
/// double filter's when p is fast, from g's lower ends gc (within the widths d of g) and
/// p's doubles (each within 2 v of itself, plus a subnormal's gap: kDoubleFloor). The
/// evaluation (three products, two sums: gamma_5) and the normal's error take kMeetError of
/// the magnitude; <d, |n|> (rounded upward) twice covers the move by g's widths. Needs
/// |g| <= kAwayRange (no overflow: |<g, n>| < 2^462).
int away_sign(const Plane& p, const V3<double>& gc, const V3<double>& d) {
  if (!p.fast) return 2;
  const V3<double> na = p.na();
  const double value = dot(gc, p.nd);
  const double magnitude = std::abs(gc.x) * na.x + std::abs(gc.y) * na.y + std::abs(gc.z) * na.z;
  const double bound = kMeetError * magnitude + 2 * dot(d, na) + kDoubleFloor;
  if (value > bound) return 1;
  if (value < -bound) return -1;
  return 2;
}

/// Builds the intersection from a candidate dual hull, checking exactly that it is the
/// dual hull of all the planes; nullopt when it is not. The result has `rounded`, and
/// `polytope` when options.polytope (its exact points computed up front when
/// options.eager_exact, else on demand: polytope_points).
/// `repaired`, when not null (a guess, with its triangles' vertices), allows edges that are
/// not locally convex to be repaired (repair_surface) and the result checked again; it
/// tells whether that happened. `given_ray`: the ray of the check before a repair.
std::optional<MaybePolytope> build_verified(const HalfSpaces& hs, const Planes& planes,
                                            const PrecisePlanes& precise, const KnownPoints& known,
                                            DualSurface s, const IntersectOptions& options,
                                            const std::shared_ptr<const void>& owner,
                                            bool* repaired = nullptr,
                                            const CheckRay* given_ray = nullptr) {
  const bool with_polytope = options.polytope;
  const int nt = static_cast<int>(s.corner.size());
  const int n = static_cast<int>(planes.size());
  if (nt == 0) return std::nullopt;
  RepairCounts scratch;  // where the caller asks for no counts
  RepairCounts& counts = options.counts ? *options.counts : scratch;
  // Every triangle sees o on its inner side: det(n_a, n_b, n_c) > 0 (dual points are the
  // normals scaled by positive factors).
  // A vertex the candidate computed from its corners' planes, in order (not a known point),
  // has W = det(n_a, n_b, n_c) in intervals: positive there is the test passed.
  const auto oriented = [&](int t) {
    if (s.keeps_vertices() && s.has_vertex(t)) {
      const HVertex& v = s.vertex(t);
      if (v.known < 0 && v.planes == s.corner[t] && w_positive(v)) return true;
    }
    return det_sign(s.dual.get(), planes, precise, s.corner[t][0], s.corner[t][1], s.corner[t][2]) >
           0;
  };
  std::atomic<bool> ok = true;
  parallel_chunks(s.oriented ? 0 : nt, 512, [&](int begin, int end) {
    RoundingGuard guard;
    for (int t = begin; t < end && ok; ++t)
      if (!oriented(t)) ok = false;
  });
  if (!ok) return std::nullopt;
  // A ray from o crosses exactly one triangle: through the inside of triangle 0, and
  // strictly inside or outside every other one. (After a repair: the ray before it, through
  // the inside of the triangle that was triangle 0 then; the count is the test.)
  CheckRay made_ray;
  const CheckRay& check_ray = given_ray ? *given_ray : made_ray;
  if (!given_ray) {
    const auto& c0 = s.corner[0];
    V3<ExactN>& r = made_ray.r;
    r = planes[c0[0]].n() + planes[c0[1]].n() + planes[c0[2]].n();
    // A triangle whose three normals lie strictly on one side of a plane through o that
    // holds r or leaves it on the other side (<g, n> > 0 for all three, <g, r> <= 0) is
    // missed without its determinants: its cone holds no such r, so one of them would be
    // negative. Tested by intervals for g = -r (normals pointing away from the ray) and
    // for two planes through the ray, g = +-u and +-w with u = e_k x r, w = r x u exactly
    // orthogonal to r (Mpzf): only the few triangles around the ray are left to test.
    V3<ExactN>& u = made_ray.u;
    u = {ExactN(0), ExactN(0), ExactN(0)};
    {
      // e_k the axis of r's smallest component, so that u is far from zero.
      const double ax = std::abs(r.x.to_double()), ay = std::abs(r.y.to_double()),
                   az = std::abs(r.z.to_double());
      if (ax <= ay && ax <= az)
        u = {ExactN(0), ExactN(0) - r.z, r.y};  // e_x x r
      else if (ay <= az)
        u = {r.z, ExactN(0), ExactN(0) - r.x};  // e_y x r
      else
        u = {ExactN(0) - r.y, r.x, ExactN(0)};  // e_z x r
    }
    made_ray.w = cross(r, u);
    // Per plane, bit 0: <r, n> < 0; bits 1, 2: <u, n> > 0, < 0; bits 3, 4: <w, n> > 0, < 0.
    // Only a filter (a bit not set where the sign is undecided: more triangles tested).
    std::vector<unsigned char>& away = made_ray.away;
    away.resize(n);
    parallel_chunks(n, 1024, [&](int begin, int end) {
      RoundingGuard guard;
      const V3<Interval> gi[3] = {to_interval_n(r), to_interval_n(u), to_interval_n(made_ray.w)};
      // The double filter's copies of r, u, w (their lower ends and widths, rounded up),
      // where all are within kAwayRange.
      V3<double> gc[3], gd[3];
      bool doubles = true;
      for (int g = 0; g < 3; ++g) {
        gc[g] = {gi[g].x.inf(), gi[g].y.inf(), gi[g].z.inf()};
        gd[g] = {gi[g].x.sup() - gi[g].x.inf(), gi[g].y.sup() - gi[g].y.inf(),
                 gi[g].z.sup() - gi[g].z.inf()};
        for (double x : {gi[g].x.inf(), gi[g].x.sup(), gi[g].y.inf(), gi[g].y.sup(), gi[g].z.inf(),
                         gi[g].z.sup()})
          doubles = doubles && std::abs(x) <= kAwayRange;  // (false for NaN)
      }
      const auto sign_of = [&](const Plane& p, int g) {
        const int s = doubles ? away_sign(p, gc[g], gd[g]) : 2;
        return s != 2 ? s : interval_sign(dot(gi[g], p.ni));
      };
      const auto bits = [](int sign, int positive, int negative) {
        return sign == 1 ? positive : sign == -1 ? negative : 0;
      };
      for (int p = begin; p < end; ++p)
        away[p] = static_cast<unsigned char>(bits(sign_of(planes[p], 0), 0, 1) |
                                             bits(sign_of(planes[p], 1), 2, 4) |
                                             bits(sign_of(planes[p], 2), 8, 16));
    });
  }
  {
    const V3<ExactN>& r = check_ray.r;
    const std::vector<unsigned char>& away = check_ray.away;
    std::atomic<int> hits = 0;
    parallel_chunks(nt, 512, [&](int begin, int end) {
      RoundingGuard guard;
      const ExactN zero(0);
      const Plane ray{&r, &zero, nullptr, to_interval_n(r), Interval(0)};
      for (int t = begin; t < end && ok; ++t) {
        if (away[s.corner[t][0]] & away[s.corner[t][1]] & away[s.corner[t][2]]) continue;
        const Plane &a = planes[s.corner[t][0]], &b = planes[s.corner[t][1]],
                    &c = planes[s.corner[t][2]];
        const int s0 = det_sign(ray, b, c);
        if (s0 < 0) continue;
        const int s1 = det_sign(a, ray, c);
        if (s1 < 0) continue;
        const int s2 = det_sign(a, b, ray);
        if (s2 < 0) continue;
        if (s0 == 0 || s1 == 0 || s2 == 0)
          ok = false;  // on a boundary: undecided, let the exact route do it
        else
          ++hits;
      }
    });
    if (!ok || hits != 1) return std::nullopt;
  }
  // Group triangles whose planes meet in one point (exactly coplanar dual triangles):
  // each group is a vertex of the intersection. Every edge between groups must be
  // strictly convex: the far plane of each neighbour is strictly satisfied. Each far plane
  // is tested at the triangle's own vertex, in parallel: a triangle that joins a group has
  // its three planes through the group's point (two shared with a member, the far one
  // tested there), with independent normals (det > 0 above), so its vertex is that point
  // and the signs are the group's. A surface without vertices gets none stored (large,
  // and most would be dropped): each is made for its tests, and the seeds' again below.
  // The two tests of an edge are one: plane d at the vertex of (a, b, c) and plane c at
  // that of (b, a, d) are both the sign of det(r_a, r_b, r_c, r_d) for the rows
  // r = (n, -d) (the vertex of three planes is their rows' generalised cross product, W its
  // last coordinate; the rows' order differs by two swaps), so the triangle with the
  // larger index takes its neighbour's sign. Signs the candidate knows (s.far_side: the
  // flips' tests of a polygon's diagonals, the repair's unchanged edges) are not tested.
  const bool stored = s.keeps_vertices();
  const bool can_repair = repaired && stored;
  if (stored) s.vertices.reserve(nt);  // (at most one vertex a triangle, made in parallel)
  std::atomic<bool> reflex = false;    // an edge to repair
  std::vector<signed char> far_side(3 * static_cast<std::size_t>(nt));
  // The slot of triangle t's edge k in the triangle across it, where that one runs back
  // along it and has t across; -1 otherwise (then each side is tested on its own).
  const auto twin = [&](int t, int k) {
    const int u = s.across[t][k], a = s.corner[t][k], b = s.corner[t][k == 2 ? 0 : k + 1];
    for (int j = 0; j < 3; ++j)
      if (s.corner[u][j] == b && s.corner[u][j == 2 ? 0 : j + 1] == a)
        return s.across[u][j] == t ? j : -1;
    return -1;
  };
  const auto note = [&](int sd) {
    if (sd <= 0) return;
    if (can_repair)
      reflex = true;
    else
      ok = false;
  };
  constexpr signed char kLater = 3;  // taken from the neighbour's test afterwards
  parallel_chunks(nt, 256, [&](int begin, int end) {
    RoundingGuard guard;
    HVertex local;
    for (int t = begin; t < end && ok; ++t) {
      int untested = 0;
      for (int k = 0; k < 3; ++k) {
        signed char& f = far_side[3 * t + k];
        f = s.far_side.empty() ? 2 : s.far_side[3 * t + k];
        if (f != 2) {
          note(f);
        } else if (s.across[t][k] < t && twin(t, k) >= 0) {
          f = kLater;
        } else {
          ++untested;
        }
      }
      if (untested == 0) continue;
      // The vertex is made where a test needs it (the dual points' filter decides most
      // without it: making and storing every triangle's wrote an icosphere's 136 MB again);
      // a stored one is kept for the repair and the steps below, which make the others
      // where they need them.
      bool made = false;  // (local is t's vertex)
      const auto vertex = [&]() -> HVertex& {
        if (stored) return s.stored_vertex(t, planes, known);
        if (made) return local;
        made = true;
        // A polygon's triangles come in a row and, in a closing, share one known point: the
        // previous triangle's vertex is then this one's (nothing copied again).
        const int k =
            known.empty() ? -1 : known.common(s.corner[t][0], s.corner[t][1], s.corner[t][2]);
        if (k >= 0 && k == local.known)
          local.planes = s.corner[t];
        else
          local = independent_vertex_of(planes, s.corner[t], known);
        return local;
      };
      for (int k = 0; k < 3; ++k) {
        if (far_side[3 * t + k] != 2) continue;
        const int far = s.far_corner(t, k);
        int sd = far < 0 ? 1 : dual_side(s.dual.get(), s.corner[t], far);
        if (sd == 2) {
          HVertex& w = vertex();
          sd = known_through(known, far, w) ? 0 : side(planes, precise, far, w);
        }
        note(sd);
        far_side[3 * t + k] = static_cast<signed char>(sd);
      }
    }
  });
  if (!ok) return std::nullopt;
  parallel_chunks(nt, 1024, [&](int begin, int end) {
    for (int t = begin; t < end; ++t)
      for (int k = 0; k < 3; ++k)
        if (far_side[3 * t + k] == kLater) {
          const int u = s.across[t][k];
          far_side[3 * t + k] = far_side[3 * u + twin(t, k)];
          note(far_side[3 * t + k]);
        }
  });
  if (!ok) return std::nullopt;
  if (reflex) {
    // (The repair keeps the vertices stored for triangles it leaves, and makes others where
    // it needs them.)
    std::vector<std::pair<int, int>> edges;
    for (int t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k)
        if (far_side[3 * t + k] > 0) edges.emplace_back(t, k);
    s.far_side = std::move(far_side);
    const bool parallel =
        tbb::this_task_arena::max_concurrency() > 1 || options.repair_regions_on_one_thread;
    if (!repair_surface(planes, precise, known, s, edges,
                        parallel ? options.repair_regions_from : 0, options.remove_beneath, counts))
      return std::nullopt;
    *repaired = true;
    return build_verified(hs, planes, precise, known, std::move(s), options, owner, nullptr,
                          &check_ray);
  }
  // Group triangles across their coplanar edges (far side 0): each group is a vertex. Usually
  // every edge is strictly convex (a simple surface: each triangle is its own vertex,
  // numbered as the search below would), which one scan shows.
  const bool simple =
      std::all_of(far_side.begin(), far_side.end(), [](signed char f) { return f < 0; });
  std::vector<int> group(nt), seed;
  if (simple) {
    std::iota(group.begin(), group.end(), 0);
    seed = group;
  } else {
    std::fill(group.begin(), group.end(), -1);
    std::vector<int> stack;
    for (int t0 = 0; t0 < nt; ++t0) {
      if (group[t0] >= 0) continue;
      const int g = static_cast<int>(seed.size());
      seed.push_back(t0);
      group[t0] = g;
      stack.assign(1, t0);
      while (!stack.empty()) {
        const int t = stack.back();
        stack.pop_back();
        for (int k = 0; k < 3; ++k) {
          if (far_side[3 * t + k] < 0) continue;
          const int nb = s.across[t][k];
          if (group[nb] < 0) {
            group[nb] = g;
            stack.push_back(nb);
          } else if (group[nb] != g) {
            return std::nullopt;
          }
        }
      }
    }
  }
  const int nv = static_cast<int>(seed.size());
  // Each group's vertex is its seed's where the candidate made that one (kept where it is);
  // the others are made now, each chunk's in a row.
  IndexedVertices vertex;
  vertex.index.assign(nv, -1);
  if (stored) {
    vertex.store = std::move(s.vertices);
    for (int g = 0; g < nv; ++g) vertex.index[g] = s.slot[seed[g]];
  }
  vertex.store.reserve(nv);
  parallel_chunks(nv, 256, [&](int begin, int end) {
    RoundingGuard guard;
    int missing = 0;
    for (int g = begin; g < end; ++g) missing += vertex.index[g] < 0;
    if (missing == 0) return;
    int next = vertex.store.add_range(missing);
    for (int g = begin; g < end; ++g)
      if (vertex.index[g] < 0) {
        vertex.index[g] = next++;
        vertex[g] = independent_vertex_of(planes, s.corner[seed[g]], known);
      }
  });
  // The vertex graph (edges between groups): each vertex's neighbours in increasing order,
  // once. A simple surface's are the three triangles across, sorted in place when distinct
  // (and not the triangle itself); otherwise a counting pass by vertex, then each short list
  // sorted.
  std::vector<int> adj_begin(nv + 1, 0), adj;
  bool adj_made = false;
  if (simple) {
    if (sorted_triples(s.across, adj,
                       [](int t, int a, int b, int c) { return (a != t) & (b != t) & (c != t); })) {
      for (int v = 0; v <= nv; ++v) adj_begin[v] = 3 * v;
      adj_made = true;
    }
  }
  if (!adj_made) {
    for (int t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k)
        if (group[s.across[t][k]] != group[t]) ++adj_begin[group[t] + 1];
    std::partial_sum(adj_begin.begin(), adj_begin.end(), adj_begin.begin());
    adj.resize(adj_begin[nv]);
    std::vector<int> next(adj_begin.begin(), adj_begin.end() - 1);
    for (int t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k)
        if (group[s.across[t][k]] != group[t]) adj[next[group[t]]++] = group[s.across[t][k]];
    sort_unique_lists(adj_begin, adj);
  }
  // Facets: dual vertices with at least three groups around them (others lie on a dual
  // edge or facet: their planes only touch the intersection).
  std::vector<int> some_triangle(n, -1);
  for (int t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) some_triangle[s.corner[t][k]] = t;
  // Facet f's cycle of vertices is face_vertex[face_begin[f] .. face_begin[f + 1]).
  // The walk around each plane visits the triangles at it once (a closed surface, checked
  // above): 3 nt entries at most, written by index (push_back was not inlined here).
  std::vector<int> face_begin(n + 1), face_vertex(3 * static_cast<std::size_t>(nt)),
      face_halfspace(n);
  face_begin[0] = 0;
  int facets = 0;
  std::size_t used = 0;
  for (int p = 0; p < n; ++p) {
    const int first = some_triangle[p];
    if (first < 0) continue;
    const std::size_t start = used;
    int t = first, steps = 0;
    do {
      const int g = group[t];
      if (used == start || face_vertex[used - 1] != g) {
        if (used == face_vertex.size()) return std::nullopt;  // (not a closed surface)
        face_vertex[used++] = g;
      }
      // p's first corner in t, without branches (its place is unpredictable).
      const auto& c = s.corner[t];
      const int not0 = c[0] != p;
      const int k = not0 + (not0 & (c[1] != p));
      if (c[k] != p || ++steps > nt) return std::nullopt;
      t = s.across[t][k];
    } while (t != first);
    while (used > start + 1 && face_vertex[start] == face_vertex[used - 1]) --used;
    if (used < start + 3) {
      used = start;
      continue;
    }
    face_halfspace[facets] = p;
    face_begin[++facets] = static_cast<int>(used);
  }
  face_vertex.resize(used);
  face_begin.resize(facets + 1);
  face_halfspace.resize(facets);
  const int nf = facets;
  if (nf < 4) return std::nullopt;
  // Precise vertices, for the checks below (a second filter stage) and the rounding; exact
  // ones only where those cannot decide (LazyExact; for a polytope computed with further,
  // see polytope_points).
  // The planes of vertices that are not known points are made precise up front; the
  // others when the walk below first needs them.
  {
    std::vector<char> used(n, 0);
    for (int g = 0; g < vertex.size(); ++g) {
      const HVertex& v = vertex[g];
      if (v.known < 0 && !v.precise) used[v.planes[0]] = used[v.planes[1]] = used[v.planes[2]] = 1;
    }
    parallel_chunks(n, 256, [&](int begin, int end) {
      for (int i = begin; i < end; ++i)
        if (used[i]) precise[i];
    });
  }
  // (A vertex made precise by the flips or the checks above keeps it.)
  parallel_chunks(nv, 128, [&](int begin, int end) {
    RoundingGuard nearest(CGAL_FE_TONEAREST);
    for (int v = begin; v < end; ++v) {
      // Each vertex reads three planes, scattered: those of one a few ahead are fetched now.
      if (v + PrecisePlanes::kAhead < end)
        for (const int i : vertex[v + PrecisePlanes::kAhead].planes) precise.prefetch(i);
      if (!vertex[v].precise) make_precise(precise, vertex[v]);
    }
  });
  LazyExact exact_vertex(planes, vertex);
  const auto side_of = [&](int i, int v) {
    const Plane& p = planes[i];
    const int s = side_filter(planes, precise, i, vertex[v]);
    return s != 2 ? s : side_exact(p, exact_vertex(v));
  };
  // The candidate is a convex polytope. Every plane that is not a dual vertex must not cut
  // it: climb to its highest vertex (a local maximum is global on a convex polytope) and
  // collect the vertices where it touches (sorted). Where the plane is known to pass through
  // a vertex (a known point: in a closing, every facet of S not on A touches A at its corners'
  // vertices of A), the climb starts there and usually ends at once; where it does not, at
  // the chunk's last vertex. The result does not depend on the start. Two vertices both
  // known on the plane compare equal without arithmetic.
  // (Not those a repair removed, strictly inside: see DualSurface::inside;
  // with options.verify_certified, those too, each that is not strictly inside counted.)
  std::vector<int> others;
  const auto certified_inside = [&](int p) { return !s.inside.empty() && s.inside[p]; };
  for (int p = 0; p < n; ++p)
    if (some_triangle[p] < 0 && (options.verify_certified || !certified_inside(p)))
      others.push_back(p);
  std::atomic<long> inside_wrong = 0;
  std::vector<int> vertex_at_point;  // the vertex that is known point k, or -1
  if (!known.empty() && !others.empty()) {
    vertex_at_point.assign(known.size(), -1);
    for (int v = 0; v < nv; ++v)
      if (vertex[v].known >= 0) vertex_at_point[vertex[v].known] = v;
  }
  std::vector<std::vector<int>> touched(others.size());
  // Per plane off the surface that cuts it, where a guess may be repaired: the vertex it
  // cuts off (the climb's end), else -1.
  std::vector<int> cut(can_repair ? others.size() : 0, -1);
  std::atomic<long> check_steps = 0;
  parallel_chunks(static_cast<int>(others.size()), 64, [&](int begin, int end) {
    RoundingGuard guard;
    long steps = 0;
    int u = 0;
    std::vector<int> plateau;  // scratch: each list is then allocated once, at its size
    std::vector<signed char> sides;
    for (int j = begin; j < end && ok; ++j) {
      const int i = others[j];
      const Plane& p = planes[i];
      int start = seed[u];  // a triangle of u, where a walk starts
      if (!s.near.empty() && s.near[i] >= 0) u = group[start = s.near[i]];
      if (!known.empty())
        for (int k = known.begin[others[j]]; k < known.begin[others[j] + 1]; ++k)
          if (vertex_at_point[known.point[k]] >= 0) {
            u = vertex_at_point[known.point[k]];
            start = seed[u];
            break;
          }
      // Unless u is known on the plane, the walk to the triangle whose cone holds the normal
      // (walk_to_cone: the candidate is convex) ends at the highest vertex, and the climb only
      // goes on where it did not arrive or ends on a known point.
      bool walked = false;
      if (!known_through(known, others[j], vertex[u]) &&
          walk_to_cone(s, planes, precise, s.dual.get(), i, start, steps)) {
        u = group[start];
        walked = true;
      }
      // With u known on the plane, a neighbour compares with u as it lies to the plane (the
      // cheaper test), and those sides (`sides`, when the climb ends there) start the plateau.
      bool u_on = false;
      for (bool moved = true; moved;) {
        moved = false;
        u_on = known_through(known, others[j], vertex[u]);
        if (walked && !u_on) break;
        sides.clear();
        for (int a = adj_begin[u]; a < adj_begin[u + 1]; ++a) {
          int s;
          if (u_on) {
            s = known_through(known, others[j], vertex[adj[a]]) ? 0 : side_of(i, adj[a]);
            sides.push_back(static_cast<signed char>(s));
          } else {
            s = compare_filter(planes, precise, i, vertex[adj[a]], vertex[u]);
            if (s == 2) s = compare_exact(p, exact_vertex(adj[a]), exact_vertex(u));
          }
          if (s > 0) {
            u = adj[a];
            moved = true;
            break;
          }
        }
      }
      // (After a walk, u is the vertex of the triangle it ended on: the dual points first.)
      int sd = u_on ? 0 : walked ? dual_side(s.dual.get(), s.corner[start], i) : 2;
      if (sd == 2) sd = side_of(i, u);
      if (sd >= 0 && certified_inside(i)) ++inside_wrong;
      if (sd > 0) {
        if (can_repair)
          cut[j] = u;
        else
          ok = false;
      }
      if (sd != 0) continue;
      plateau.assign(1, u);
      for (std::size_t q = 0; q < plateau.size(); ++q)
        for (int a = adj_begin[plateau[q]]; a < adj_begin[plateau[q] + 1]; ++a)
          if (std::find(plateau.begin(), plateau.end(), adj[a]) == plateau.end() &&
              (q == 0 && u_on
                   ? sides[a - adj_begin[u]] == 0
                   : known_through(known, others[j], vertex[adj[a]]) || side_of(i, adj[a]) == 0))
            plateau.push_back(adj[a]);
      std::sort(plateau.begin(), plateau.end());
      touched[j].assign(plateau.begin(), plateau.end());
    }
    check_steps += steps;
  });
  counts.check_planes += static_cast<long>(others.size());
  counts.check_steps += check_steps;
  counts.certified_wrong += inside_wrong;
  if (!ok) return std::nullopt;
  if (std::any_of(cut.begin(), cut.end(), [](int v) { return v >= 0; })) {
    // Planes the guess left out that cut it (a closing of a UV sphere, whose result is not
    // quite A: facets of B or edge facets of S just outside A's nearly planar facets). The
    // candidate is convex here (every edge locally convex): they are inserted as the
    // incremental hull would, and the result checked again.
    std::vector<int> triangle_of(nv, -1);
    bool identity = nv == nt;
    for (int t = 0; t < nt; ++t) {
      triangle_of[group[t]] = t;
      identity = identity && group[t] == t;
    }
    std::vector<std::pair<int, int>> cutting;
    for (std::size_t j = 0; j < others.size(); ++j)
      if (cut[j] >= 0) cutting.emplace_back(others[j], triangle_of[cut[j]]);
    // The vertices of the triangles that are their own group; the others made again. (A UV
    // sphere's pole is one group of many triangles: before, every vertex was made again
    // then, and their precise coordinates.)
    if (identity) {
      s.slot = std::move(vertex.index);
    } else {
      std::vector<int> members(nv, 0);
      for (int t = 0; t < nt; ++t) ++members[group[t]];
      s.slot.assign(nt, -1);
      for (int t = 0; t < nt; ++t)
        if (members[group[t]] == 1) s.slot[t] = vertex.index[group[t]];
    }
    s.vertices = std::move(vertex.store);
    s.far_side = std::move(far_side);
    RepairState state(nt, static_cast<int>(planes.size()));
    if (!SurfaceRepair(planes, precise, known, s, state, counts).insert_cutting(cutting))
      return std::nullopt;
    *repaired = true;
    return build_verified(hs, planes, precise, known, std::move(s), options, owner, nullptr,
                          &check_ray);
  }
  // Verified. The half-spaces through each vertex (key[key_begin[v] ..), sorted, once):
  // those of its triangles and the touching ones. A touching plane along a whole facet is
  // that facet's plane given twice: the facet takes the smaller index.
  // A simple surface's vertex without touching planes has its triangle's three corners
  // (distinct on a valid surface; otherwise the general pass below).
  std::vector<int> key_begin(nv + 1, 0), key;
  bool key_made = false;
  if (simple && std::all_of(touched.begin(), touched.end(),
                            [](const std::vector<int>& plateau) { return plateau.empty(); })) {
    if (sorted_triples(s.corner, key, [](int, int, int, int) { return true; })) {
      for (int v = 0; v <= nv; ++v) key_begin[v] = 3 * v;
      key_made = true;
    }
  }
  if (!key_made) {
    for (int t = 0; t < nt; ++t) key_begin[group[t] + 1] += 3;
    for (const auto& plateau : touched)
      for (int v : plateau) ++key_begin[v + 1];
    std::partial_sum(key_begin.begin(), key_begin.end(), key_begin.begin());
    key.resize(key_begin[nv]);
    {
      std::vector<int> next(key_begin.begin(), key_begin.end() - 1);
      for (int t = 0; t < nt; ++t)
        for (int a : s.corner[t]) key[next[group[t]]++] = a;
      for (std::size_t j = 0; j < others.size(); ++j)
        for (int v : touched[j]) key[next[v]++] = others[j];
    }
    sort_unique_lists(key_begin, key);
  }
  for (std::size_t j = 0; j < others.size(); ++j) {
    if (touched[j].size() < 3) continue;
    for (int f = 0; f < nf; ++f) {
      if (face_begin[f + 1] - face_begin[f] != static_cast<int>(touched[j].size())) continue;
      std::vector<int> cyc(face_vertex.begin() + face_begin[f],
                           face_vertex.begin() + face_begin[f + 1]);
      std::sort(cyc.begin(), cyc.end());
      if (cyc == touched[j]) face_halfspace[f] = std::min(face_halfspace[f], others[j]);
    }
  }
  // Number vertices and facets canonically (hull orders depend on CGAL's internal
  // shuffling): a vertex by the sorted half-spaces through it, a facet by its half-space,
  // each cycle starting at its smallest vertex. The output then depends only on the input.
  // Both orders are strict (no two vertices have the same half-spaces, no two facets the
  // same one), so bucket passes give them: vertices by their smallest half-space, each
  // bucket (a few vertices) then sorted by the whole list.
  std::vector<int> order(nv), rank(nv);
  {
    std::vector<int> bucket(n + 1, 0);
    for (int v = 0; v < nv; ++v) ++bucket[key[key_begin[v]] + 1];
    std::partial_sum(bucket.begin(), bucket.end(), bucket.begin());
    std::vector<int> next(bucket.begin(), bucket.end() - 1);
    for (int v = 0; v < nv; ++v) order[next[key[key_begin[v]]]++] = v;
    const auto key_less = [&](int a, int b) {
      return std::lexicographical_compare(
          key.begin() + key_begin[a], key.begin() + key_begin[a + 1], key.begin() + key_begin[b],
          key.begin() + key_begin[b + 1]);
    };
    for (int p = 0; p < n; ++p)
      if (bucket[p + 1] - bucket[p] > 1)
        std::sort(order.begin() + bucket[p], order.begin() + bucket[p + 1], key_less);
  }
  for (int r = 0; r < nv; ++r) rank[order[r]] = r;
  {
    std::vector<int> facet_of(n, -1);  // by half-space
    for (int f = 0; f < nf; ++f) facet_of[face_halfspace[f]] = f;
    std::vector<int> sorted_begin(nf + 1), sorted_vertex(face_vertex.size()), sorted_halfspace(nf);
    sorted_begin[0] = 0;
    int sorted = 0, written = 0;
    for (int p = 0; p < n; ++p) {
      const int f = facet_of[p];
      if (f < 0) continue;
      // The cycle from its smallest vertex (the first one if repeated), found without
      // branches (ranks come in no order).
      const int first = face_begin[f], size = face_begin[f + 1] - first;
      int least = rank[face_vertex[first]], at = 0;
      for (int j = 1; j < size; ++j) {
        const int r = rank[face_vertex[first + j]];
        const bool less = r < least;
        least = less ? r : least;
        at = less ? j : at;
      }
      for (int j = at; j < size; ++j) sorted_vertex[written++] = rank[face_vertex[first + j]];
      for (int j = 0; j < at; ++j) sorted_vertex[written++] = rank[face_vertex[first + j]];
      sorted_halfspace[sorted] = p;
      sorted_begin[++sorted] = written;
    }
    sorted_begin.resize(sorted + 1);
    sorted_halfspace.resize(sorted);
    face_begin = std::move(sorted_begin);
    face_vertex = std::move(sorted_vertex);
    face_halfspace = std::move(sorted_halfspace);
  }
  // Circulating around a dual vertex may run clockwise: orient by the first facet.
  {
    std::vector<int> cyc(face_vertex.begin(), face_vertex.begin() + face_begin[1]);
    for (int& r : cyc) r = order[r];
    {
      RoundingGuard guard;
      for (int r : cyc) make_intervals(planes, vertex[r]);
    }
    if (clockwise(cyc, vertex, hs[face_halfspace[0]].exact_normal(), exact_vertex))
      for (int f = 0; f < nf; ++f)
        std::reverse(face_vertex.begin() + face_begin[f], face_vertex.begin() + face_begin[f + 1]);
  }
  // Rounded vertices, exactly rounded from the homogeneous coordinates: from the precise
  // ones unless they lie too close to a rounding midpoint, from the exact ones then.
  MaybePolytope out;
  RoundedPolytope& rp = out.rounded;
  rp.points.resize(nv);
  parallel_chunks(nv, 128, [&](int begin, int end) {
    RoundingGuard nearest(CGAL_FE_TONEAREST);  // for round_precise
    const auto coordinate = [](const auto& p, int i) -> const auto& {
      return i == 0 ? p.x : i == 1 ? p.y : p.z;
    };
    // In the vertices' order, each written to its place in the output's (rank): reading
    // the records in the output's order missed the cache on most of them.
    for (int u = begin; u < end; ++u) {
      const HVertex& v = vertex[u];
      double rounded[3];
      const double inverse = v.precise ? 1 / v.pw.hi : 0;
      for (int i = 0; i < 3; ++i) {
        if (v.exact_dd) {  // X / 1 exactly hi + lo: the sum rounds it (ties to even)
          rounded[i] = coordinate(v.px, i).hi + coordinate(v.px, i).lo;
          continue;
        }
        if (v.doubles) {
          rounded[i] = coordinate(*v.X, i).to_double();
          continue;
        }
        if (v.precise && round_precise(coordinate(v.px, i), coordinate(v.ex, i), v.pw, v.ew,
                                       inverse, rounded[i]))
          continue;
        const HVertex& e = exact_vertex(u);
        // (Any estimate serves: round_quotient only starts from it, and gives up for the
        // rational quotient, a gcd, after four ulps. A vertex with only the double filter's
        // X and W, within 2^-48 of their magnitudes, starts from the exact values' doubles.)
        const double q = v.intervals ? 0 : coordinate(*e.X, i).to_double() / e.W->to_double();
        const Interval estimate =
            v.intervals ? coordinate(v.Xi, i) / v.Wi : Interval(std::isfinite(q) ? q : 0.0);
        rounded[i] = round_quotient(coordinate(*e.X, i), *e.W, estimate);
      }
      rp.points[rank[u]] = {rounded[0], rounded[1], rounded[2]};
    }
  });
  rp.face_source.resize(nf);
  rp.face_element.resize(nf);
  // (Large half-spaces, each read for two labels: the misses are overlapped.)
  constexpr int kLabelsAhead = 8;
  for (int f = 0; f < nf; ++f) {
    if (f + kLabelsAhead < nf) __builtin_prefetch(&hs[face_halfspace[f + kLabelsAhead]].source);
    rp.face_source[f] = hs[face_halfspace[f]].source;
    rp.face_element[f] = hs[face_halfspace[f]].element;
  }
  if (with_polytope) {
    ExactPoints points = polytope_points(planes, vertex, order, options.eager_exact, owner);
    Polytope p;
    // Facet f's normal is its half-space's: read from there where `owner` keeps the
    // half-spaces (made exact on first read), else copied.
    const auto copied = [&] {
      std::vector<V3<ExactN>> normals(nf);
      for (int f = 0; f < nf; ++f) normals[f] = hs[face_halfspace[f]].exact_normal();
      return normals;
    };
    if (options.direct_polytope) {
      GivenNormals normals =
          owner ? GivenNormals(std::make_shared<const HalfSpaceNormals>(hs, face_halfspace, owner),
                               nf)
                : GivenNormals(copied());
      p = verified_polytope(rp.points, std::move(points), face_begin, face_vertex,
                            std::move(normals));
    } else {
      std::vector<std::vector<int>> faces;
      for (int f = 0; f < nf; ++f)
        faces.emplace_back(face_vertex.begin() + face_begin[f],
                           face_vertex.begin() + face_begin[f + 1]);
      p = make_polytope(rp.points, std::move(points), faces, copied(), "A (-) B");
    }
    for (auto& src : p.face_source) src = hs[face_halfspace[src]].source;
    out.polytope = std::move(p);
  }
  rp.face_begin = std::move(face_begin);
  rp.corner_vertex = std::move(face_vertex);
  return out;
}

/// The exact dual hull, built incrementally on the planes themselves: the dual point of a
/// plane sees a dual triangle iff the plane cuts off the triangle's vertex (side > 0), an
/// interval-filtered test on dyadic homogeneous coordinates, exact only when undecided.
/// Randomised insertion order (fixed seed); each pending plane keeps one triangle it sees
/// and, when that one is replaced, looks among the new triangles only (as in Quickhull:
/// a plane that sees none of them no longer cuts the intersection). Exact degeneracies
/// need no care: a plane through a vertex (side 0) sees nothing, and exactly coplanar
/// dual triangles are grouped by the builder. Starts from four virtual planes, a regular
/// tetrahedron around o reaching `reach` beyond it; if one is left on the hull the
/// tetrahedron did not hold the intersection (run again with a larger reach).
class IncrementalHull {
 public:
  enum class Outcome { hull, too_small, failed };

  IncrementalHull(const Planes& planes, const PrecisePlanes& precise, const KnownPoints& known,
                  const V3<double>& o, double reach)
      : planes_(planes), precise_(precise), known_(known), n_(static_cast<int>(planes.size())) {
    const double dirs[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
    for (int k = 0; k < 4; ++k) {
      const V3<ExactN> m{ExactN(dirs[k][0]), ExactN(dirs[k][1]), ExactN(dirs[k][2])};
      const ExactN d = dot(m, to_exact_n(o)) + ExactN(reach);
      Plane& v = virtual_[k];
      v.scaled = std::make_shared<const ExactPlane>(ExactPlane{m, d});
      v.n_exact = &v.scaled->n;
      v.d_exact = &v.scaled->d;
      v.ni = to_interval_n(m);
      v.di = to_interval_n(d);
    }
  }

  /// The hull in `out` when the outcome is `hull`.
  Outcome run(DualSurface& out) {
    RoundingGuard guard;
    start();
    std::vector<int> order(n_);
    std::iota(order.begin(), order.end(), 0);
    std::uint64_t state = 0x9e3779b97f4a7c15ull;  // fixed seed: the result must not vary
    for (int i = n_ - 1; i > 0; --i) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      std::swap(order[i],
                order[static_cast<int>((state >> 33) % static_cast<std::uint64_t>(i + 1))]);
    }
    for (int p : order)
      if (conflict_[p] >= 0 && !insert(p)) return Outcome::failed;
    std::vector<int> index(tris_.size(), -1);
    out = {};
    for (std::size_t t = 0; t < tris_.size(); ++t) {
      if (!tris_[t].alive) continue;
      if (std::max({tris_[t].c[0], tris_[t].c[1], tris_[t].c[2]}) >= n_) return Outcome::too_small;
      index[t] = static_cast<int>(out.corner.size());
      out.corner.push_back(tris_[t].c);
    }
    for (const Tri& t : tris_)
      if (t.alive)
        out.across.push_back({index[t.across[0]], index[t.across[1]], index[t.across[2]]});
    // Each triangle's vertex for the check, as far as the run computed it (the intervals of
    // its meet, its precise and exact coordinates, its known point); one whose W is not
    // positive by intervals is left to the check.
    out.slot.assign(out.corner.size(), -1);
    for (std::size_t t = 0; t < tris_.size(); ++t) {
      const Tri& tri = tris_[t];
      if (!tri.alive || !(tri.Wi.inf() > 0)) continue;
      out.slot[index[t]] = out.vertices.add_range(1);
      HVertex& v = out.vertex(index[t]);
      v.planes = tri.c;
      if (tri.known >= 0) {
        set_known(known_, tri.known, v);
      } else {
        v.Xi = tri.Xi;
        v.Wi = tri.Wi;
        v.intervals = true;
        if (tri.precise >= 0) {
          const HVertex& q = precise_vertex_[tri.precise];
          v.px = q.px;
          v.pw = q.pw;
          v.ex = q.ex;
          v.ew = q.ew;
          v.precise = true;
        }
        v.precise_tried = tri.precise != -1;
        if (tri.exact >= 0) set_exact(v, exact_[tri.exact].X, exact_[tri.exact].W);
      }
    }
    return Outcome::hull;
  }

 private:
  struct Tri {
    std::array<int, 3> c, across;  // edge k runs from corner k to corner k + 1
    V3<Interval> Xi;               // the vertex of the three planes, X / W
    Interval Wi;
    int exact = -1;     // its exact coordinates in exact_, once computed
    int precise = -1;   // its precise coordinates in precise_vertex_, once tried (-2: none)
    int known = -1;     // the known point it is, if any (KnownPoints)
    int pending = -1;   // first of the planes that see it (linked by next_pending_)
    int replaced = -1;  // once removed: a new triangle made on one of its horizon edges
    bool alive = true;
  };
  struct ExactVertex {
    V3<ExactN> X;
    ExactN W;
  };

  const Plane& plane(int i) const { return i < n_ ? planes_[i] : virtual_[i - n_]; }

  /// Adds triangle (a, b, c) with the cross products of its corners' normals along its edges
  /// (edge k, corner k to k + 1: ab = n_a x n_b, bc, ca), kept for the triangles made next
  /// to it (edge_cross_).
  int add(int a, int b, int c, const V3<Interval>& ab, const V3<Interval>& bc,
          const V3<Interval>& ca) {
    Tri t;
    t.c = {a, b, c};
    t.across = {-1, -1, -1};
    const Plane& pa = plane(a);
    meet_of_crosses(pa.ni, pa.di, plane(b).di, plane(c).di, bc, ca, ab, t.Xi, t.Wi);
    // Three planes through a known point with independent normals (W > 0) meet there.
    if (!known_.empty() && a < n_ && b < n_ && c < n_ && t.Wi.inf() > 0)
      t.known = known_.common(a, b, c);
    tris_.push_back(t);
    edge_cross_.push_back({ab, bc, ca});
    return static_cast<int>(tris_.size()) - 1;
  }
  int add(int a, int b, int c) {
    const V3<Interval>&na = plane(a).ni, &nb = plane(b).ni, &nc = plane(c).ni;
    return add(a, b, c, cross(na, nb), cross(nb, nc), cross(nc, na));
  }

  int side_of(int p, int t) {
    Tri& tri = tris_[t];
    const Plane& h = plane(p);
    if (tri.known >= 0) {  // the same sign as on the meet (a positive multiple)
      const int k = tri.known;
      if (p < n_ && known_.passes(p, k)) return 0;
      const int s = interval_sign(dot(h.ni, known_.Xi[k]) - h.di * known_.Wi[k]);
      return s != 2 ? s : CGAL::sign(dot(h.n(), known_.exact_X(k)) - h.d() * known_.exact_W(k));
    }
    const int s = interval_sign(dot(h.ni, tri.Xi) - h.di * tri.Wi);
    if (s != 2) return s;
    // The precise stage, for real planes (nearly through one point: the moved facets around
    // a vertex of a nearly planar A).
    if (p < n_ && tri.precise != -2 && std::max({tri.c[0], tri.c[1], tri.c[2]}) < n_) {
      RoundingGuard nearest(CGAL_FE_TONEAREST);
      if (tri.precise < 0) {
        HVertex v;
        v.planes = tri.c;
        make_precise(precise_, v);
        if (v.precise) {
          precise_vertex_.push_back(std::move(v));
          tri.precise = static_cast<int>(precise_vertex_.size()) - 1;
        } else {
          tri.precise = -2;
        }
      }
      const PrecisePlane& q = precise_[p];
      if (tri.precise >= 0 && q.valid()) {
        const int t = precise_side(q, precise_vertex_[tri.precise]);
        if (t != 2) return t;
      }
    }
    if (tri.exact < 0) {
      const Plane &a = plane(tri.c[0]), &b = plane(tri.c[1]), &c = plane(tri.c[2]);
      ExactVertex& v = exact_.emplace_back();
      meet(a.n(), a.d(), b.n(), b.d(), c.n(), c.d(), v.X, v.W);
      tri.exact = static_cast<int>(exact_.size()) - 1;
    }
    const ExactVertex& v = exact_[tri.exact];
    return CGAL::sign(dot(h.n(), v.X) - h.d() * v.W);
  }

  void see(int p, int t) {
    conflict_[p] = t;
    next_pending_[p] = tris_[t].pending;
    tris_[t].pending = p;
  }

  // The tetrahedron of the virtual planes, then every real plane's first conflict.
  void start() {
    const int n = n_;
    tris_.reserve(8 * static_cast<std::size_t>(n) + 16);
    edge_cross_.reserve(tris_.capacity());
    around_cross_.resize(n + 4);
    // Around vertex n + 3 (det of the other three normals > 0 in this order).
    const int t0 = add(n, n + 1, n + 2), t1 = add(n + 1, n, n + 3), t2 = add(n + 2, n + 1, n + 3),
              t3 = add(n, n + 2, n + 3);
    tris_[t0].across = {t1, t2, t3};
    tris_[t1].across = {t0, t3, t2};
    tris_[t2].across = {t0, t1, t3};
    tris_[t3].across = {t0, t2, t1};
    conflict_.assign(n, -1);
    next_pending_.assign(n, -1);
    start_at_.assign(n + 4, -1);
    for (int p = 0; p < n; ++p) {
      for (int t = t0; t <= t3; ++t) {
        if (side_of(p, t) > 0) {
          see(p, t);
          break;
        }
      }
    }
  }

  bool insert(int p) {
    // The visible triangles (connected), and the horizon around them.
    visible_.assign(1, conflict_[p]);
    tris_[visible_[0]].alive = false;
    horizon_.clear();
    for (std::size_t q = 0; q < visible_.size(); ++q) {
      const int t = visible_[q];
      for (int k = 0; k < 3; ++k) {
        const int nb = tris_[t].across[k];
        if (!tris_[nb].alive) continue;
        if (side_of(p, nb) > 0) {
          tris_[nb].alive = false;
          visible_.push_back(nb);
        } else {
          horizon_.emplace_back(t, k);
        }
      }
    }
    // A horizon edge may have been recorded before its far triangle turned out visible.
    horizon_.erase(std::remove_if(horizon_.begin(), horizon_.end(),
                                  [&](const auto& h) {
                                    return !tris_[tris_[h.first].across[h.second]].alive;
                                  }),
                   horizon_.end());
    // One new triangle (u, w, p) per horizon edge u -> w, linked around p.
    created_.clear();
    bool ok = true;
    // Each new triangle (u, w, p) needs n_u x n_w (the removed triangle's, along its edge
    // u -> w), n_w x n_p and n_p x n_u: the last computed once per horizon vertex u
    // (around_cross_), the other the next triangle's negated (negation is exact: the same
    // intervals as computed afresh). A w that starts no horizon edge fails the insertion below.
    const V3<Interval>& np = plane(p).ni;
    for (const auto& [t, k] : horizon_) {
      const int u = tris_[t].c[k];
      around_cross_[u] = cross(np, plane(u).ni);
    }
    const auto negated = [](const V3<Interval>& v) { return V3<Interval>{-v.x, -v.y, -v.z}; };
    for (const auto& [t, k] : horizon_) {
      const int u = tris_[t].c[k], w = tris_[t].c[(k + 1) % 3];
      const int kept = tris_[t].across[k];
      const int nt = add(u, w, p, edge_cross_[t][k], negated(around_cross_[w]), around_cross_[u]);
      tris_[nt].across[0] = kept;
      int j = 0;
      while (j < 3 && tris_[kept].across[j] != t) ++j;
      if (j == 3 || start_at_[u] >= 0) ok = false;
      if (!ok) break;
      tris_[kept].across[j] = nt;
      tris_[t].replaced = nt;
      start_at_[u] = nt;
      created_.push_back(nt);
    }
    for (int nt : created_) {
      const int next = start_at_[tris_[nt].c[1]];
      if (next < 0) ok = false;
      if (!ok) break;
      tris_[nt].across[1] = next;
      tris_[next].across[2] = nt;
    }
    for (int nt : created_) start_at_[tris_[nt].c[0]] = -1;
    if (!ok) return false;
    // Pending planes of the removed triangles look for a new triangle they see.
    for (int t : visible_) {
      for (int q = tris_[t].pending, next; q >= 0; q = next) {
        next = next_pending_[q];
        conflict_[q] = -1;
        if (q == p) continue;
        // The new triangle made on t's horizon edge first (q saw t, and often sees what
        // replaced it), then the others in order. Which one q records does not change the
        // hull: the visible triangles found from any of them are the same.
        const int near = tris_[t].replaced;
        if (near >= 0 && side_of(q, near) > 0) {
          see(q, near);
          continue;
        }
        for (int nt : created_) {
          if (nt != near && side_of(q, nt) > 0) {
            see(q, nt);
            break;
          }
        }
      }
      tris_[t].pending = -1;
    }
    return true;
  }

  const Planes& planes_;
  const PrecisePlanes& precise_;
  const KnownPoints& known_;
  int n_;
  std::array<Plane, 4> virtual_;
  std::vector<Tri> tris_;
  std::vector<std::array<V3<Interval>, 3>> edge_cross_;  // per triangle: ab, bc, ca (add)
  std::vector<V3<Interval>> around_cross_;  // per plane: n_p x n_u around the inserted p
  std::deque<ExactVertex> exact_;
  std::deque<HVertex> precise_vertex_;
  std::vector<int> conflict_, next_pending_;  // per real plane
  std::vector<int> start_at_;                 // per plane: new triangle starting there
  std::vector<int> visible_, created_;
  std::vector<std::pair<int, int>> horizon_;
};

/// A power of two that the distance (L1) from o to the intersection's vertices most likely
/// stays below: a few times the largest distance from o to a plane (the run checks it).
double first_reach(const Planes& planes, const V3<double>& o) {
  double r = 0;
  for (const Plane& p : planes) {
    const V3<double> n{p.n().x.to_double(), p.n().y.to_double(), p.n().z.to_double()};
    const double dist = (p.d().to_double() - dot(n, o)) / std::sqrt(dot(n, n));
    if (std::isfinite(dist)) r = std::max(r, dist);
  }
  return std::ldexp(1.0, std::ilogb(std::max(r, 1e-300)) + 4);
}

/// The dual hull of the exact dual points about o: n / (d - <n, o>), with o = p / q
/// (q an integer) written as q n / (q d - <n, p>).
DualSurface exact_dual_hull(const Planes& planes, const V3<Exact>& o) {
  using Point = ExactKernel::Point_3;
  using FT = ExactKernel::FT;
  using Q = CGAL::Quotient<ExactN>;
  const Exact q = Exact(o.x.denominator()) * Exact(o.y.denominator()) * Exact(o.z.denominator());
  const ExactN qn = integer_n(q.numerator());
  const V3<Exact> po{o.x * q, o.y * q, o.z * q};
  const V3<ExactN> p{integer_n(po.x.numerator()), integer_n(po.y.numerator()),
                     integer_n(po.z.numerator())};
  const int n = static_cast<int>(planes.size());
  std::vector<Point> points(n);
  std::map<Point, int> index_of;
  for (int i = 0; i < n; ++i) {
    const Plane& h = planes[i];
    const ExactN w = qn * h.d() - dot(h.n(), p);
    points[i] = Point(FT(Q(qn * h.n().x, w)), FT(Q(qn * h.n().y, w)), FT(Q(qn * h.n().z, w)));
    index_of.emplace(points[i], i);
  }
  CGAL::Surface_mesh<Point> hull;
  CGAL::convex_hull_3(points.begin(), points.end(), hull);
  return surface_of(hull, [&](const Point& y) { return index_of.at(y); });
}

}  // namespace

namespace {

void probe_rounding(const HVertex& v, PreciseProbe& out) {
  if (v.exact_dd) {
    out.rounded = {v.px.x.hi + v.px.x.lo, v.px.y.hi + v.px.y.lo, v.px.z.hi + v.px.z.lo};
    out.decided = {true, true, true};
    return;
  }
  if (v.doubles) {
    out.rounded = {v.X->x.to_double(), v.X->y.to_double(), v.X->z.to_double()};
    out.decided = {true, true, true};
  }
  if (!v.precise) return;
  const double inverse = 1 / v.pw.hi;
  out.decided = {round_precise(v.px.x, v.ex.x, v.pw, v.ew, inverse, out.rounded.x),
                 round_precise(v.px.y, v.ex.y, v.pw, v.ew, inverse, out.rounded.y),
                 round_precise(v.px.z, v.ex.z, v.pw, v.ew, inverse, out.rounded.z)};
}

}  // namespace

PreciseProbe probe_precise(const HalfSpaces& hs) {
  const Planes planes = planes_of(hs);
  RoundingGuard nearest(CGAL_FE_TONEAREST);
  const PrecisePlanes precise(planes);
  PreciseProbe out;
  HVertex u;
  u.planes = {0, 1, 2};
  make_precise(precise, u);
  probe_rounding(u, out);
  out.newton = u.precise && u.ew == 0;
  if (precise[0].valid() && precise[1].valid() && precise[2].valid())
    out.det = precise_det_sign(precise[0], precise[1], precise[2]);
  if (hs.size() < 4 || !u.precise || !precise[3].valid()) return out;
  out.side = precise_side(precise[3], u);
  if (hs.size() < 7) return out;
  HVertex v;
  v.planes = {4, 5, 6};
  make_precise(precise, v);
  if (v.precise) out.compare = precise_compare(precise[3], u, v);
  return out;
}

DoubleProbe probe_double(const HalfSpaces& hs) {
  const Planes planes = planes_of(hs);
  RoundingGuard guard;  // (vertex_of's intervals for planes that are not fast)
  DoubleProbe out;
  const HVertex u = vertex_of(planes, {0, 1, 2});
  out.w = w_positive(u) && u.fast ? 1 : 2;
  if (hs.size() < 4) return out;
  out.side = double_side(planes[3], u);
  if (hs.size() < 7) return out;
  out.compare = double_compare(planes[3], u, vertex_of(planes, {4, 5, 6}));
  return out;
}

PreciseProbe probe_precise_point(const V3<ExactN>& X, const ExactN& W) {
  RoundingGuard nearest(CGAL_FE_TONEAREST);
  PreciseProbe out;
  HVertex v;
  v.known = 0;
  v.X = &X;
  v.W = &W;
  const Planes none;
  make_precise(PrecisePlanes(none), v);
  probe_rounding(v, out);
  return out;
}

void set_normal_dd(HalfSpace& h, const V3<double>& p0, const V3<double>& p1, const V3<double>& p2) {
  RoundingGuard nearest(CGAL_FE_TONEAREST);
  // The edge vectors, each difference exact (two_sum's error term zero, no overflow).
  V3<double> e1, e2;
  const auto difference = [](double a, double b, double& out) {
    const DD s = two_sum(a, -b);
    out = s.hi;
    return s.lo == 0 && std::abs(s.hi) <= 0x1p900;
  };
  if (!difference(p1.x, p0.x, e1.x) || !difference(p1.y, p0.y, e1.y) ||
      !difference(p1.z, p0.z, e1.z) || !difference(p2.x, p0.x, e2.x) ||
      !difference(p2.y, p0.y, e2.y) || !difference(p2.z, p0.z, e2.z))
    return;
  // Each component is a b - c d of doubles: both products exact by two_prod (factors below
  // 2^900, each non-zero product at least 2^-900 in magnitude: no overflow, no underflow), and
  // a.hi - c.hi exact by two_sum. The rest, s.lo + (a.lo - c.lo), errs by u = 2^-53 of each
  // of its two rounded operations' results; the last two_sum is exact. So the value is within
  // u (|t| + |r|) of hi + lo, which must be within 2^-101 of |hi| (else the normal is left
  // to its exact conversion).
  const auto component = [](double a, double b, double c, double d, DD& out) {
    for (double x : {a, b, c, d})
      if (!(std::abs(x) <= 0x1p900)) return false;
    const DD p = two_prod(a, b), q = two_prod(c, d);
    const auto in_range = [](double x, double y, double product) {
      return x == 0 || y == 0 || (std::abs(product) >= 0x1p-900 && std::abs(product) <= 0x1p990);
    };
    if (!in_range(a, b, p.hi) || !in_range(c, d, q.hi)) return false;
    const DD s = two_sum(p.hi, -q.hi);
    const double t = p.lo - q.lo, r = s.lo + t;
    out = two_sum(s.hi, r);
    const double error = 0x1p-53 * (std::abs(t) + std::abs(r)) * 1.01;
    return error <= 0x1p-101 * std::abs(out.hi);
  };
  std::array<DD, 3> n;
  if (component(e1.y, e2.z, e1.z, e2.y, n[0]) && component(e1.z, e2.x, e1.x, e2.z, n[1]) &&
      component(e1.x, e2.y, e1.y, e2.x, n[2])) {
    h.normal_dd = n;
    h.has_normal_dd = true;
  }
}

V3<ExactN> exact_value(const V3<DD>& p) {
  const auto exact = [](const DD& c) { return ExactN(c.hi) + ExactN(c.lo); };
  return {exact(p.x), exact(p.y), exact(p.z)};
}

// (GCC 12 takes Mpzf's freeing of its own limbs, inlined here, for a mismatched delete: a
// false positive of -Wmismatched-new-delete, which depends on what the inliner does.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
HalfSpace make_halfspace(const V3<ExactN>& normal, const Exact& offset, int source) {
  HalfSpace h;
  h.normal() = normal;
  h.offset() = integer_n(offset.numerator());
  h.set_denominator(integer_n(offset.denominator()));
  h.source = source;
  return h;
}
#pragma GCC diagnostic pop

namespace {

/// A known point on all of the planes p[0 .. k), or -1.
int common_point(const KnownPoints& known, const int* p, int k) {
  if (known.empty()) return -1;
  for (int j = known.begin[p[0]]; j < known.begin[p[0] + 1]; ++j) {
    bool all = true;
    for (int i = 1; i < k && all; ++i) all = known.passes(p[i], known.point[j]);
    if (all) return known.point[j];
  }
  return -1;
}

/// Scratch space of triangulate_polygon, kept across the polygons of a chunk.
struct PolygonScratch {
  std::vector<std::array<int, 3>> triangle;  // corners: positions in the polygon
  std::vector<HVertex> vertex;               // each triangle's, where ready
  std::vector<char> ready;                   // whether its vertex is computed
  std::vector<std::pair<int, int>> pending;  // diagonals to test
  std::vector<V3<Interval>> cross;           // n_i x n_j of positions i, j (k i + j)
  std::vector<char> has_cross;
  std::vector<V3<double>> nd, na;  // the normals' doubles of fast planes, and their magnitudes
  std::vector<V3<double>> dual;    // their dual points about o, in plain doubles
  std::vector<signed char> diagonal_side;  // of diagonal i, j (k i + j, i < j), or 2
  std::vector<int> owner;  // 4 t + slot of the triangle t holding edge i -> j (k i + j), or -1
};

/// Flips per corner after which a polygon's triangulation stops: Lawson's flips may take
/// O(k^2) on a vertex of A of high degree, and where planes of the polygon vanish (a UV
/// sphere's pole, its facets moved by several vertices of B) they do not end; the check
/// and its repair, which can take planes off the surface, go on from there. (Giving the
/// guess up there ran the incremental hull on UV spheres from 120 x 120 facets, 20x a
/// dilation; the repair takes 8-12x to 400 x 400.)
/// (Where planes of the polygon vanish, a UV sphere's pole with its facets moved by
/// several vertices of B, they do not end: a repair could lift those planes off, but
/// from a pole of 120 planes or more it takes longer than the hull, to 8 s at 160,000
/// planes, mostly in its rounds over the waiting edges.)
constexpr int kFlipsPerCorner = 4;

/// triangulate_polygon's steps for a quadrilateral of fast planes that do not meet in a
/// known point (a UV sphere's vertex: most of its polygons), without its scratch: one
/// diagonal, (p0, p2), tested at the vertex of (p0, p2, p3) and flipped to (p1, p3) when
/// plane p1 cuts it off. The same triangles, slots, signs and vertex as the general steps.
bool triangulate_quadrilateral(const Planes& planes, const PrecisePlanes& precise,
                               const KnownPoints& known, const int* p, int base,
                               std::array<int, 3>* out, std::array<int, 3>* out_across,
                               int* out_side, VertexStore* store, int* out_slot,
                               signed char* out_far) {
  HVertex v = vertex_of(planes, {p[0], p[2], p[3]});  // (the double filter's: all fast)
  take_known(known, v);
  if (!w_positive(v) && det_sign(planes, precise, p[0], p[2], p[3]) <= 0) return false;
  const int sd = known_through(known, p[1], v) ? 0 : side(planes, precise, p[1], v);
  const auto set_far = [&](int t, signed char f0, signed char f1, signed char f2) {
    out_far[3 * t] = f0;
    out_far[3 * t + 1] = f1;
    out_far[3 * t + 2] = f2;
  };
  if (sd <= 0) {
    // (p0, p1, p2) and (p0, p2, p3), the latter's vertex kept.
    out[0] = {p[0], p[1], p[2]};
    out[1] = {p[0], p[2], p[3]};
    set_far(0, 2, 2, static_cast<signed char>(sd));
    set_far(1, static_cast<signed char>(sd), 2, 2);
    out_across[0][2] = base + 1;
    out_across[1][0] = base;
    out_side[0] = 3 * base;
    out_side[1] = 3 * base + 1;
    out_side[2] = 3 * (base + 1) + 1;
    out_side[3] = 3 * (base + 1) + 2;
    const int slot = store->add_range(1);
    (*store)[slot] = std::move(v);
    out_slot[0] = -1;
    out_slot[1] = slot;
    return true;
  }
  // Flipped: (p1, p2, p3) and (p0, p1, p3); the new diagonal's sign the opposite of the
  // test's, and neither vertex made.
  out[0] = {p[1], p[2], p[3]};
  out[1] = {p[0], p[1], p[3]};
  set_far(0, 2, 2, -1);
  set_far(1, 2, -1, 2);
  out_across[0][2] = base + 1;
  out_across[1][1] = base;
  out_side[0] = 3 * (base + 1);
  out_side[1] = 3 * base;
  out_side[2] = 3 * base + 1;
  out_side[3] = 3 * (base + 1) + 2;
  out_slot[0] = out_slot[1] = -1;
  return true;
}

/// Triangulates the polygon of planes p[0 .. k) (counter-clockwise seen from outside) so
/// that it is locally convex, as the dual hull is: Lawson flips from a fan (first in plain
/// doubles, a prediction, then exactly from the triangulation they give). The diagonal
/// (a, c) between triangles (a, c, b) and (c, a, d) is flipped to (b, d) when plane d cuts
/// off the vertex of a, c and b (side > 0, exactly; 0 is four planes through one point,
/// left as it is: the builder groups such triangles). Each flip makes the surface more
/// convex, so flips stop for dual points in convex position (nearly coplanar ones, such as
/// the moved facets around a vertex of A). Writes k - 2 triangles to `out`; false when a
/// triangle is not positively oriented, or the polygon would split and `split` is false
/// (ExpectedVertices::split). After kFlipsPerCorner k flips it stops with the triangulation
/// as it is: the diagonals it has not tested, like a triangle never tested, are left to the
/// check (and its repair).
/// When it splits the polygon, each final triangle's vertex is added to `store` (which has
/// room reserved for it: this runs on several threads) and its index written to out_slot.
/// out_far (3 per triangle) gets the check's far-plane sign of each diagonal's edge (see
/// build_verified; 2 for the polygon's own edges): the last test of each diagonal, made
/// with its final triangles, or for a diagonal a flip made, -1 (the flipped test's four
/// planes in an odd order: the opposite sign, and it was positive); 0 for planes through
/// one known point (four planes through a point).
/// The triangles are numbered from `base` on the surface: each diagonal's two triangles are
/// joined in out_across (3 per triangle; the polygon's sides are left as they are), and side
/// i of the polygon, p[i] -> p[i + 1] (cyclically), is the directed edge out_side[i] =
/// 3 t + m of the surface (triangle t, corner m to m + 1).
/// Needs a RoundingGuard.
bool triangulate_polygon(const Planes& planes, const PrecisePlanes& precise,
                         const KnownPoints& known, const V3<double>& o, const int* p, int k,
                         bool split, int base, std::array<int, 3>* out,
                         std::array<int, 3>* out_across, int* out_side, VertexStore* store,
                         int* out_slot, signed char* out_far, PolygonScratch& scratch) {
  // Planes through one known point (facets of A moved by one vertex of B): one vertex.
  if (k == 3 || common_point(known, p, k) >= 0) {
    for (int i = 1; i + 1 < k; ++i) {
      const int t = i - 1;
      out[t] = {p[0], p[i], p[i + 1]};
      // The diagonals: (p[0], p[i]) and (p[i + 1], p[0]) where they are not polygon edges.
      signed char* f = out_far + 3 * t;
      f[0] = i > 1 ? 0 : 2;
      f[1] = 2;
      f[2] = i + 2 < k ? 0 : 2;
      if (i > 1) out_across[t][0] = base + t - 1;
      if (i + 2 < k) out_across[t][2] = base + t + 1;
      out_side[i] = 3 * (base + t) + 1;
    }
    out_side[0] = 3 * base;
    out_side[k - 1] = 3 * (base + k - 3) + 2;
    return true;
  }
  if (!split) return false;
  if (k == 4 && planes[p[0]].fast && planes[p[1]].fast && planes[p[2]].fast && planes[p[3]].fast)
    return triangulate_quadrilateral(planes, precise, known, p, base, out, out_across, out_side,
                                     store, out_slot, out_far);
  auto& triangle = scratch.triangle;
  // Each triangle's vertex, computed where it is tested (ready); those go to the store at the
  // end, the others are made where the check or the repair needs them.
  auto& vertex = scratch.vertex;
  vertex.clear();
  vertex.resize(k - 2);
  auto& ready = scratch.ready;
  auto& pending = scratch.pending;
  triangle.clear();
  pending.clear();
  auto& owner = scratch.owner;
  owner.assign(static_cast<std::size_t>(k) * k, -1);
  // Triangle t's corners and the owner of each of its edges.
  const auto set_triangle = [&](int t, int x, int y, int z) {
    triangle[t] = {x, y, z};
    owner[x * k + y] = 4 * t;  // (4: shifts, no divisions, in find)
    owner[y * k + z] = 4 * t + 1;
    owner[z * k + x] = 4 * t + 2;
  };
  for (int i = 1; i + 1 < k; ++i) {
    triangle.emplace_back();
    set_triangle(i - 1, 0, i, i + 1);
    if (i > 1) pending.emplace_back(0, i);
  }
  ready.assign(triangle.size(), 0);
  // All planes fast (the usual case): the vertices are the double filter's (double_meet).
  // (Their doubles copied on the way: one pass over the scattered planes.)
  bool fast = true;
  scratch.nd.resize(k);
  scratch.na.resize(k);
  for (int i = 0; i < k; ++i) {
    const Plane& plane = planes[p[i]];
    fast = fast && plane.fast;
    scratch.nd[i] = plane.nd;
    scratch.na[i] = plane.na();
  }
  if (!fast) {
    scratch.cross.resize(static_cast<std::size_t>(k) * k);
    scratch.has_cross.assign(static_cast<std::size_t>(k) * k, 0);
  }
  scratch.diagonal_side.assign(static_cast<std::size_t>(k) * k, 2);
  const auto diagonal_side = [&](int a, int c) -> signed char& {
    return scratch.diagonal_side[a < c ? a * k + c : c * k + a];
  };
  // The cross product of the interval normals of positions i and j, computed once for
  // both orders (n_j x n_i is its exact negation: the same intervals as computed afresh).
  const auto cross_of = [&](int i, int j) -> const V3<Interval>& {
    V3<Interval>& c = scratch.cross[i * k + j];
    if (scratch.has_cross[i * k + j]) return c;
    if (scratch.has_cross[j * k + i]) {
      const V3<Interval>& r = scratch.cross[j * k + i];
      c = {-r.x, -r.y, -r.z};
    } else {
      c = cross(planes[p[i]].ni, planes[p[j]].ni);
    }
    scratch.has_cross[i * k + j] = 1;
    return c;
  };
  // (Cross products of doubles are computed afresh: a dozen operations, fewer than a
  // cache's look-ups cost; icosphere_5120 erosion, the flips' vertices 7.2M to 5.5M
  // instructions.)
  // Triangle t's vertex, as vertex_of(planes, abc) and take_known compute it.
  const auto compute_vertex = [&](int t) {
    ready[t] = 1;
    const auto [i, j, l] = triangle[t];
    // Fresh, or a flipped triangle's: drop what that one had (a `made` is freed when the
    // vertex is made exact again, or goes).
    HVertex& v = vertex[t];
    v.X = nullptr;
    v.W = nullptr;
    v.known = -1;
    v.precise = v.precise_tried = v.exact_dd = v.doubles = false;
    v.planes = {p[i], p[j], p[l]};
    const Plane &a = planes[p[i]], &b = planes[p[j]], &c = planes[p[l]];
    if (fast) {
      const auto& n = scratch.nd;
      const auto& m = scratch.na;
      double_meet(a, b, c, cross(n[j], n[l]), cross(n[l], n[i]), cross(n[i], n[j]),
                  magnitude_cross(m[j], m[l]), magnitude_cross(m[l], m[i]),
                  magnitude_cross(m[i], m[j]), v);
    } else {
      meet_of_crosses(a.ni, a.di, b.di, c.di, cross_of(j, l), cross_of(l, i), cross_of(i, j), v.Xi,
                      v.Wi);
      v.intervals = true;
      v.fast = false;
    }
    take_known(known, v);
  };
  // Triangle t's vertex (computed when first tested); false when t is not positively
  // oriented.
  const auto make_vertex = [&](int t) {
    if (ready[t]) return true;
    compute_vertex(t);
    const std::array<int, 3>& abc = vertex[t].planes;
    return w_positive(vertex[t]) || det_sign(planes, precise, abc[0], abc[1], abc[2]) > 0;
  };
  // The triangle holding the directed edge a -> c and that edge's slot in it, or -1.
  const auto find = [&](int a, int c, int& slot) {
    const int o = owner[a * k + c];
    slot = o & 3;
    return o < 0 ? -1 : o >> 2;
  };
  const auto side_of = [&](int plane, HVertex& v) {
    return known_through(known, p[plane], v) ? 0 : side(planes, precise, p[plane], v);
  };
  const auto diagonal = [&](int a, int c) {  // not a side of the polygon
    const int gap = a > c ? a - c : c - a;
    return gap != 1 && gap != k - 1;
  };
  // Flips the diagonal between t (edge a -> c, third corner b) and u (c -> a, d) to b, d.
  const auto flip = [&](int a, int b, int c, int d, int t, int u) {
    owner[a * k + c] = owner[c * k + a] = -1;
    set_triangle(t, a, d, b);
    set_triangle(u, d, c, b);
  };
  // A prediction first: the same flips on the dual points n / (d - <n, o>) in plain doubles
  // (no filter, nothing exact: any triangulation may start the exact flips below, which
  // then mostly test each diagonal once and flip none, so make no vertex that a flip drops).
  // icosphere_5120 erosion: exact flips 5678 to 0, vertices made 15914 to 10236 (as many
  // as triangles), expected_surface 12.1M to 11.1M instructions.
  // Not for a quadrilateral: its one diagonal is tested once either way, and a prediction
  // could only spare the vertex of a flip; a UV sphere's, nearly planar, are predicted no
  // better than by chance (uvsphere_1600 erosion: 0.4M more instructions with them).
  bool predicted = fast && k > 4;
  if (predicted) {
    scratch.dual.resize(k);
    for (int i = 0; i < k && predicted; ++i) {
      const double h = planes[p[i]].dd - dot(scratch.nd[i], o);
      const double r = 1 / h;
      const V3<double>& n = scratch.nd[i];
      scratch.dual[i] = {n.x * r, n.y * r, n.z * r};
      predicted = h > 0;  // (o inside; false for NaN)
    }
  }
  if (predicted) {
    const auto& q = scratch.dual;
    for (int flips = 0; !pending.empty() && flips <= kFlipsPerCorner * k;) {
      const auto [a, c] = pending.back();
      pending.pop_back();
      int i, j;
      const int t = find(a, c, i), u = find(c, a, j);
      if (t < 0 || u < 0) continue;
      const int b = triangle[t][i == 0 ? 2 : i - 1], d = triangle[u][j == 0 ? 2 : j - 1];
      // d beyond the plane of (a, c, b), counter-clockwise seen from outside.
      if (!(dot(cross(q[c] - q[a], q[b] - q[a]), q[d] - q[a]) > 0)) continue;
      ++flips;
      flip(a, b, c, d, t, u);
      for (const auto& e : {std::pair(a, d), std::pair(d, c), std::pair(c, b), std::pair(b, a)})
        if (diagonal(e.first, e.second)) pending.push_back(e);
    }
    pending.clear();
    for (const auto& x : triangle)
      for (int m = 0; m < 3; ++m) {
        const int a = x[m], c = x[m == 2 ? 0 : m + 1];
        if (a < c && diagonal(a, c)) pending.emplace_back(a, c);
      }
  }
  for (int flips = 0; !pending.empty();) {
    const auto [a, c] = pending.back();
    pending.pop_back();
    int i, j;
    const int t = find(a, c, i), u = find(c, a, j);
    if (t < 0 || u < 0) continue;  // flipped away meanwhile
    const int b = triangle[t][i == 0 ? 2 : i - 1], d = triangle[u][j == 0 ? 2 : j - 1];
    // Plane d at t's vertex, or the same sign from the other side when only u's is made:
    // plane b at the vertex of u = (c, a, d) (see build_verified's far-plane tests).
    int sd;
    if (!ready[t] && ready[u]) {
      sd = side_of(b, vertex[u]);
    } else {
      if (!make_vertex(t)) return false;
      sd = side_of(d, vertex[t]);
    }
    if (sd <= 0) {
      diagonal_side(a, c) = static_cast<signed char>(sd);
      continue;
    }
    if (++flips > kFlipsPerCorner * k) break;
    flip(a, b, c, d, t, u);
    ready[t] = ready[u] = 0;
    diagonal_side(b, d) = -1;
    // The quadrilateral's sides have a new triangle each: tested again where diagonals.
    for (const auto& e : {std::pair(a, d), std::pair(d, c), std::pair(c, b), std::pair(b, a)})
      if (diagonal(e.first, e.second)) {
        diagonal_side(e.first, e.second) = 2;
        pending.push_back(e);
      }
  }
  // The tested triangles' vertices, for the check. (Each untested one was made here too, and
  // stored: a UV sphere of 512 x 512 facets, 54 MB more of fresh vertex records, most of
  // which the check's far-plane tests never read, deciding on the dual points. Its
  // orientation is left to the check.)
  int tested = 0;
  for (std::size_t t = 0; t < triangle.size(); ++t) {
    out[t] = {p[triangle[t][0]], p[triangle[t][1]], p[triangle[t][2]]};
    for (int m = 0; m < 3; ++m) {
      const int x = triangle[t][m], y = triangle[t][m == 2 ? 0 : m + 1];
      out_far[3 * t + m] = diagonal_side(x, y);  // (2 for the polygon's sides: never set)
      if (diagonal(x, y))
        out_across[t][m] = base + (owner[y * k + x] >> 2);
      else
        out_side[x] = 3 * (base + static_cast<int>(t)) + m;  // (y is x + 1: a side)
    }
    tested += ready[t];
  }
  int next = tested > 0 ? store->add_range(tested) : 0;
  for (std::size_t t = 0; t < triangle.size(); ++t) {
    out_slot[t] = ready[t] ? next : -1;
    if (ready[t]) (*store)[next++] = std::move(vertex[t]);
  }
  return true;
}

/// The signs of a guess of A's own fans that A's convexity makes certain (see
/// ExpectedVertices::fans_of_operand and moved_by, where the arguments are): every triangle
/// is positively oriented (s.oriented), and where moved_by is given, the far plane across a
/// side of a polygon whose planes one vertex b of B moved, to a triangle of another such
/// polygon of the same b, is strictly above its vertex (far side -1). `first`: each
/// polygon's first triangle. With options.verify_certified each is also tested.
void certify(const Planes& planes, const PrecisePlanes& precise, const KnownPoints& known,
             const ExpectedVertices& expected, const std::vector<int>& first, DualSurface& s,
             const IntersectOptions& options) {
  const int nv = static_cast<int>(first.size()) - 1, nt = static_cast<int>(s.corner.size());
  const std::vector<int>& moved_by = expected.moved_by;
  // Per triangle: the one vertex of B moving its polygon, or -1 (none without moved_by).
  std::vector<int> by(moved_by.empty() ? 0 : nt, -1);
  if (!by.empty())
    parallel_chunks(nv, 256, [&](int begin, int end) {
      for (int v = begin; v < end; ++v) {
        const int b = moved_by[expected.facets[expected.begin[v]]];
        bool one = true;
        for (int j = expected.begin[v] + 1; j < expected.begin[v + 1] && one; ++j)
          one = moved_by[expected.facets[j]] == b;
        if (one) std::fill(by.begin() + first[v], by.begin() + first[v + 1], b);
      }
    });
  s.oriented = true;
  std::atomic<long> certified = nt, wrong = 0;
  parallel_chunks(by.empty() && !options.verify_certified ? 0 : nv, 256, [&](int begin, int end) {
    RoundingGuard guard;
    long made = 0, differ = 0;
    for (int v = begin; v < end; ++v) {
      for (int t = first[v]; t < first[v + 1]; ++t) {
        const auto& c = s.corner[t];
        if (options.verify_certified && det_sign(planes, precise, c[0], c[1], c[2]) <= 0) ++differ;
        if (by.empty() || by[t] < 0) continue;
        for (int k = 0; k < 3; ++k) {
          // Only a side of the polygon, untested (far side 2), with the same b across.
          const int u = s.across[t][k];
          if (s.far_side[3 * t + k] != 2 || (u >= first[v] && u < first[v + 1]) || by[u] != by[t])
            continue;
          s.far_side[3 * t + k] = -1;
          ++made;
          if (options.verify_certified) {
            const int far = s.far_corner(t, k);
            HVertex x = independent_vertex_of(planes, c, known);
            if (far < 0 || known_through(known, far, x) || side(planes, precise, far, x) >= 0)
              ++differ;
          }
        }
      }
    }
    certified += made;
    wrong += differ;
  });
  if (options.counts) {
    options.counts->certified += certified;
    options.counts->certified_wrong += wrong;
  }
}

/// The dual surface of an expected result: each expected vertex's polygon of planes
/// triangulated (triangulate_polygon, in parallel; counter-clockwise seen from outside, as
/// the dual hull's), joined across shared edges. Empty when a polygon cannot be
/// triangulated or the triangles do not close up into a surface.
DualSurface expected_surface(const Planes& planes, const PrecisePlanes& precise,
                             const KnownPoints& known, const ExpectedVertices& expected,
                             const V3<double>& o, const IntersectOptions& options) {
  DualSurface s;
  const int nv = static_cast<int>(expected.begin.size()) - 1;
  std::vector<int> first(nv + 1, 0);  // each polygon's first triangle
  for (int v = 0; v < nv; ++v) {
    const int k = expected.begin[v + 1] - expected.begin[v];
    if (k < 3) return {};
    first[v + 1] = first[v] + k - 2;
  }
  const int nt = first[nv];
  s.corner.resize(nt);
  if (expected.split) {  // otherwise no polygon splits, and none has vertices to keep
    s.slot.assign(nt, -1);
    s.vertices.reserve(nt);  // (room for all: made on several threads)
  }
  s.far_side.resize(3 * static_cast<std::size_t>(nt));
  // Each polygon joins its own triangles across its diagonals, and names the surface's
  // directed edge 3 t + k (corner k to k + 1 of triangle t) on each of its sides: side i of
  // polygon v, facets[begin[v] + i] -> facets[begin[v] + i + 1], is side[begin[v] + i].
  s.across.assign(nt, {-1, -1, -1});
  const std::size_t sides = expected.facets.size();
  const auto side = std::make_unique_for_overwrite<int[]>(sides);
  std::atomic<bool> ok = true;
  const auto triangulate = [&](int v, PolygonScratch& scratch) {
    const int b = expected.begin[v];
    if (!triangulate_polygon(planes, precise, known, o, &expected.facets[b],
                             expected.begin[v + 1] - b, expected.split, first[v],
                             &s.corner[first[v]], &s.across[first[v]], &side[b], &s.vertices,
                             expected.split ? &s.slot[first[v]] : nullptr,
                             &s.far_side[3 * static_cast<std::size_t>(first[v])], scratch))
      ok = false;
  };
  parallel_chunks(ok ? nv : 0, 64, [&](int begin, int end) {
    RoundingGuard guard;
    PolygonScratch scratch;
    for (int v = begin; v < end && ok; ++v) triangulate(v, scratch);
  });
  if (!ok) return {};
  const auto next_corner = [](int k) { return k == 2 ? 0 : k + 1; };
  // The sides' planes: a -> b of directed edge e (corner e % 3 of triangle e / 3).
  const auto tail = [&](int e) { return s.corner[e / 3][e % 3]; };
  const auto head = [&](int e) { return s.corner[e / 3][next_corner(e % 3)]; };
  // Joins directed edges e and r (r is e's reverse). (Atomic: two searches may reach one
  // side where the surface is not closed.)
  const auto join = [&](int e, int r) {
    std::atomic_ref<int>(s.across[e / 3][e % 3]).store(r / 3, std::memory_order_relaxed);
    std::atomic_ref<int>(s.across[r / 3][r % 3]).store(e / 3, std::memory_order_relaxed);
  };
  if (expected.edge.size() == sides) {
    // Each side is an edge of the operand (ExpectedVertices::edge), on two sides reversed:
    // whichever of the two comes second joins them. (Checked: the reverse planes, and below,
    // every edge joined.)
    std::vector<int> seen(expected.edges, -1);
    parallel_chunks(static_cast<int>(sides), 2048, [&](int begin, int end) {
      for (int i = begin; i < end && ok; ++i) {
        const int e = expected.edge[i];
        if (e < 0 || e >= expected.edges) {
          ok = false;
          break;
        }
        const int r = std::atomic_ref<int>(seen[e]).exchange(side[i], std::memory_order_relaxed);
        if (r < 0) continue;
        if (tail(r) != head(side[i]) || head(r) != tail(side[i])) {
          ok = false;
          break;
        }
        join(side[i], r);
      }
    });
  } else {
    // Sides listed by their first plane (a counting sort), each with its second plane: each
    // side's reverse is the one side back among the few leaving its second plane. Only
    // sides a -> b with a < b search (the search's variable length cost a mispredicted exit
    // each); each joins its reverse too. Every side has exactly one reverse (a closed
    // surface, each edge used once) iff each search finds exactly one, every side b -> a
    // with b > a is reached, and there are as many of those as of the searching ones (then
    // the searches pair them one to one).
    // (Each side's head beside it: a search reads one array. Not zeroed: all are written.)
    struct OutEdge {
      int head, edge;
    };
    std::vector<int> out_begin(planes.size() + 1, 0);
    const auto out = std::make_unique_for_overwrite<OutEdge[]>(sides);
    std::ptrdiff_t balance = 0;  // sides a -> b with a < b, less those with a > b
    for (std::size_t i = 0; i < sides; ++i) {
      const int a = tail(side[i]), b = head(side[i]);
      ++out_begin[a + 1];
      balance += a < b ? 1 : -1;
    }
    if (balance != 0) return {};
    std::partial_sum(out_begin.begin(), out_begin.end(), out_begin.begin());
    {
      std::vector<int> next(out_begin.begin(), out_begin.end() - 1);
      for (std::size_t i = 0; i < sides; ++i) out[next[tail(side[i])]++] = {head(side[i]), side[i]};
    }
    parallel_chunks(static_cast<int>(sides), 1024, [&](int begin, int end) {
      for (int i = begin; i < end && ok; ++i) {
        const int a = tail(side[i]), b = head(side[i]);
        if (a > b) continue;  // joined by its reverse's search
        int back = -1, found = 0;
        for (int j = out_begin[b]; j < out_begin[b + 1]; ++j)
          if (out[j].head == a) back = out[j].edge, ++found;
        if (found != 1) {
          ok = false;  // an open surface, or an edge used twice
          break;
        }
        join(side[i], back);
      }
    });
  }
  if (!ok) return {};
  // Closed: every edge joined; and no triangle has a plane twice (a polygon that does).
  for (int t = 0; t < nt; ++t) {
    const auto &u = s.across[t], &c = s.corner[t];
    if (u[0] < 0 || u[1] < 0 || u[2] < 0 || c[0] == c[1] || c[1] == c[2] || c[2] == c[0]) return {};
  }
  if (expected.fans_of_operand && options.certify)
    certify(planes, precise, known, expected, first, s, options);
  return s;
}

}  // namespace

MaybePolytope intersect_halfspaces(const HalfSpaces& hs, const V3<double>& hint,
                                   const IntersectOptions& options, const KnownPoints& known,
                                   const ExpectedVertices& expected,
                                   std::shared_ptr<const void> owner) {
  MaybePolytope out;
  // (The guess's dual points made with the planes, about the hint: usually the centre.)
  const bool guess_filter =
      options.incremental && options.guess && !expected.empty() && options.dual_filter;
  DualPoints dual;
  const Planes planes = planes_of(hs, &hint, guess_filter ? &dual : nullptr);
  V3<Exact> o = to_exact(hint);
  V3<double> o_double = hint;
  if (!strictly_inside(planes, hint)) {
    dual.clear();
    const CentreResult c = exact_centre(hs);
    if (c.t < 0) {
      out.reason = EmptyReason::empty;
      out.message = "the structuring element fits nowhere inside the mesh: the erosion is empty";
      return out;
    }
    if (c.t == 0) {
      out.reason = EmptyReason::flat;
      out.message =
          "the structuring element fits only on a plane, a segment or a point: the erosion has no "
          "interior";
      return out;
    }
    o = c.x;
    o_double = {round_to_nearest(o.x), round_to_nearest(o.y), round_to_nearest(o.z)};
  }
  // The verification does not depend on o: any exact interior point (there is one) makes
  // the duality argument hold, so the rounded o only has to centre the virtual planes.
  const PrecisePlanes precise(planes);
  if (options.incremental && options.guess && !expected.empty()) {
    bool repaired = false;
    DualSurface guess = expected_surface(planes, precise, known, expected, o_double, options);
    if (options.dual_filter && !guess.corner.empty())
      guess.dual = std::make_shared<const DualPoints>(dual.empty() ? dual_points(planes, o_double)
                                                                   : std::move(dual));
    if (auto built = build_verified(hs, planes, precise, known, std::move(guess), options, owner,
                                    &repaired)) {
      built->route = repaired ? HullRoute::repaired : HullRoute::expected;
      return std::move(*built);
    }
  }
  if (options.incremental) {
    double reach = first_reach(planes, o_double);
    for (int attempt = 0; attempt < kReachAttempts; ++attempt, reach = std::ldexp(reach, 20)) {
      DualSurface s;
      const auto outcome = IncrementalHull(planes, precise, known, o_double, reach).run(s);
      if (outcome == IncrementalHull::Outcome::too_small) continue;
      if (outcome == IncrementalHull::Outcome::hull) {
        if (auto built = build_verified(hs, planes, precise, known, std::move(s), options, owner)) {
          built->route = HullRoute::incremental;
          return std::move(*built);
        }
      }
      break;
    }
  }
  auto built =
      build_verified(hs, planes, precise, known, exact_dual_hull(planes, o), options, owner);
  if (!built) throw error("internal error: the exact dual hull of an erosion failed its own check");
  built->route = HullRoute::exact;
  return std::move(*built);
}

bool round_precise_sum(const DD& X, double error, const DD& W, double w_error, double b,
                       double& out) {
  // X / W + b = (X + b W) / W. In this range the double-double product and sum neither
  // overflow nor lose their splits (below 2^995); underflow is covered by the absolute term.
  if (!(W.hi >= 0x1p-300 && W.hi <= 0x1p300) || !(std::abs(b) <= 0x1p600) ||
      !(std::abs(X.hi) <= 0x1p900))
    return false;
  const DD sum = X + DD{b, 0} * W;
  // The numerator's error: X's, W's times |b|, and the product and the sum, each within
  // 4 u^2 of the magnitude of its operands (|b| |W|, then |X| + |b W|), taken as 16 u^2.
  const double magnitude = std::abs(X.hi) + std::abs(b) * W.hi;
  const double bound = (error + std::abs(b) * w_error + 16 * kU2 * magnitude) * 1.01 + 0x1p-1000;
  return round_precise(sum, bound, W, w_error, 1 / W.hi, out);
}

}  // namespace morph::detail
