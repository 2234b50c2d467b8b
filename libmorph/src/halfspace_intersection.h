// Private: erosion of a convex polytope by a convex element, as an exact intersection of
// half-spaces (each facet plane of A moved inwards by B's support value along its
// normal), and the underlying exact half-space intersection.
#pragma once

#include <morph/morphology.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <new>
#include <optional>
#include <string>

#include "huge_pages.h"
#include "polytope.h"
#include "run_once.h"

namespace morph::detail {

struct SumFacets;  // fims.h

/// An erosion's exact normal and offset as the fixed-point words they come from
/// (wide_exact.h's small frame): normal 2^normal_exp n, offset 2^offset_exp d, for n below
/// 2^126 per component and d a 192-bit two's complement integer, least significant word first.
/// Most of an intersection's exact planes are never read (the filters decide on the
/// double-double copies): these become Mpzf on first need (HalfSpace::make_exact).
/// Set only with HalfSpace::lazy (left uninitialised otherwise: not read, not copied).
struct ExactWords {
  std::array<__int128, 3> n;
  std::array<std::uint64_t, 3> d;
  int normal_exp;
  int offset_exp;
};

/// A once-flag that a copy of its owner copies (copied only while no thread sets it).
struct OnceFlag {
  std::atomic<unsigned char> state{once_state::kNone};
  OnceFlag() = default;
  OnceFlag(const OnceFlag& o) : state(o.state.load(std::memory_order_acquire)) {}
  OnceFlag& operator=(const OnceFlag& o) {
    state.store(o.state.load(std::memory_order_acquire), std::memory_order_release);
    return *this;
  }
};

/// A closed half-space { x : <normal, x> <= offset / denominator }, exact. Dyadic offsets
/// (polytopes with double or dyadic points) have denominator 1; a rational offset p/q is
/// stored as offset p, denominator q (not necessarily reduced). `source` and `element` are carried
/// to the facets of the result for their labels.
/// The exact values (five Mpzf, 440 bytes) are allocated only when set or made: an erosion's
/// thousands of lazy half-spaces, most never read, then cost neither their construction nor
/// their destruction, nor the memory (a half-space is 176 bytes; with the values inline it
/// was 624, and an erosion of 327,680 facets spent 6% of its time faulting their pages in).
struct HalfSpace {
  int source = -1;             // erosion: the facet of A (its label)
  int element = -1;            // erosion: the vertex of B that moved it inwards (its label)
  bool has_normal_dd = false;  // normal_dd is set
  bool has_offset_dd = false;  // offset_dd is set
  // Lazy exact values (an erosion's fixed-point planes, which then have both double-double
  // copies and denominator 1): normal and offset are made from `words` on first read, by
  // whichever thread reads first (the values do not depend on it, so neither does any
  // decision).
  bool lazy = false;
  mutable OnceFlag made;

 private:
  struct Values;
  bool unit_denominator_ = true;
  // Set once the values are allocated (a lazy half-space's in set_exact_from_words, under
  // `made`; otherwise by the thread that builds the half-space).
  mutable Values* values_ = nullptr;

 public:
  // The members above are all a new half-space initialises (one cache line: an erosion
  // makes thousands, on one thread); the copies and words below are read and copied only
  // where their flags say they are set.
  // Optional (set_normal_dd): the normal's components in double-double, each within 2^-101 of
  // its |hi|, |lo| at most half the gap to hi's neighbour on lo's side (round-to-nearest), so
  // the precise stage and the filters' enclosures need not convert them from the normal.
  std::array<DD, 3> normal_dd;
  // Optional: the offset in double-double within 2^-101 of |hi|, |lo| at most half the gap
  // to hi's neighbour on lo's side (hi rounded to nearest), for a denominator 1: the
  // filters' enclosure (hi's neighbours) and the precise stage's copy of the offset without
  // converting the Mpzf (an erosion makes it from the same fixed-point words).
  DD offset_dd;
  ExactWords words;  // when lazy

  // User-provided, so that a vector's value-initialisation does not zero the whole record
  // (the storage and the unset copies) before running it.
  HalfSpace() {}
  HalfSpace(const HalfSpace& o) { *this = o; }
  HalfSpace& operator=(const HalfSpace& o) {
    if (this == &o) return *this;
    source = o.source;
    element = o.element;
    has_normal_dd = o.has_normal_dd;
    has_offset_dd = o.has_offset_dd;
    lazy = o.lazy;
    made = o.made;
    if (has_normal_dd) normal_dd = o.normal_dd;
    if (has_offset_dd) offset_dd = o.offset_dd;
    if (lazy) words = o.words;
    if (o.values_)
      values() = *o.values_;
    else
      destroy();
    unit_denominator_ = o.unit_denominator_;
    return *this;
  }
  ~HalfSpace() { destroy(); }

  /// The exact values to set (constructed here, zero, on first use; not for a lazy
  /// half-space, and not while other threads read it).
  V3<ExactN>& normal() { return values().normal; }
  ExactN& offset() { return values().offset; }
  void set_denominator(const ExactN& q) {
    values().denominator = q;
    unit_denominator_ = q == 1;
  }
  /// Whether the denominator is 1 (without reading an Mpzf).
  bool unit_denominator() const { return unit_denominator_; }
  const ExactN& denominator() const { return unit_denominator_ ? one() : values_->denominator; }

  /// Makes normal and offset from `words` when lazy, once (any thread).
  void make_exact() const {
    if (lazy && made.state.load(std::memory_order_acquire) != once_state::kDone)
      run_once(made.state, [this] { set_exact_from_words(*this); });
  }
  const V3<ExactN>& exact_normal() const {
    make_exact();
    return values_ ? values_->normal : zero().normal;
  }
  const ExactN& exact_offset() const {
    make_exact();
    return values_ ? values_->offset : zero().offset;
  }
  /// Whether the exact values are constructed (set, or made from the words).
  bool has_exact_values() const { return values_ != nullptr; }
  /// (erosion.cpp: the words made Mpzf into normal and offset, zero before.)
  static void set_exact_from_words(const HalfSpace& h);

 private:
  struct Values {
    V3<ExactN> normal;
    ExactN offset;
    ExactN denominator = ExactN(1);
  };
  static const ExactN& one() {
    static const ExactN value(1);
    return value;
  }
  static const Values& zero() {
    static const Values value;
    return value;
  }
  /// The values, constructed (zero) on first use.
  Values& values() const {
    if (!values_) values_ = new Values;
    return *values_;
  }
  void destroy() {
    delete values_;
    values_ = nullptr;
    unit_denominator_ = true;
  }
};

/// The half-spaces of an intersection, one per facet of A: tens of megabytes made afresh for
/// each operation (huge_pages.h).
using HalfSpaces = std::vector<HalfSpace, HugePageAllocator<HalfSpace>>;

/// Sets h.normal_dd from h.normal = (p1 - p0) x (p2 - p0) for a triangle of double points
/// (its Newell normal), when the differences are exact in doubles and the products and the
/// bound allow; leaves h unchanged otherwise.
void set_normal_dd(HalfSpace& h, const V3<double>& p0, const V3<double>& p1, const V3<double>& p2);

/// The half-space <normal, x> <= offset for any rational offset.
HalfSpace make_halfspace(const V3<ExactN>& normal, const Exact& offset, int source);

/// Which hull gave an intersection (for tests and profiling).
enum class HullRoute : unsigned char {
  none,         // empty or flat: no hull
  incremental,  // the exact incremental hull on the planes, checked exactly
  exact,        // CGAL's hull of the exact dual points (its check failed, or it was not tried)
  expected,     // the caller's expected result (ExpectedVertices), checked exactly
  repaired,     // that result with edges flipped where it was wrong, checked exactly
};

/// An intersection as it is written out: its vertices rounded to nearest (from their exact
/// values), and facet cycles counter-clockwise about the outward normal. The same
/// numbering as the polytope's, when there is one.
struct RoundedPolytope {
  std::vector<V3<double>> points;
  std::vector<int> face_begin;     // size F + 1
  std::vector<int> corner_vertex;  // corner k of facet f: corner_vertex[face_begin[f] + k]
  std::vector<int> face_source;    // the `source` of each facet's half-space
  std::vector<int> face_element;   // the `element` of each facet's half-space
};

/// A polytope, or why there is none.
struct MaybePolytope {
  std::optional<Polytope> polytope;  // exact, when IntersectOptions::polytope
  RoundedPolytope rounded;           // whenever the intersection is a solid
  EmptyReason reason = EmptyReason::none;
  std::string message;
  HullRoute route = HullRoute::none;
};

/// What the repair of a guess did (IntersectOptions::counts), for tests: deterministic counts
/// where times are not.
struct RepairCounts {
  long flips = 0;
  long removals = 0;
  long fan_removals = 0;  // of those, planes of more than three neighbours (see remove_beneath)
  long lifts = 0;
  long insertions = 0;    // planes put back into a convex surface (lifted, or cutting it)
  long cuts = 0;          // of those, the ones that cut it (the others stay off)
  long insert_steps = 0;  // the insertions' walks to their normals' cones, in triangles
  long check_planes = 0;  // planes off a candidate the check tested
  long check_steps = 0;   // their walks, in triangles
  // The repair's orientation and side tests decided by the planes' dual points (a filter
  // on 32 bytes a plane), and those left to the planes' own filters and exact values.
  long dual_decided = 0;
  long dual_undecided = 0;
  // A guess's signs taken without a test (ExpectedVertices::fans_of_operand, moved_by):
  // triangle orientations and far-plane signs. With IntersectOptions::verify_certified, the
  // signs taken, and planes a repair removed (3-1 flips, fans; not walked to), that the tests
  // then made found otherwise (none, or the argument is wrong).
  long certified = 0;
  long certified_wrong = 0;
  // Repairs run first in regions (IntersectOptions::repair_regions_from): the regions, and
  // the edges they left to the whole surface's pass (across their borders, or stuck there).
  long regions = 0;
  long handed_over = 0;

  RepairCounts& operator+=(const RepairCounts& o) {
    flips += o.flips;
    removals += o.removals;
    fan_removals += o.fan_removals;
    lifts += o.lifts;
    insertions += o.insertions;
    cuts += o.cuts;
    insert_steps += o.insert_steps;
    check_planes += o.check_planes;
    check_steps += o.check_steps;
    dual_decided += o.dual_decided;
    dual_undecided += o.dual_undecided;
    certified += o.certified;
    certified_wrong += o.certified_wrong;
    regions += o.regions;
    handed_over += o.handed_over;
    return *this;
  }
};

/// Options of intersect_halfspaces.
struct IntersectOptions {
  bool incremental = true;  // false: go straight to the exact hull (tests compare the routes)
  bool polytope = true;     // false: only `rounded` (a final result: no rationals, no Polytope)
  bool guess = true;        // false: ignore ExpectedVertices (tests compare the routes)
  // true: the polytope's exact points are all computed up front and it has no precise points
  // (its sums are then rounded exactly; tests compare the routes). false: on demand.
  bool eager_exact = false;
  // true: the polytope is built straight from the verified facet cycles (verified_polytope).
  // false: through make_polytope's general build, merge pass and checks (tests compare).
  bool direct_polytope = true;
  // Not null: the repairs and checks of this intersection add what they did here (tests).
  RepairCounts* counts = nullptr;
  // false: the checks and repairs test the planes without their dual points' filter (tests
  // compare: the same decisions either way).
  bool dual_filter = true;
  // false: the guess's signs that ExpectedVertices makes certain are tested like
  // any other (tests compare). verify_certified: they are skipped, and also tested, each
  // different sign counted (RepairCounts::certified_wrong; tests); so are the planes a
  // repair removed (3-1 flips, fans: always certain, not walked to: DualSurface::inside).
  bool certify = true;
  bool verify_certified = false;
  // A guess's repair runs first in six regions, in parallel, when it has at least this many
  // triangles and the arena more than one thread (0: never; tests make it small to cover
  // the regions on small inputs). The result is the same polytope either way (its vertices
  // may come from other triples of planes), whatever the number of threads; the files
  // written are byte-identical. (On one thread the regions cost 1-8% more than one pass.)
  int repair_regions_from = 16384;
  bool repair_regions_on_one_thread = false;  // tests: the regions on one thread too
  // A reflex edge that cannot flip (the flip would fold a triangle) has an end strictly
  // beneath the triangle of the other three planes: the repair takes it off at once,
  // whatever its number of neighbours. false: only an end of three neighbours is, the others
  // wait, and stuck edges lift planes to insert again later (the repair up to session 26;
  // tests keep that path covered). The result is the same polytope either way.
  bool remove_beneath = true;
};

/// The exact value hi + lo of each coordinate.
V3<ExactN> exact_value(const V3<DD>& p);

/// Points known to lie exactly on some of the half-spaces' planes: an erosion knows them
/// combinatorially (the facets of A around a vertex v moved by the same vertex b of B all
/// pass through v - b). Point k is X[k] / W[k] (W[k] > 0, enclosed by Xi[k] / Wi[k]); the
/// plane of half-space i passes through points point[begin[i]] .. point[begin[i + 1] - 1].
/// A vertex of the intersection whose three planes share a known point is that point (no
/// exact construction), and a plane through it tests zero without arithmetic. Empty: none.
/// The exact values come in one of two forms: X and W (Mpzf), or, when `dd` is not empty,
/// dd[k] with W = 1, each coordinate exactly hi + lo (an erosion's differences v - b of
/// double points: 48 bytes a point where four Mpzf took over 300, most of them never read;
/// an erosion of 327,680 facets spent more on making and touching those than on its guess).
struct KnownPoints {
  std::vector<V3<ExactN>> X;
  std::vector<ExactN> W;
  std::vector<V3<DD>> dd;
  std::vector<V3<Interval>> Xi;
  std::vector<Interval> Wi;
  std::vector<int> begin;  // size n + 1 for n half-spaces, or empty
  std::vector<int> point;
  bool empty() const { return begin.empty(); }
  int size() const { return static_cast<int>(Xi.size()); }
  /// Point k's exact homogeneous coordinates, in either form.
  V3<ExactN> exact_X(int k) const { return dd.empty() ? X[k] : exact_value(dd[k]); }
  ExactN exact_W(int k) const { return dd.empty() ? W[k] : ExactN(1); }
  /// Whether half-space i's plane is known to pass through point k.
  bool passes(int i, int k) const {
    for (int j = begin[i]; j < begin[i + 1]; ++j)
      if (point[j] == k) return true;
    return false;
  }
  /// A point known to lie on the planes of half-spaces a, b and c, or -1.
  int common(int a, int b, int c) const {
    for (int j = begin[a]; j < begin[a + 1]; ++j)
      if (passes(b, point[j]) && passes(c, point[j])) return point[j];
    return -1;
  }
};

/// What the intersection is expected to look like, when the caller knows: polygons of
/// half-spaces, each the facets around a vertex of a polytope the result resembles
/// (counter-clockwise seen from outside, facets[begin[v]] ..): a closing gives A back, an
/// erosion is A with its facets moved in. The planes of a polygon may meet in several
/// vertices (an erosion's facets around a vertex of A moved by different vertices of B):
/// each polygon is triangulated to be locally convex, in parallel. Only a guess: it is
/// checked exactly, as any candidate; where it is wrong (a facet that vanishes, an edge that
/// collapses) it is repaired by flips and checked again, and the hull is computed when that
/// fails. Empty: none.
struct ExpectedVertices {
  std::vector<int> begin;  // size V + 1, or empty
  std::vector<int> facets;
  // false: each polygon is expected to be one vertex of the result, its planes through one
  // known point (a closing's A, its facets exactly planar); a polygon that is not gives the
  // guess up at once, and the check computes no triangle's vertex to keep (no repair).
  // true: polygons split as their planes meet, and the check's repair takes off planes
  // that vanish and puts in planes the guess left out that cut it (a closing of an A whose
  // facets are only nearly planar).
  bool split = true;
  // Set by erode_polytope: the polygons are the vertex fans of the eroded polytope A itself
  // (polygon v: the facets around A's vertex v), half-space f its facet f, whose normal is
  // A's facet normal (times a positive factor). Every triangle of a polygon is then
  // positively oriented, certain and not tested: its normals are three of a strictly convex
  // spherical polygon (A's Gauss map at v) in its counter-clockwise order.
  bool fans_of_operand = false;
  // Empty, or per half-space the vertex of B that moved it, set by the erosion when every
  // facet of A is a triangle whose corners lie exactly on its plane (so every edge of the
  // canonical A is exactly strictly convex) and the polygons are A's fans. Then a polygon
  // whose planes one vertex b moved is A's vertex v moved: its triangles' vertex is v - b
  // exactly, and across an edge of A to another such polygon of the same b the far plane lies
  // strictly above that vertex (A's vertex v strictly below every facet not at v): certain,
  // not tested.
  std::vector<int> moved_by;
  // Empty, or per slot of `facets` the operand's edge between that slot's facet and the
  // next (Polytope::fan_edge), each of the `edges` edges in exactly two slots, once each
  // way round (as in a polytope's fans): the guess then joins its polygons by edge, with no
  // search for each side's reverse.
  std::vector<int> edge;
  int edges = 0;
  bool empty() const { return begin.empty(); }
};

/// The intersection of bounded half-spaces (their normals must positively span space).
/// `hint` is a point that is often strictly inside (checked exactly; an exact linear
/// program finds one otherwise). Empty or flat intersections are reported, not thrown.
/// The result is exact and canonical (numbered by the half-spaces through each vertex),
/// whichever route computed it. Expected O(n log n) for n half-spaces (exact arithmetic
/// only where interval filters cannot decide).
/// `known`: points known to lie on the planes; `expected`: a guess of the result (both
/// optional: the result is the same, only faster). `owner`, when given, owns `halfspaces`
/// and `known` (unchanged while it lives): the polytope's lazy exact points then keep it
/// and read their exact planes and known points there; otherwise they copy what they need.
MaybePolytope intersect_halfspaces(const HalfSpaces& halfspaces, const V3<double>& hint,
                                   const IntersectOptions& options = {},
                                   const KnownPoints& known = {},
                                   const ExpectedVertices& expected = {},
                                   std::shared_ptr<const void> owner = nullptr);

/// For tests: the precise (double-double) stage of the intersection's vertices alone.
/// `rounded` holds the coordinates of a vertex rounded to nearest where that stage decides
/// (`decided`; elsewhere the exact rounding is left to do); `side` and `compare` are signs
/// it decides, or 2 where it leaves them to exact arithmetic.
struct PreciseProbe {
  V3<double> rounded{0, 0, 0};
  std::array<bool, 3> decided{false, false, false};
  int side = 2;         // of <n, u> - d for hs[3]
  int compare = 2;      // of <n, u> - <n, v> for hs[3]'s normal n
  int det = 2;          // of det(n_0, n_1, n_2)
  bool newton = false;  // u's precise coordinates are X / W itself (newton_meet)
};
/// u is the meet of the planes of hs[0], hs[1] and hs[2] (det of their normals > 0 for all
/// but `det`); v, when hs has 7 half-spaces, that of hs[4], hs[5] and hs[6].
PreciseProbe probe_precise(const HalfSpaces& hs);
/// The rounding of a point known exactly, X / W (W > 0), as an erosion's known points.
PreciseProbe probe_precise_point(const V3<ExactN>& X, const ExactN& W);

/// For tests: the double filter alone (the first stage of the vertices' tests, before
/// intervals), on hs as probe_precise's: 1 where it finds W = det(n_0, n_1, n_2) > 0 (`w`),
/// and the signs of <n, X> - d W for hs[3] (`side`) and <n, Xu> Wv - <n, Xv> Wu (`compare`)
/// where it decides them; 2 elsewhere (also where a plane is out of its range).
struct DoubleProbe {
  int w = 2;
  int side = 2;
  int compare = 2;
};
DoubleProbe probe_double(const HalfSpaces& hs);

/// One coordinate of X / W + b rounded to nearest (ties to even), for X / W a vertex given
/// by its precise coordinates (a PrecisePoint's X.x, error.x, W, w_error, or y, or z) and b a
/// double, when the precise stage decides; false when the sum lies too close to a rounding
/// midpoint (or out of range): round_quotient on exact coordinates decides then. Needs
/// round-to-nearest.
bool round_precise_sum(const DD& X, double error, const DD& W, double w_error, double b,
                       double& out);

/// A (-) B = intersection over facets f of A of { x : <N_f, x> <= h_A(N_f) - h_B(N_f) }.
/// The facets of A through a vertex v moved by a vertex b of B (one that attains h_B(N_f))
/// all pass through v - b: these incidences are passed on as KnownPoints.
/// A's vertices are the expected result (ExpectedVertices): when B is small against A's
/// features no facet vanishes, and the hull is not needed. The guess's triangles take their
/// orientation from A's Gauss map turning strictly at every vertex, as every polytope here
/// does (an operand's is checked; an exact one's facets have no straight corners).
MaybePolytope erode_polytope(const Polytope& A, const Polytope& B,
                             const IntersectOptions& options = {});

/// (A (+) B) (-) B for S = sum_polytope(A, B, fims_facets(A, B)): a closing. For convex A
/// this is A, whose facets are S's translated facets (fims.h: S's facets of A's facets
/// come first, in A's order); that guess is checked exactly (ExpectedVertices) and the
/// intersection is computed as any erosion when it fails (A's facets only nearly planar).
/// A vertex A_i + B_j of S moved by B_j is A_i: one known point for all the vertices of S
/// over A_i (S.sum_pairs).
MaybePolytope erode_sum(const Polytope& S, const Polytope& A, const Polytope& B,
                        const IntersectOptions& options = {});

/// The closing (A (+) B) (-) B of operands A and B, and the origin of each facet of A (+) B
/// that a facet of the result can lie on: facet f of `eroded` lies on the facet of
/// A (+) B labelled origins[eroded.rounded.face_source[f]] (for a convex A, the translated
/// facets of A's facets). Three routes, in this order:
/// - closing_input, when A's and B's facets are exactly planar (the usual case);
/// - otherwise erode_sum's input on the exact sum S, when S is a valid polytope of FIMS's
///   facets as they are (none merged), its guess split (ExpectedVertices::split);
/// - otherwise the rounded sum (as dilate gives it), validated as an operand and eroded
///   exactly. Where a facet is planar only within the tolerance, S's Gauss map can fold (an
///   edge facet's exact normal just outside its neighbours' arc: not_convex), or make_polytope
///   merges facets of S across edges that are not strictly convex, and the merged facets'
///   planes are not S's: eroded, they cut A by a visible amount (up to 7% of a UV sphere's
///   radius, tests/morphology_test.cpp). The rounded sum's facets are planar within the
///   tolerance, and its closing is A within that tolerance.
struct Closing {
  MaybePolytope eroded;
  std::vector<FacetOrigin> origins;
};
Closing close_polytope(const Polytope& A, const Polytope& B, const IntersectOptions& options = {});

/// What an erosion hands to intersect_halfspaces (tests compare the closing's routes).
struct ErosionInput {
  HalfSpaces halfspaces;
  V3<double> hint{0, 0, 0};
  KnownPoints known;
  ExpectedVertices expected;
};
ErosionInput erode_sum_input(const Polytope& S, const Polytope& A, const Polytope& B);

/// The closing's input from the facets of S = A (+) B (fims_facets(A, B)), without S: a
/// facet of S is A's face plus B's face along its normal n, so its plane moved back by
/// h_B(n) is <n, x> = <n, a_i> for any of its corners (a_i, b_j). The normals come from the
/// operands (A's facet, B's facet, the cross product of an edge of each, or the Newell normal
/// of the exact sums where parallel features were summed into one polygon), exactly the
/// normals S would have, and the half-spaces, known points and guess are erode_sum_input's
/// on S. Empty when a facet of A or B is planar only within the tolerance (S may then differ:
/// merged facets); close_polytope then takes another route.
std::optional<ErosionInput> closing_input(const SumFacets& sum, const Polytope& A,
                                          const Polytope& B);

}  // namespace morph::detail
