// The FIMS kernel: translated, corner and edge facets of A (+) B from the overlay of
// the two Gauss maps, every decision exact (see gauss_map.h and docs/algorithm.md).
#include <morph/error.h>
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <memory>
#include <numeric>

#include "fims.h"
#include "gauss_map.h"
#include "halfspace_intersection.h"
#include "parallel.h"

namespace morph::detail {

namespace {

// Elements per chunk of the facet loops. The output does not depend on them (buffers are
// gathered in order, and every location is exact whatever the walk's start). Small enough
// that two threads share a loop evenly (a chunk is a few microseconds of work); for walks
// from the previous answer, large enough that a task's first walk, from vertex 0, costs
// little (128: icosphere_320 (+) icosphere_1280 at two threads 95 us rather than 92).
constexpr int kFacetGrain = 256;
constexpr int kHintedGrain = 64;  // walks from WalkStarts: no restart at a chunk
constexpr int kEdgeGrain = 64;
// Walks per region from which the regions' caps pay (cap_regions).
constexpr int kCapWalksPerRegion = 16;

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

/// The facets found by one chunk of a loop, in loop order.
struct FacetBuffer {
  std::vector<int> sizes;
  std::vector<std::uint64_t> corners;
  std::vector<FacetOrigin> origins;
  std::vector<std::pair<int, int>> pairs;  // scratch
  std::vector<Arc> x_arcs, y_arcs;         // scratch
  std::vector<int> halves;                 // scratch
  std::vector<int> starts;                 // scratch: the chunk's walk starts (WalkStarts)

  void add(const FacetOrigin& origin) {
    for (const auto& [i, j] : pairs) corners.push_back(pair_key(i, j));
    sizes.push_back(static_cast<int>(pairs.size()));
    origins.push_back(origin);
  }
};

/// A loop of in_chunks: body(begin, end, buffer, hint) over [0, n) in chunks of `grain`.
/// `hint` is the vertex where the task's previous walk ended (0 at a task's first chunk):
/// chunks run by one task continue the walk from chunk to chunk.
template <class Body>
struct ChunkLoop {
  int n, grain;
  const Body& body;
  std::vector<FacetBuffer>* out;
  int chunks() const { return (n + grain - 1) / grain; }
};
/// With one thread, one chunk per loop: fewer buffers to fill and gather.
template <class Body>
ChunkLoop<Body> chunk_loop(int n, int grain, const Body& body, std::vector<FacetBuffer>& out) {
  return {n, tbb::this_task_arena::max_concurrency() == 1 ? std::max(n, 1) : grain, body, &out};
}

/// in_chunks' `task` when there is none.
using NoTask = void (*)();
constexpr const NoTask* kNoTask = nullptr;

/// Runs `task` (unless null) and the chunks of both loops as one parallel loop (one join
/// for all), each chunk writing its own buffer: the buffers are in loop order, whatever
/// the schedule.
template <class Body1, class Body2, class Task>
void in_chunks(const ChunkLoop<Body1>& one, const ChunkLoop<Body2>& two, const Task* task) {
  const int t = task ? 1 : 0, c1 = one.chunks(), c2 = two.chunks();
  one.out->resize(c1);
  two.out->resize(c2);
  auto run = [](const auto& loop, int c, int& hint) {
    FacetBuffer& b = (*loop.out)[c];
    // About one facet per element, of about four corners.
    b.sizes.reserve(loop.grain);
    b.origins.reserve(loop.grain);
    b.corners.reserve(4 * loop.grain);
    loop.body(c * loop.grain, std::min(loop.n, (c + 1) * loop.grain), b, hint);
  };
  parallel_chunks(t + c1 + c2, 1, [&](int first, int last) {
    int hint = 0;
    for (int c = first; c < last; ++c) {
      if (c < t)
        (*task)();
      else if (c < t + c1)
        run(one, c - t, hint);
      else {
        if (c == t + c1) hint = 0;  // the second loop walks on another map
        run(two, c - t - c1, hint);
      }
    }
  });
}
template <class Body>
void in_chunks(const ChunkLoop<Body>& one) {
  std::vector<FacetBuffer> none;
  in_chunks(one, chunk_loop(0, 1, one.body, none), kNoTask);
}

/// The facet of A (+) B whose normal is the normal of facet f of X (X is A when
/// x_is_a), located at `loc` in Y's Gauss map.
void facet_at_normal(const Polytope& X, int f, const Polytope& Y, const Location& loc, bool x_is_a,
                     FacetBuffer& out) {
  const Element ex{Element::Kind::facet, X.face_source[f]};
  const Element ey = element_of(Y, loc);
  const FacetOrigin origin =
      x_is_a ? FacetOrigin{FacetKind::translated, ex, ey} : FacetOrigin{FacetKind::corner, ey, ex};
  if (loc.kind == Location::Kind::vertex) {
    // Inside a region of Y (the usual case) the overlay is f's own arcs: f moved by the
    // vertex, its corners in the order overlay_regions gives them (from corner 1 on).
    const int d = X.degree(f), b = X.face_begin[f], y = loc.index;
    for (int k = 1; k <= d; ++k) {
      const int x = X.corner_vertex[b + (k == d ? 0 : k)];
      out.corners.push_back(x_is_a ? pair_key(x, y) : pair_key(y, x));
    }
    out.sizes.push_back(d);
    out.origins.push_back(origin);
    return;
  }
  arcs_around(X, {Location::Kind::face, f}, out.x_arcs);
  arcs_around(Y, loc, out.y_arcs);
  out.pairs.clear();
  overlay_regions(NormalRef{&X, f}, out.x_arcs, out.y_arcs, loc.index, out.pairs, out.halves);
  if (!x_is_a)
    for (auto& c : out.pairs) std::swap(c.first, c.second);
  out.add(origin);
}

/// Per-thread marks for the walks of edge_facets, over B's elements.
struct WalkScratch {
  std::vector<int> region_stamp, edge_stamp, face_stamp;
  // orient(n1, n2, N_g), or kUndecided, when face_stamp[g] is current.
  std::vector<signed char> face_side;
  std::vector<int> queue;
  // The regions next to the end region of the short arcs' shortcut (near_stamp[v] current),
  // with the edge across (near_edge[v]).
  std::vector<int> near_stamp, near_edge;
  explicit WalkScratch(const Polytope& B)
      : region_stamp(B.num_vertices(), 0),
        edge_stamp(B.num_edges(), 0),
        face_stamp(B.num_faces(), 0),
        face_side(B.num_faces(), 0),
        near_stamp(B.num_vertices(), 0),
        near_edge(B.num_vertices(), 0) {}
};

/// Appends the edge facets of edge a of A: for each edge of B whose arc the arc of a
/// crosses (in B's edge order), the parallelogram a (+) b counter-clockwise about its
/// outward normal. The crossings are found by a breadth-first walk over the regions of B
/// that the arc touches, starting where the arc starts (`start`); each of B's normals is
/// tested against the arc's great circle once. The region where the arc ends, when its end
/// is inside one (`end`), is not walked on from: the arc enters it once and stays (a convex
/// region), so its one crossing into it is found from the region before.
void edge_facets(const Polytope& A, int a, const ArcPlane& plane_a, const Polytope& B,
                 const Location& start, const Location& end, WalkScratch& w, FacetBuffer& out) {
  const auto& ea = A.edges[a];
  const NormalRef n1{&A, ea.left}, n2{&A, ea.right};
  const int ua = ea.from, wa = ea.to;
  // The parallelogram of a crossing with edge e of B, whose arc's right facet's normal is on
  // side `side_of_b` of a's great circle.
  auto emit = [&](int e, int side_of_b) {
    // b's ends in the order (from, to) when side > 0, else (to, from) (a crossing's side is
    // never 0).
    int ub = B.edges[e].from, wb = B.edges[e].to;
    if (side_of_b <= 0) std::swap(ub, wb);
    const std::uint64_t q[4] = {pair_key(wa, ub), pair_key(wa, wb), pair_key(ua, wb),
                                pair_key(ua, ub)};
    out.corners.insert(out.corners.end(), q, q + 4);
    out.sizes.push_back(4);
    out.origins.push_back({FacetKind::edge,
                           {Element::Kind::edge, A.edge_source[a]},
                           {Element::Kind::edge, B.edge_source[e]}});
  };
  if (start.kind == Location::Kind::vertex && end.kind == Location::Kind::vertex) {
    // The usual short arcs first, by the double filters alone: when a's arc starts inside
    // region l and ends inside region r, crossing an arc of l's boundary at a point interior
    // to both arcs is where it leaves l (a convex region, a segment from its interior leaves
    // it once) into the region across, and from there likewise. So a crossing of the arc
    // between l and r, or of the arcs l | w and w | r for a region w next to both, is all
    // the walk below would find (the same crossings, the same sides). Anything else (not
    // decided by the filters, longer arcs) takes the walk.
    auto crosses = [&](int e, int& side_of_b) {
      const auto& eb = B.edges[e];
      const int s1 = orient_arc_filter(plane_a, NormalRef{&B, eb.left});
      const int s2 = orient_arc_filter(plane_a, NormalRef{&B, eb.right});
      if (s1 == kUndecided || s2 == kUndecided || s1 * s2 >= 0) return false;
      const ArcPlane plane_b = arc_plane(B, e);
      const int t1 = orient_arc_filter(plane_b, n1), t2 = orient_arc_filter(plane_b, n2);
      if (t1 == kUndecided || t2 == kUndecided || t1 * t2 >= 0 || t1 != -s1) return false;
      side_of_b = s2;  // as arc_contact gives it
      return true;
    };
    const int l = start.index, r = end.index;
    // r's neighbours, marked once: then each region next to l is looked up, not scanned.
    for (int s = B.fan_begin[r]; s < B.fan_begin[r + 1]; ++s) {
      w.near_stamp[B.fan_vertex[s]] = a + 1;
      w.near_edge[B.fan_vertex[s]] = B.fan_edge[s];
    }
    int side1, side2;
    if (w.near_stamp[l] == a + 1) {  // l next to r
      const int e = w.near_edge[l];
      if (crosses(e, side1)) {
        emit(e, side1);
        return;
      }
    } else {
      for (int s = B.fan_begin[l]; s < B.fan_begin[l + 1]; ++s) {
        const int v = B.fan_vertex[s];
        if (w.near_stamp[v] != a + 1) continue;
        const int e1 = B.fan_edge[s], e2 = w.near_edge[v];
        if (crosses(e1, side1) && crosses(e2, side2)) {  // in B's edge order
          emit(std::min(e1, e2), e1 < e2 ? side1 : side2);
          emit(std::max(e1, e2), e1 < e2 ? side2 : side1);
          return;
        }
      }
    }
  }
  const int stamp = a + 1;
  w.queue.clear();
  auto visit = [&](int v) {
    if (w.region_stamp[v] != stamp) {
      w.region_stamp[v] = stamp;
      w.queue.push_back(v);
    }
  };
  // orient(n1, n2, N_g): first by the double stage alone (kUndecided when it cannot tell),
  // exactly only when needed.
  auto side = [&](int g) {
    if (w.face_stamp[g] != stamp) {
      w.face_stamp[g] = stamp;
      w.face_side[g] = static_cast<signed char>(orient_arc_filter(plane_a, NormalRef{&B, g}));
    }
    return static_cast<int>(w.face_side[g]);
  };
  auto exact_side = [&](int g) {
    if (w.face_side[g] == kUndecided)
      w.face_side[g] = static_cast<signed char>(orient_arc(A, a, plane_a, NormalRef{&B, g}));
    return static_cast<int>(w.face_side[g]);
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
  std::vector<std::pair<int, int>>& crossings = out.pairs;  // (edge of B, side)
  crossings.clear();
  const int last = end.kind == Location::Kind::vertex ? end.index : -1;
  for (std::size_t q = 0; q < w.queue.size(); ++q) {
    const int v = w.queue[q];
    if (v == last) continue;
    for (int s = B.fan_begin[v]; s < B.fan_begin[v + 1]; ++s) {
      const int e = B.fan_edge[s];
      if (w.edge_stamp[e] == stamp) continue;
      w.edge_stamp[e] = stamp;
      const auto& eb = B.edges[e];
      int s1 = side(eb.left), s2 = side(eb.right);
      if (s1 != kUndecided && s2 != kUndecided && s1 * s2 > 0) continue;  // as below, sooner
      const ArcPlane plane_b = arc_plane(B, e);
      if (s1 == kUndecided || s2 == kUndecided) {
        // Nearly on a's great circle. Before deciding exactly: a's arc strictly on one side
        // of b's great circle touches nothing.
        const int u1 = orient_arc_filter(plane_b, n1), u2 = orient_arc_filter(plane_b, n2);
        if (u1 != kUndecided && u2 != kUndecided && u1 * u2 > 0) continue;
        s1 = exact_side(eb.left);
        s2 = exact_side(eb.right);
      }
      if (s1 * s2 > 0) continue;  // b's arc strictly on one side of a's great circle
      int t1 = 0, t2 = 0;
      if (arc_contact_needs_t(s1, s2)) {
        t1 = orient_arc(B, e, plane_b, n1);
        t2 = orient_arc(B, e, plane_b, n2);
      }
      const ArcContact c =
          arc_contact(n1, n2, NormalRef{&B, eb.left}, NormalRef{&B, eb.right}, s1, s2, t1, t2);
      if (c.crosses) crossings.emplace_back(e, c.side);
      if (c.touches) visit(B.fan_vertex[s]);
    }
  }
  std::sort(crossings.begin(), crossings.end());
  for (const auto& [e, side_of_b] : crossings) emit(e, side_of_b);
}

/// Whether facets f and g of P share an edge: a scan of f's edges.
bool facets_adjacent(const Polytope& P, int f, int g) {
  for (int k = P.face_begin[f]; k < P.face_begin[f + 1]; ++k) {
    const auto& e = P.edges[P.corner_edge[k]];
    if (e.left == g || e.right == g) return true;
  }
  return false;
}

/// Where to start locating facets of X in Y's Gauss map, from Y's facets located in X's
/// (loc_y): N_f is the common corner of the regions of f's corners in X's map, so the
/// facets of Y whose normals those regions contain are the ones near it; the walk starts
/// at the corner furthest along N_f of the nearest of them in the first such region that has
/// any (nearest and furthest in doubles: they only pick where the exact walk starts; one
/// region's scan costs less than the steps the others would spare).
class WalkStarts {
 public:
  /// Y's facets by the vertex of X whose region contains their normal (a counting sort).
  WalkStarts(const Polytope& X, const Polytope& Y, const std::vector<Location>& loc_y)
      : X_(X), Y_(Y), first_(X.num_vertices() + 1, 0) {
    for (const Location& l : loc_y)
      if (l.kind == Location::Kind::vertex) ++first_[l.index + 1];
    std::partial_sum(first_.begin(), first_.end(), first_.begin());
    std::vector<int> next(first_.begin(), first_.end() - 1);
    by_region_.resize(first_.back());
    for (int g = 0; g < Y.num_faces(); ++g)
      if (loc_y[g].kind == Location::Kind::vertex) by_region_[next[loc_y[g].index]++] = g;
  }

  /// The start for facet f of X: a vertex of Y, or -1 when the regions of f's corners
  /// contain no facet normal of Y.
  int operator()(int f) const {
    const UnitNormal& n = X_.unit_normals[f];
    double best = -2;  // below any dot product of unit vectors
    int nearest = -1;
    for (int k = 0; k < X_.degree(f) && nearest < 0; ++k) {  // the first region with any
      const int u = X_.corner(f, k);
      for (int i = first_[u]; i < first_[u + 1]; ++i) {
        const UnitNormal& m = Y_.unit_normals[by_region_[i]];
        const double d = n.x * m.x + n.y * m.y + n.z * m.z;
        if (d > best) {
          best = d;
          nearest = by_region_[i];
        }
      }
    }
    if (nearest < 0) return -1;
    // Of its corners, the one furthest along N_f (the walk then starts there, without
    // locate's step: that usually is the contributing vertex).
    double top = -std::numeric_limits<double>::infinity();
    int start = -1;
    for (int k = 0; k < Y_.degree(nearest); ++k) {
      const V3<double>& q = Y_.points[Y_.corner(nearest, k)];
      const double h = n.x * q.x + n.y * q.y + n.z * q.z;
      if (h > top) {
        top = h;
        start = Y_.corner(nearest, k);
      }
    }
    return start;
  }

 private:
  const Polytope& X_;
  const Polytope& Y_;
  std::vector<int> first_, by_region_;
};

/// Whether `walks` walks on P's map test enough slots to pay for making each slot's plane
/// once (slot_planes, or a SlotCache), rather than forming it at each test: making one costs
/// about as much as testing it, and a walk tests about ten; at least a quarter as many walks
/// as slots.
bool cache_slots(const Polytope& P, int walks) {
  return 4 * static_cast<std::size_t>(walks) >= P.fan_face.size();
}

/// Whether `walks` walks on P's map are enough per region to pay for making each region's
/// cap (RegionCap), which costs about as much as a few region tests and spares one (and the
/// step in doubles) to each walk that ends in the cap of where it starts. Measured: at 8 walks
/// per region (icosphere_1280 on icosphere_320's map) about even, at 27 (uvsphere_1600 on the
/// snub dodecahedron's) 6 us of 88 spared.
bool cap_regions(const Polytope& P, int walks) {
  return walks >= kCapWalksPerRegion * P.num_vertices();
}

using BufferLists = std::initializer_list<const std::vector<FacetBuffer>*>;

/// Appends the facets of the buffers to `out`, in order: sizes summed once, each array
/// extended in one go.
void append(SumFacets& out, BufferLists lists) {
  std::size_t faces = 0, corners = 0;
  for (const auto* list : lists)
    for (const auto& b : *list) faces += b.origins.size(), corners += b.corners.size();
  const std::size_t done = out.origins.size();
  out.face_begin.resize(done + faces + 1);
  out.corners.reserve(out.corners.size() + corners);
  out.origins.reserve(done + faces);
  int* begin = out.face_begin.data() + done;
  for (const auto* list : lists)
    for (const auto& b : *list) {
      for (int size : b.sizes) begin[1] = begin[0] + size, ++begin;
      out.corners.insert(out.corners.end(), b.corners.begin(), b.corners.end());
      out.origins.insert(out.origins.end(), b.origins.begin(), b.origins.end());
    }
}

/// The first part of the facets, gathered while the last loop makes the rest: the arrays
/// made with room for about `more_faces` more facets of four corners (they grow if that
/// was too few), the buffers appended.
void gather_head(SumFacets& out, BufferLists lists, std::size_t more_faces) {
  std::size_t faces = 0, corners = 0;
  for (const auto* list : lists)
    for (const auto& b : *list) faces += b.origins.size(), corners += b.corners.size();
  out.face_begin.reserve(faces + more_faces + 1);
  out.corners.reserve(corners + 4 * more_faces);
  out.origins.reserve(faces + more_faces);
  append(out, lists);
}

/// With one thread (one chunk a loop, chunk_loop): room in the head loop's one buffer for
/// about `faces` facets of four corners, all of the result's, so that take_head can make its
/// arrays the result's.
void make_room(std::vector<FacetBuffer>& head, std::size_t faces) {
  head.resize(1);
  head[0].corners.reserve(4 * faces);
  head[0].origins.reserve(faces);
}

/// gather_head for a head of one buffer made with make_room: its arrays become the result's
/// (moved rather than copied; their room holds the rest), then `rest` is appended.
void take_head(SumFacets& out, FacetBuffer& head, BufferLists rest) {
  out.face_begin.reserve(head.origins.capacity() + 1);
  out.face_begin.resize(head.sizes.size() + 1);
  int* begin = out.face_begin.data();
  for (int size : head.sizes) begin[1] = begin[0] + size, ++begin;
  out.corners = std::move(head.corners);
  out.origins = std::move(head.origins);
  append(out, rest);
}

}  // namespace

SumFacets fims_facets(const Polytope& A, const Polytope& B) {
  // The facets of one operand are located first, walking on the other's map from the
  // previous facet's answer: those of the one whose walks are shorter (on the coarser map,
  // fewer vertices). The other's then start next to the nearest of them (WalkStarts). Each
  // step is one parallel loop over chunks of all the facets it can make: 1. the first
  // operand's facets located, with their translated or corner facets; 2. the other's
  // likewise, and A's edge facets when A's facets were located in step 1; 3. A's edge
  // facets otherwise (with threads, that case runs otherwise: see below). The chunks'
  // buffers are gathered in the same order whatever the schedule.
  // The double-double cross products of nearly parallel pairs kept for the calling thread's
  // predicates (with one thread, all of them).
  const NearPairScope near_pairs(A, B);
  const int na = A.num_faces(), nb = B.num_faces();
  std::vector<Location> loc_a(na), loc_b(nb);
  std::vector<FacetBuffer> translated, corner, edge, none;
  // The slot planes of the map walked on, when they pay (cache_slots): all made at once just
  // before the walks (slot_planes: in one pass over the fans, about 1.5 ns a slot, where made
  // as the walks first test each region they cost about twice that; icosphere_5120 (+) a
  // rotated copy 0.80 ms rather than 0.85), or, when the regions' caps pay too (cap_regions),
  // per thread as the walks first test each region (a SlotCache, which makes the caps with
  // them: there the walks are many and the regions few).
  const bool caps_a = cap_regions(A, nb), caps_b = cap_regions(B, na);
  const bool all_a = !caps_a && cache_slots(A, nb), all_b = !caps_b && cache_slots(B, na);
  SlotPlanes planes_a, planes_b;
  auto make_planes_a = [&] {
    if (all_a) planes_a = slot_planes(A);
  };
  auto make_planes_b = [&] {
    if (all_b) planes_b = slot_planes(B);
  };
  tbb::enumerable_thread_specific<SlotCache> slots_a([&] { return SlotCache(A, true); });
  tbb::enumerable_thread_specific<SlotCache> slots_b([&] { return SlotCache(B, true); });
  const WalkStarts* starts = nullptr;  // null: each walk starts at the previous answer
  // The facets of P at their normals' locations in Q's map: translated facets (P = A), one
  // per facet of A; corner facets (P = B), one per facet of B whose normal is not also a
  // facet normal of A.
  auto located_facets = [&](const Polytope& P, const Polytope& Q, std::vector<Location>& loc,
                            tbb::enumerable_thread_specific<SlotCache>& q_slots, bool caps_q,
                            const SlotPlanes& q_planes) {
    return [&, P = &P, Q = &Q, loc = loc.data(), q_slots = &q_slots, caps_q, q_planes = &q_planes](
               int begin, int end, FacetBuffer& out, int& hint) {
      const bool translated = P == &A;
      SlotCache* const slots = caps_q ? &q_slots->local() : nullptr;
      const ArcPlane* const planes = q_planes->data();  // null: each formed as it is tested
      // The chunk's starts first, in a loop of their own: each scan reads scattered normals
      // and points of Q, and, with no walk between them, the scans' cache misses overlap.
      if (starts) {
        out.starts.resize(end - begin);
        for (int f = begin; f < end; ++f) out.starts[f - begin] = (*starts)(f);
      }
      // Whether the previous walk ended where it started: then this one likely does too (a
      // fine map walked on a coarse one: runs of facets in one region), and its first region
      // test costs less than locate's step in doubles would.
      bool stayed = false;
      for (int f = begin; f < end; ++f) {
        const int start = starts ? out.starts[f - begin] : -1;
        if (start >= 0) hint = start;
        const bool step = start < 0 && !stayed && !slots;
        const NormalRef n{P, f};
        loc[f] = slots ? locate(*Q, *slots, n, hint, step) : locate(*Q, planes, n, hint, step);
        const int found = location_vertex(*Q, loc[f]);
        stayed = found == hint;
        hint = found;
        if (translated || loc[f].kind != Location::Kind::face)
          facet_at_normal(*P, f, *Q, loc[f], translated, out);
      }
    };
  };
  const auto translated_facets = located_facets(A, B, loc_a, slots_b, caps_b, planes_b);
  const auto corner_facets = located_facets(B, A, loc_b, slots_a, caps_a, planes_a);
  // Edge facets: for every edge of A whose two facets have different contributing
  // vertices, the edges of B whose arcs its arc crosses.
  tbb::enumerable_thread_specific<WalkScratch> scratch([&] { return WalkScratch(B); });
  auto edge_facets_of = [&](int begin, int end, FacetBuffer& out, int&) {
    WalkScratch& w = scratch.local();
    for (int a = begin; a < end; ++a) {
      const auto& l = loc_a[A.edges[a].left];
      const auto& r = loc_a[A.edges[a].right];
      if (l.kind == Location::Kind::vertex && r.kind == Location::Kind::vertex &&
          l.index == r.index)
        continue;
      // a's arc is an arc of B's map (its facets' normals are those of two adjacent facets
      // of B: parallel edges, as in A (+) A): the other arcs of B meet it only at its ends,
      // so it crosses none.
      if (l.kind == Location::Kind::face && r.kind == Location::Kind::face &&
          facets_adjacent(B, l.index, r.index))
        continue;
      edge_facets(A, a, arc_plane(A, a), B, l, r, w, out);
    }
  };
  SumFacets out;
  // Edge facets: usually about as many as the edges of both (one per crossing of arcs).
  const std::size_t edge_estimate = A.num_edges() + B.num_edges();
  if (tbb::this_task_arena::max_concurrency() > 1 && A.num_vertices() <= B.num_vertices()) {
    // With threads, where the steps below would be three loops, the two operands' facets
    // are located side by side from the start instead, each walk from the previous answer
    // (more walking in all, but no locating before the other side can start), and the edge
    // facets follow on A's side, in chunks that the other thread takes once its side is done.
    // Measured at two threads: icosphere_320 (+) icosphere_1280 93 us rather than 104 in
    // three loops, icosphere_5120 (+) a rotated copy 0.51 ms rather than 0.58 (each thread
    // runs its chunks 25-60% slower than one thread alone would: the fewer steps, the
    // better). With A's facets located first the steps are two loops, and faster so
    // (uvsphere_1600 (+) snub_dodecahedron 77 us rather than 91). Whichever side finishes
    // its facets second gathers both into the result (the same facets either way).
    std::atomic<int> sides_done{0};
    auto side_done = [&] {
      if (sides_done.fetch_add(1, std::memory_order_acq_rel) == 1)
        gather_head(out, {&translated, &corner}, edge_estimate);
    };
    run_both(
        [&] {
          make_planes_a();
          in_chunks(chunk_loop(nb, kFacetGrain, corner_facets, corner));
          side_done();
        },
        [&] {
          make_planes_b();
          in_chunks(chunk_loop(na, kFacetGrain, translated_facets, translated));
          side_done();
          in_chunks(chunk_loop(A.num_edges(), kEdgeGrain, edge_facets_of, edge));
        });
    append(out, {&edge});
  } else if (A.num_vertices() <= B.num_vertices()) {
    make_planes_a();
    in_chunks(chunk_loop(nb, kFacetGrain, corner_facets, corner));
    const WalkStarts hints(A, B, loc_b);
    starts = &hints;
    make_planes_b();
    in_chunks(chunk_loop(na, kHintedGrain, translated_facets, translated));
    auto head = [&] { gather_head(out, {&translated, &corner}, edge_estimate); };
    in_chunks(chunk_loop(A.num_edges(), kEdgeGrain, edge_facets_of, edge),
              chunk_loop(0, 1, edge_facets_of, none), &head);
    append(out, {&edge});
  } else {
    make_planes_b();
    const bool one_chunk = tbb::this_task_arena::max_concurrency() == 1;
    if (one_chunk) make_room(translated, na + nb + edge_estimate);
    in_chunks(chunk_loop(na, kFacetGrain, translated_facets, translated));
    const WalkStarts hints(B, A, loc_a);
    starts = &hints;
    make_planes_a();
    if (one_chunk && translated.size() == 1 && nb > 0 && A.num_edges() > 0) {
      // One buffer for all three loops (one chunk each, in order), made the result's at the
      // end: the corner and edge facets are not copied from buffers of their own.
      in_chunks(chunk_loop(nb, kHintedGrain, corner_facets, translated),
                chunk_loop(A.num_edges(), kEdgeGrain, edge_facets_of, translated), kNoTask);
      take_head(out, translated[0], {});
      return out;
    }
    auto head = [&] { gather_head(out, {&translated}, nb + edge_estimate); };
    in_chunks(chunk_loop(nb, kHintedGrain, corner_facets, corner),
              chunk_loop(A.num_edges(), kEdgeGrain, edge_facets_of, edge), &head);
    append(out, {&corner, &edge});
  }
  return out;
}

namespace {

/// The distinct values among partner[b..e) (vertices of B), sorted, written to `out`; their
/// number. `slot` is -1 at every vertex of B on entry, and 0 at those written on return
/// (the caller numbers them there, then resets them).
int distinct_partners(const int* partner, int b, int e, int* slot, int* out) {
  int n = 0;
  for (int k = b; k < e; ++k) {
    const int j = partner[k];
    if (slot[j] < 0) {
      slot[j] = 0;
      out[n++] = j;
    }
  }
  std::sort(out, out + n);
  return n;
}

/// index_vertices in one thread by a bit set of partners per vertex of A: a row of
/// ceil(num_b / 64) words per vertex i, bit j set for each pair (i, j) of a corner (one pass,
/// no branch per corner). Reading the rows in order lists the pairs sorted by (i, j), so a
/// pair's number is the bits set before its own (a running count per word, then a bit count
/// within the word): no search, no sort. `count` counts a word's bits. `kOneWord`: row is 1
/// (B has at most 64 vertices), so a pair's word is its vertex of A.
template <bool kOneWord, class Count>
[[gnu::always_inline]] inline void index_by_bits(const SumFacets& facets, int num_a, int row,
                                                 std::vector<std::uint64_t>& pairs,
                                                 std::vector<int>& corners, Count count) {
  const int nc = static_cast<int>(facets.corners.size());
  const int num_words = num_a * row;
  std::vector<std::uint64_t> bits(num_words, 0);
  const std::uint64_t* const key = facets.corners.data();
  const auto word = [row](int i, int j) {
    return kOneWord ? std::size_t(i) : std::size_t(i) * row + (j >> 6);
  };
  for (int c = 0; c < nc; ++c) {
    const int i = pair_first(key[c]), j = pair_second(key[c]);
    bits[word(i, j)] |= std::uint64_t{1} << (j & 63);
  }
  // before[w]: the pairs in the words before w.
  const auto before = std::make_unique_for_overwrite<int[]>(num_words);
  int num_pairs = 0;
  for (int w = 0; w < num_words; ++w) {
    before[w] = num_pairs;
    num_pairs += count(bits[w]);
  }
  pairs.resize(num_pairs);
  std::uint64_t* const pair = pairs.data();
  for (int i = 0, w = 0; i < num_a; ++i)
    for (int k = 0; k < row; ++k, ++w)
      for (std::uint64_t b = bits[w], n = before[w]; b != 0; b &= b - 1)
        pair[n++] = pair_key(i, k * 64 + std::countr_zero(b));
  corners.resize(nc);
  int* const corner = corners.data();
  for (int c = 0; c < nc; ++c) {
    const int i = pair_first(key[c]), j = pair_second(key[c]);
    const std::size_t w = word(i, j);
    const std::uint64_t below = (std::uint64_t{1} << (j & 63)) - 1;
    corner[c] = before[w] + count(bits[w] & below);
  }
}

/// index_by_bits with the popcnt instruction (the build targets baseline x86-64).
[[gnu::target("popcnt")]] void index_by_bits_popcnt(const SumFacets& facets, int num_a, int row,
                                                    std::vector<std::uint64_t>& pairs,
                                                    std::vector<int>& corners) {
  const auto count = [](std::uint64_t x) { return __builtin_popcountll(x); };
  // A row of one word (B of at most 64 vertices, e.g. the snub dodecahedron): no word
  // arithmetic per corner.
  if (row == 1)
    index_by_bits<true>(facets, num_a, 1, pairs, corners, count);
  else
    index_by_bits<false>(facets, num_a, row, pairs, corners, count);
}

/// index_vertices by bit sets (index_by_bits), when the rows are few for the corners (the
/// words cleared and scanned cost about as much as the corners; uvsphere_1600 (+) snub
/// dodecahedron: 1562 words for about 9800 corners) and the processor counts bits in one
/// instruction; false otherwise, nothing done. Measured with 1 thread: uvsphere_1600 (+) snub
/// dodecahedron 3% faster than the lists (index_vertices_serial, whose branches per corner
/// mispredict), icosphere_320 (+) icosphere_1280 (11 words a row) the same; counting bits
/// without popcnt (shifts and masks) cost what the lists' mispredictions did.
bool index_vertices_bits(const SumFacets& facets, int num_a, int num_b,
                         std::vector<std::uint64_t>& pairs, std::vector<int>& corners) {
  constexpr std::int64_t kCornersPerWord = 2;
  static const bool popcnt = __builtin_cpu_supports("popcnt");
  const int row = (num_b + 63) / 64;  // words per vertex of A
  if (!popcnt || std::int64_t{num_a} * row * kCornersPerWord >
                     static_cast<std::int64_t>(facets.corners.size()) + 1024)
    return false;
  index_by_bits_popcnt(facets, num_a, row, pairs, corners);
  return true;
}

/// index_vertices in one thread when the bit sets do not apply (index_vertices_bits: large
/// operands): the distinct pairs are found in one pass over the corners,
/// each in a short list of the pairs found so far at its vertex of the operand with more
/// vertices (fewer partners each: about 1.5 for uvsphere 1600 (+) snub dodecahedron), each
/// corner numbered by its pair's place in the lists; then the pairs are sorted by two
/// counting sorts over the pairs (by j, then stably by i: about a quarter as many as the
/// corners) and the corners renumbered. Random accesses stay within arrays of a vertex or
/// pair each, rather than scattering the corners into buckets and back.
/// A vertex with many partners (the apex of a fine cone against a fine sphere) would make the
/// list searches quadratic in its partners: past kListStepsPerCorner steps a corner on
/// average, this gives up (false, nothing written that the caller keeps) and the caller
/// numbers by buckets, linear whatever the partners.
bool index_vertices_serial(const SumFacets& facets, int num_a, int num_b,
                           std::vector<std::uint64_t>& pairs, std::vector<int>& corners) {
  constexpr long kListStepsPerCorner = 4;
  const int nc = static_cast<int>(facets.corners.size());
  corners.resize(nc);
  struct Found {
    int i, j;
    int next;  // the pair found before it at the same listed vertex (-1: none)
  };
  const auto found = std::make_unique_for_overwrite<Found[]>(nc);  // at most a pair per corner
  int num_pairs = 0;
  const std::uint64_t* const key = facets.corners.data();
  int* const corner = corners.data();
  const auto find_pairs = [&](auto by_b, int num_listed) {
    std::vector<int> last(num_listed, -1);  // the pair last found at each listed vertex
    long steps_left = kListStepsPerCorner * nc + 64;
    for (int c = 0; c < nc; ++c) {
      const int i = pair_first(key[c]), j = pair_second(key[c]);
      int& head = last[by_b ? j : i];
      int n = head;
      while (n >= 0 && (by_b ? found[n].i != i : found[n].j != j)) {
        n = found[n].next;
        --steps_left;
      }
      if (steps_left < 0) return false;
      if (n < 0) {
        n = num_pairs++;
        found[n] = {i, j, head};
        head = n;
      }
      corner[c] = n;
    }
    return true;
  };
  if (!(num_b > num_a ? find_pairs(std::true_type{}, num_b) : find_pairs(std::false_type{}, num_a)))
    return false;
  // The pairs in order of j (counting sort), then stably of i: sorted by (i, j).
  const auto by_j = std::make_unique_for_overwrite<int[]>(num_pairs);
  {
    std::vector<int> end(num_b + 1, 0);
    for (int n = 0; n < num_pairs; ++n) ++end[found[n].j];
    std::partial_sum(end.begin(), end.end(), end.begin());
    for (int n = num_pairs - 1; n >= 0; --n) by_j[--end[found[n].j]] = n;
  }
  const auto place = std::make_unique_for_overwrite<int[]>(num_pairs);  // of each found pair
  pairs.resize(num_pairs);
  {
    std::vector<int> end(num_a + 1, 0);
    for (int n = 0; n < num_pairs; ++n) ++end[found[n].i];
    std::partial_sum(end.begin(), end.end(), end.begin());
    for (int k = num_pairs - 1; k >= 0; --k) {
      const int n = by_j[k];
      const int p = --end[found[n].i];
      place[n] = p;
      pairs[p] = pair_key(found[n].i, found[n].j);
    }
  }
  for (int c = 0; c < nc; ++c) corner[c] = place[corner[c]];
  return true;
}

}  // namespace

void index_vertices(const SumFacets& facets, int num_a, int num_b,
                    std::vector<std::uint64_t>& pairs, std::vector<int>& corners) {
  const int nc = static_cast<int>(facets.corners.size());
  // Large results with threads to spare, or a vertex with too many partners for the lists
  // (index_vertices_serial gives up): the buckets of a counting sort by vertex of A are
  // numbered in two passes, parallel with threads (below).
  constexpr int kParallelCorners = 1 << 17;
  if ((nc < kParallelCorners || tbb::this_task_arena::max_concurrency() == 1) &&
      (index_vertices_bits(facets, num_a, num_b, pairs, corners) ||
       index_vertices_serial(facets, num_a, num_b, pairs, corners)))
    return;
  // first[i]..first[i + 1]: the corners at vertex i of A, in `by_a`, with their vertex of B
  // in `partner` (read in order below rather than through by_a).
  std::vector<int> first(num_a + 1, 0);
  const auto by_a = std::make_unique_for_overwrite<int[]>(nc);
  const auto partner = std::make_unique_for_overwrite<int[]>(nc);
  for (const std::uint64_t key : facets.corners) ++first[pair_first(key)];
  std::partial_sum(first.begin(), first.end(), first.begin());  // first[i]: end of bucket i
  for (int c = nc - 1; c >= 0; --c) {
    const std::uint64_t key = facets.corners[c];
    const int k = --first[pair_first(key)];
    by_a[k] = c;
    partner[k] = pair_second(key);
  }
  corners.resize(nc);
  // The same numbering, bucket by bucket in parallel: first each bucket's distinct partners,
  // sorted, at the front of its range in `distinct`, and each corner's index among them in
  // place of its partner; then, from the bucket sizes' prefix sums, the pairs and corners.
  // The numbers do not depend on how the buckets are split between threads.
  const auto distinct = std::make_unique_for_overwrite<int[]>(nc);
  std::vector<int> count(num_a + 1);
  tbb::enumerable_thread_specific<std::vector<int>> slots(
      [&] { return std::vector<int>(num_b, -1); });
  // About kCornerGrain corners a chunk (the buckets have about nc / num_a corners each).
  constexpr int kCornerGrain = 4096;
  const int grain = std::max(1, static_cast<int>(std::int64_t{num_a} * kCornerGrain / nc));
  parallel_chunks(num_a, grain, [&](int begin, int end) {
    std::vector<int>& slot = slots.local();  // all -1 between buckets
    for (int i = begin; i < end; ++i) {
      int* const own = distinct.get() + first[i];
      const int n = distinct_partners(partner.get(), first[i], first[i + 1], slot.data(), own);
      for (int p = 0; p < n; ++p) slot[own[p]] = p;
      for (int k = first[i]; k < first[i + 1]; ++k) partner[k] = slot[partner[k]];
      for (int p = 0; p < n; ++p) slot[own[p]] = -1;
      count[i + 1] = n;
    }
  });
  std::partial_sum(count.begin(), count.end(), count.begin());  // count[i]: bucket i's first pair
  pairs.resize(count[num_a]);
  parallel_chunks(num_a, grain, [&](int begin, int end) {
    for (int i = begin; i < end; ++i) {
      const int base = count[i];
      const int* const own = distinct.get() + first[i];
      for (int p = 0; p < count[i + 1] - base; ++p) pairs[base + p] = pair_key(i, own[p]);
      for (int k = first[i]; k < first[i + 1]; ++k) corners[by_a[k]] = base + partner[k];
    }
  });
}

namespace {

/// A vertex of a polytope in homogeneous dyadic coordinates (X, W) with an estimate of X / W.
struct Homogeneous {
  V3<ExactN> X;
  ExactN W;
  V3<double> estimate;
};
Homogeneous homogeneous(const Polytope& p, int v) {
  if (p.exact_points.empty()) return {to_exact_n(p.points[v]), ExactN(1), p.points[v]};
  return {p.exact_points.X(v), p.exact_points.W(v), p.points[v]};
}

/// E(i) + b rounded to the nearest doubles for E's exact point i and a double point b, from
/// E's precise point (round_precise_sum) where that decides, else exactly (round_quotient
/// on E's exact coordinates, computed on demand): an opening's sums, nearly all decided
/// without reading an exact point.
V3<double> round_sum_with_precise(const Polytope& E, int i, const V3<double>& b) {
  RoundingGuard nearest(CGAL_FE_TONEAREST);
  const PrecisePoint& p = E.exact_points.precise[i];
  const V3<double>& e = E.points[i];
  if (p.doubles) return {e.x + b.x, e.y + b.y, e.z + b.z};  // E(i) is e: correctly rounded
  double out[3];
  const double bc[3] = {b.x, b.y, b.z}, ec[3] = {e.x, e.y, e.z};
  const DD X[3] = {p.X.x, p.X.y, p.X.z};
  const double error[3] = {p.error.x, p.error.y, p.error.z};
  for (int k = 0; k < 3; ++k) {
    if (p.valid && round_precise_sum(X[k], error[k], p.W, p.w_error, bc[k], out[k])) continue;
    const V3<ExactN>& x = E.exact_points.X(i);
    const ExactN& w = E.exact_points.W(i);
    const ExactN& xk = k == 0 ? x.x : k == 1 ? x.y : x.z;
    const ExactN numerator = xk + ExactN(bc[k]) * w;
    if (CGAL::sign(numerator) == CGAL::ZERO) {  // E(i) = -b exactly: the sum is 0 (+0, as e + b)
      out[k] = 0.0;
      continue;
    }
    // Where round_quotient starts: e + b is within an ulp of e of the sum (e is E(i)
    // rounded), a good start unless e and b cancel, when that ulp is many of the sum's;
    // given as that wide an interval, round_quotient starts from the quotient of the
    // exact numerator's and W's doubles instead (a few ulps off), rather than searching
    // from e + b in vain and then dividing rationals (a gcd).
    const double s = ec[k] + bc[k];
    const double spread = (std::abs(ec[k]) + std::abs(s)) * 0x1p-52;
    out[k] = round_quotient(numerator, w, Interval(s - spread, s + spread));
  }
  return {out[0], out[1], out[2]};
}

/// A(i) + B(j) rounded to the nearest doubles, when a point is exact: homogeneous sums
/// rounded by round_quotient, no rationals (the same values as rounding the rational sum);
/// by the precise stage first when one point is double and the other has precise coordinates.
V3<double> round_exact_sum(const Polytope& A, int i, const Polytope& B, int j) {
  if (B.exact_points.empty() && !A.exact_points.precise.empty())
    return round_sum_with_precise(A, i, B.points[j]);
  if (A.exact_points.empty() && !B.exact_points.precise.empty())
    return round_sum_with_precise(B, j, A.points[i]);
  const Homogeneous a = homogeneous(A, i), b = homogeneous(B, j);
  // a.X / a.W + b.X / b.W; a double point has W = 1, and needs no multiplication by it.
  const auto sum = [&](const ExactN& x, const ExactN& y) -> ExactN {
    if (B.exact_points.empty()) return x + y * a.W;
    if (A.exact_points.empty()) return x * b.W + y;
    return x * b.W + y * a.W;
  };
  const ExactN W = A.exact_points.empty() ? b.W : B.exact_points.empty() ? a.W : a.W * b.W;
  // Only a starting point for the search: rounded sums of the rounded points.
  const V3<double> e{a.estimate.x + b.estimate.x, a.estimate.y + b.estimate.y,
                     a.estimate.z + b.estimate.z};
  return {round_quotient(sum(a.X.x, b.X.x), W, Interval(e.x)),
          round_quotient(sum(a.X.y, b.X.y), W, Interval(e.y)),
          round_quotient(sum(a.X.z, b.X.z), W, Interval(e.z))};
}

}  // namespace

namespace {

/// sum_mesh; `movable`: facets.origins, when the caller no longer needs them.
LabelledMesh sum_mesh(const Polytope& A, const Polytope& B, const SumFacets& facets,
                      std::vector<FacetOrigin>* movable) {
  std::vector<std::uint64_t> pairs;
  std::vector<int> corners;
  index_vertices(facets, A.num_vertices(), B.num_vertices(), pairs, corners);
  std::vector<V3<double>> points(pairs.size());
  const bool exact = !A.exact_points.empty() || !B.exact_points.empty();
  // Sums of double points are three additions each: split only in large chunks (at 1430
  // vertices, two chunks at two threads took 5 us more in all than one plain loop, as the
  // assembly then read the points from the other core's cache).
  const int grain = exact ? 1024 : 8192;
  parallel_chunks(static_cast<int>(pairs.size()), grain, [&](int begin, int end) {
    // Through local pointers: the stores to the points cannot then be taken for changes to
    // the arrays' bounds or to `exact`, reloaded at each vertex otherwise.
    const std::uint64_t* const pair = pairs.data();
    V3<double>* const point = points.data();
    if (!exact) {  // one correctly rounded addition per coordinate
      const V3<double>* const pa = A.points.data();
      const V3<double>* const pb = B.points.data();
      for (int v = begin; v < end; ++v) {
        const V3<double>&a = pa[pair_first(pair[v])], &b = pb[pair_second(pair[v])];
        point[v] = {a.x + b.x, a.y + b.y, a.z + b.z};
      }
    } else {
      for (int v = begin; v < end; ++v)
        point[v] = round_exact_sum(A, pair_first(pair[v]), B, pair_second(pair[v]));
    }
  });
  std::vector<int> source;
  // Initialised in place: OpenMesh meshes have no move assignment, only a deep copy.
  LabelledMesh out{clean_mesh(points, facets.face_begin, std::move(corners), &source), {}};
  // Each facet its own face (nothing merged, the usual case): the facets' origins as they are.
  bool same = movable && source.size() == movable->size();
  for (std::size_t i = 0; same && i < source.size(); ++i) same = source[i] == static_cast<int>(i);
  if (same) {
    out.origins = std::move(*movable);
    return out;
  }
  // A face with no source (a triangle of the hull fallback that no facet owns) has no origin.
  // Sized first and written in place (push_back is not inlined: a call per face).
  out.origins.resize(source.size());
  FacetOrigin* const origin = out.origins.data();
  for (std::size_t i = 0; i < source.size(); ++i)
    origin[i] = source[i] >= 0 ? facets.origins[source[i]] : FacetOrigin{FacetKind::edge, {}, {}};
  return out;
}

}  // namespace

LabelledMesh sum_mesh(const Polytope& A, const Polytope& B, const SumFacets& facets) {
  return sum_mesh(A, B, facets, nullptr);
}

LabelledMesh sum_mesh(const Polytope& A, const Polytope& B, SumFacets&& facets) {
  return sum_mesh(A, B, facets, &facets.origins);
}

Polytope sum_polytope(const Polytope& A, const Polytope& B, const SumFacets& facets) {
  std::vector<std::uint64_t> pairs;
  std::vector<int> corners;
  index_vertices(facets, A.num_vertices(), B.num_vertices(), pairs, corners);
  std::vector<V3<double>> points(pairs.size());
  if (!A.exact_points.empty() || !B.exact_points.empty())
    throw error("internal error: an exact sum needs operands with double points");
  // Sums of doubles are dyadic: exact with denominator 1.
  ExactPoints exact;
  exact.resize(pairs.size());
  // (Each vertex and each facet on its own: in parallel, Mpzf sums and Newell normals being
  // most of the time; a closing of a UV sphere goes through here.)
  parallel_chunks(static_cast<int>(pairs.size()), 1024, [&](int begin, int end) {
    for (int v = begin; v < end; ++v) {
      const V3<double>&a = A.points[pair_first(pairs[v])], &b = B.points[pair_second(pairs[v])];
      const V3<ExactN> x = to_exact_n(a) + to_exact_n(b);
      exact.numerator[v] = x;
      exact.denominator[v] = ExactN(1);
      exact.enclosure[v] = {Interval(x.x.to_interval()), Interval(x.y.to_interval()),
                            Interval(x.z.to_interval())};
      points[v] = {a.x + b.x, a.y + b.y, a.z + b.z};  // correctly rounded, as in sum_mesh
    }
  });
  std::vector<std::vector<int>> faces(facets.num_faces());
  std::vector<V3<ExactN>> normals(facets.num_faces());
  parallel_chunks(facets.num_faces(), 256, [&](int begin, int end) {
    for (int f = begin; f < end; ++f) {
      faces[f].assign(corners.begin() + facets.face_begin[f],
                      corners.begin() + facets.face_begin[f + 1]);
      const std::vector<int>& cycle = faces[f];
      normals[f] = newell_normal<ExactN>(
          static_cast<int>(cycle.size()),
          [&](int i) -> const V3<ExactN>& { return exact.numerator[cycle[i]]; });
    }
  });
  Polytope p =
      make_polytope(std::move(points), std::move(exact), faces, std::move(normals), "A (+) B");
  p.sum_pairs = std::move(pairs);  // vertex_source indexes them
  return p;
}

}  // namespace morph::detail

namespace morph {

LabelledMesh minkowski_sum(const Mesh& A, const Mesh& B, const MinkowskiOptions& options) {
  return detail::run_with_threads(options.threads, [&] {
    const detail::Operands op = detail::make_operands(A, B);
    return detail::sum_mesh(op.a, op.b, detail::fims_facets(op.a, op.b));
  });
}

}  // namespace morph
