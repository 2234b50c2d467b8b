// The last step of every operation: from an exact result (facet cycles over rounded
// points) to a clean mesh, merging features below double precision.
//
// Three passes, each linear in the size of the result:
//   1. corners of a facet closer than the feature size are merged (clusters); a facet
//      folded onto itself by that (a needle whose short diagonal merged) loses its loops of
//      fewer than three corners, when the points are finer than the feature size;
//   2. adjacent facets that are coplanar to within the feature size are grouped, and a
//      facet thinner than the feature size (a needle: two nearly parallel edges of the
//      operands summed) joins a neighbour it is flat against;
//   3. each group becomes one polygon (its boundary), and vertices left with fewer than
//      three groups around them (inside a merged facet or in the middle of an edge) go.
// When the facets no longer describe a closed manifold after pass 1 or a merged polygon
// is not convex to within the feature size, the mesh is rebuilt instead from the convex
// hull of the points (exact predicates), whose exact facets go through passes 2 and 3.
// Edges are matched into twins once (`connect`); the merged polygons' twins are read off
// those and only checked (`connect_with`).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>
#include <morph/error.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>
#include <queue>
#include <type_traits>

#include "double_pair.h"
#include "fims.h"
#include "parallel.h"
#include "union_find.h"

namespace morph::detail {

namespace {

/// Polygons over point indices, with the result facet each came from (-1: none).
struct Soup {
  std::vector<int> begin{0};
  std::vector<int> vertex;
  std::vector<int> source;
  int size() const { return static_cast<int>(begin.size()) - 1; }
  int degree(int f) const { return begin[f + 1] - begin[f]; }
  void add(const std::vector<int>& cycle, int src) {
    vertex.insert(vertex.end(), cycle.begin(), cycle.end());
    begin.push_back(static_cast<int>(vertex.size()));
    source.push_back(src);
  }
};

/// An array of ints left uninitialised (std::vector zero-fills): the per-corner arrays
/// below are written in full before they are read, and filling them with zeros first
/// costs about as much as the passes that write them.
class Ints {
 public:
  Ints() = default;
  explicit Ints(int n) : data_(std::make_unique_for_overwrite<int[]>(n)) {}
  int& operator[](int i) { return data_[i]; }
  int operator[](int i) const { return data_[i]; }
  int* data() { return data_.get(); }
  const int* data() const { return data_.get(); }

 private:
  std::unique_ptr<int[]> data_;
};

/// Halfedge connectivity of a soup: corner c is the edge from vertex[c] to the next
/// corner's vertex; twin[c] the corner of the opposite edge.
struct Connectivity {
  Ints face, next, prev, twin;
  // The last corner (in soup order) leaving each point (-1: none): a vertex's halfedge in
  // the OpenMesh build, set once per vertex rather than at each of its corners.
  Ints last_out;
  // `connect`'s only: where each point's outgoing corners start in its counting sort (of
  // num_points + 1 elements), so point v has out_begin[v + 1] - out_begin[v] of them.
  std::vector<int> out_begin;
};

// Chunk sizes of the parallel loops: large enough that a chunk pays for its task, small
// enough that a result of a few thousand facets is split between two threads. The corner
// and vertex loops are light (a few loads and stores per element) and their output is read
// by the next serial step, which then waits on the other core's cache: split finer (2048
// corners, 1024 vertices), they made icosphere_320 (+) icosphere_1280 slower at two threads
// than at one (sum_mesh 230 us against 202 us; 218 us with these).
constexpr int kFacetGrain = 512;
constexpr int kCornerGrain = 8192;
constexpr int kVertexGrain = 4096;
// Loops that do more per element (a plane test per edge, a walk around each vertex) pay
// for their task in smaller chunks.
constexpr int kEdgeTestGrain = 2048;
constexpr int kFanGrain = 512;

/// The facet, next and previous corner of every corner (no twins yet).
Connectivity facet_cycles(const Soup& soup) {
  const int nc = static_cast<int>(soup.vertex.size());
  Connectivity k{Ints(nc), Ints(nc), Ints(nc), {}, {}, {}};
  parallel_chunks(soup.size(), kFacetGrain, [&](int first, int last) {
    // Plain pointers: the writes through them could alias the captured arrays' own pointers.
    int *face = k.face.data(), *next = k.next.data(), *prev = k.prev.data();
    const int* begin = soup.begin.data();
    for (int f = first; f < last; ++f) {
      const int b = begin[f], e = begin[f + 1];
      if (e - b == 3) {  // most facets: straight-line code (the loop's vector code is slower)
        face[b] = face[b + 1] = face[b + 2] = f;
        next[b] = b + 1, next[b + 1] = b + 2, next[b + 2] = b;
        prev[b] = b + 2, prev[b + 1] = b, prev[b + 2] = b + 1;
        continue;
      }
      if (e - b == 4) {
        face[b] = face[b + 1] = face[b + 2] = face[b + 3] = f;
        next[b] = b + 1, next[b + 1] = b + 2, next[b + 2] = b + 3, next[b + 3] = b;
        prev[b] = b + 3, prev[b + 1] = b, prev[b + 2] = b + 1, prev[b + 3] = b + 2;
        continue;
      }
      if (b == e) continue;
      for (int c = b; c < e; ++c) {
        face[c] = f;
        next[c] = c + 1;
        prev[c] = c - 1;
      }
      next[e - 1] = b;
      prev[b] = e - 1;
    }
  });
  return k;
}

/// A corner leaving a vertex, with what the vertex's fan in `connect` reads of it: the point
/// its edge goes to, and the corner before it (whose edge ends at the vertex) with that
/// corner's point.
struct OutCorner {
  int corner, to, before, from;
};

/// `connect`'s fan of a vertex with N outgoing corners `o` (at place `b` of its counting
/// sort), N known at compile time: the loops are unrolled and the walk around the vertex
/// takes its N steps without a branch. The vertices' numbers of corners follow no pattern,
/// and the exits of loops of that many steps were mispredicted about once per loop and
/// vertex. The same result as the loops of any length (see `connect`).
template <int N>
bool fixed_fan(const OutCorner* o, int b, int* mark, int* twin) {
  for (int i = 0; i < N; ++i) {
    int& e = mark[o[i].to];
    if (e >= b) return false;  // v -> w twice
    e = b + i;
  }
  int place[N];  // twin[prev[o[i].corner]] is o[place[i]].corner
  for (int i = 0; i < N; ++i) {
    const int t = mark[o[i].from] - b;
    if (t < 0) return false;  // u -> v has no opposite edge
    twin[o[i].before] = o[t].corner;
    place[i] = t;
  }
  // One fan: the walk is back at the first corner after N steps, and not before.
  int i = 0;
  bool early = false;
  for (int step = 1; step < N; ++step) {
    i = place[i];
    early |= i == 0;
  }
  return !early && place[i] == 0;
}

/// Twins of every corner, or nothing when the soup is not a closed, oriented 2-manifold
/// (an edge used twice in one direction or only once, a vertex with several fans).
/// Also the last corner (in soup order) leaving each point (-1: none).
std::optional<Connectivity> connect(int num_points, const Soup& soup) {
  const int nc = static_cast<int>(soup.vertex.size());
  Connectivity k = facet_cycles(soup);
  k.twin = Ints(nc);  // each corner's twin is set below (each is the prev of one corner)
  k.last_out = Ints(num_points);
  // Outgoing corners of each vertex (counting sort), each with what its vertex's fan reads
  // of it: the point its edge goes to, and the corner before it (whose edge ends at the
  // vertex) with that corner's point. Read here in corner order, near each other, rather
  // than by chains of loads from the sorted corners in the fans below.
  using Out = OutCorner;
  std::vector<int>& out_begin = k.out_begin;
  out_begin.assign(num_points + 1, 0);
  const auto out = std::make_unique_for_overwrite<Out[]>(nc);
  {
    const int *vertex = soup.vertex.data(), *next = k.next.data(), *prev = k.prev.data();
    int* const end = out_begin.data();
    for (int c = 0; c < nc; ++c) ++end[vertex[c]];
    std::partial_sum(end, end + num_points + 1, end);  // ends, until filled
    for (int c = nc - 1; c >= 0; --c) {
      const int d = prev[c];
      out[--end[vertex[c]]] = {c, vertex[next[c]], d, vertex[d]};
    }
  }
  // By place in `out`: the place of the next edge leaving the same vertex around it.
  Ints turn(nc);
  // Vertices are independent (each writes the twins of the edges ending at it): in parallel.
  std::atomic<bool> manifold{true};
  parallel_chunks(num_points, kVertexGrain, [&](int first, int last) {
    // Each corner d ending at v (u -> v) precedes one leaving v; its twin is the edge
    // v -> u, looked up by its end while the edges leaving v are marked (by their place in
    // `out`: the vertices come in order, so a mark below v's first place is an earlier
    // vertex's, and none needs clearing).
    std::vector<int> edge_to(num_points, -1);
    // Plain pointers: the writes through them could alias the captured arrays' own pointers.
    const Out* const order = out.get();
    int *twin = k.twin.data(), *place = turn.data(), *mark = edge_to.data();
    int* const last_out = k.last_out.data();
    const int* const begin = out_begin.data();
    const auto fan = [&](int v) {
      const int b = begin[v], n = begin[v + 1] - b;
      const Out* const o = order + b;
      last_out[v] = n > 0 ? o[n - 1].corner : -1;  // the sort keeps soup order
      // The usual numbers of corners around a vertex: unrolled. Tested in a chain, most
      // frequent first (4 and 3 on sums of quadrilateral-rich and triangulated operands),
      // rather than by a switch's indirect jump, which was mispredicted more often.
      if (n == 4) return fixed_fan<4>(o, b, mark, twin);
      if (n == 3) return fixed_fan<3>(o, b, mark, twin);
      if (n == 5) return fixed_fan<5>(o, b, mark, twin);
      if (n == 6) return fixed_fan<6>(o, b, mark, twin);
      if (n == 0) return true;
      if (n == 7) return fixed_fan<7>(o, b, mark, twin);
      if (n == 8) return fixed_fan<8>(o, b, mark, twin);
      for (int i = 0; i < n; ++i) {
        int& e = mark[o[i].to];
        if (e >= b) return false;  // v -> w twice
        e = b + i;
      }
      for (int i = 0; i < n; ++i) {
        const int t = mark[o[i].from] - b;
        if (t < 0) return false;  // u -> v has no opposite edge
        twin[o[i].before] = o[t].corner;
        place[b + i] = t;  // twin[prev[out[b + i]]] is out[b + t]
      }
      // One fan per vertex: turning from an outgoing edge to the next (over the twin of the
      // edge before it) reaches them all.
      int i = 0, steps = 0;
      do {
        i = place[b + i];
        if (++steps > n) return false;
      } while (i != 0);
      return steps == n;
    };
    for (int v = first; v < last; ++v)
      if (!fan(v)) return manifold.store(false, std::memory_order_relaxed);
  });
  if (!manifold.load()) return std::nullopt;
  return k;
}

/// A facet's plane and size in doubles. (No member initialisers: an array of them is left
/// uninitialised until `geometry` fills it.)
struct FacetGeometry {
  V3<double> normal;  // unit (zero for a facet of zero area)
  double offset;      // <normal, x> = offset on the plane
  double twice_area;
  double longest_edge;
};

/// A facet's geometry from its first corner (`origin`), Newell's normal (`sum`, twice the
/// vector area), the sum of its corners' offsets from the origin, its longest squared edge
/// and its degree.
FacetGeometry finish_geometry(const V3<double>& origin, const V3<double>& sum, V3<double> centroid,
                              double longest_squared, int d) {
  FacetGeometry g{};  // zeros
  // Both roots in one instruction and the six divisions in three, two lanes at a time: a
  // lane of a packed root or quotient is the scalar one (IEEE), and the unit that does them
  // takes as long for two lanes as for one (they were most of this function's time).
  const Pair roots = pair_sqrt(Pair{longest_squared, dot(sum, sum)});
  g.longest_edge = roots[0];
  g.twice_area = roots[1];
  if (g.twice_area > 0) {
    const double area = g.twice_area;
    const Pair xy = Pair{sum.x, sum.y} / Pair{area, area};
    if (d == 4) {  // x * 0.25 is x / 4 (both exact or both the same rounding), and cheaper
      g.normal = {xy[0], xy[1], sum.z / area};
      centroid = {origin.x + centroid.x * 0.25, origin.y + centroid.y * 0.25,
                  origin.z + centroid.z * 0.25};
    } else {
      const double n = d;
      const Pair zx = Pair{sum.z, centroid.x} / Pair{area, n};
      const Pair yz = Pair{centroid.y, centroid.z} / Pair{n, n};
      g.normal = {xy[0], xy[1], zx[0]};
      centroid = {origin.x + zx[1], origin.y + yz[0], origin.z + yz[1]};
    }
    g.offset = dot(g.normal, centroid);
  }
  return g;
}

/// Any facet's geometry: Newell's sums about its first corner.
FacetGeometry geometry(const std::vector<V3<double>>& points, const Soup& soup, int f) {
  const int b = soup.begin[f], d = soup.degree(f);
  const V3<double>& origin = points[soup.vertex[b]];
  V3<double> sum{0, 0, 0}, centroid{0, 0, 0};
  double longest_squared = 0;  // the root is monotonic: the root of the maximum is the maximum root
  V3<double> p{0, 0, 0};       // the corner's offset from the origin (each computed once)
  for (int k = 0; k < d; ++k) {
    const V3<double> q = k + 1 == d ? V3<double>{0, 0, 0} : points[soup.vertex[b + k + 1]] - origin;
    sum = sum + cross(p, q);  // Newell's normal (twice the vector area)
    const V3<double> e = q - p;
    longest_squared = max_of(longest_squared, dot(e, e));
    centroid = centroid + p;
    p = q;
  }
  return finish_geometry(origin, sum, centroid, longest_squared, d);
}

/// v + 0 componentwise: v, with zeros made positive (as 0 + v, which `geometry`'s sums start
/// with).
/// Also per lane, for geometry_pair's pairs (a double added to a Pair goes to both lanes).
template <class T>
V3<T> plus_zero(const V3<T>& v) {
  return {v.x + 0.0, v.y + 0.0, v.z + 0.0};
}

/// The finite limit that the sums' checks below compare with (NaN and infinities fail).
constexpr double kLargest = std::numeric_limits<double>::max();

/// `geometry` of a triangle, without its terms known to be zeros. In `geometry`, the first
/// and last cross products have a zero vector as a factor: with finite offsets q1, q2 of the
/// corners, they are zeros of either sign, and the sum is 0 + cross(q1, q2) (adding a zero
/// to a sum that is not -0 changes nothing); the offsets' sum is 0 + q1 + q2, and the last
/// edge, 0 - q2, has the squares of q2. A component of cross(q1, q2) is a difference of
/// products of every component of q1 and q2: finite only when they are, so a sum that is
/// not finite (or whose squares overflow) takes `geometry` itself. (The same values, but
/// for the signs of NaNs, which no comparison reads.)
FacetGeometry triangle_geometry(const std::vector<V3<double>>& points, const Soup& soup, int f) {
  const int* const v = soup.vertex.data() + soup.begin[f];
  const V3<double>& origin = points[v[0]];
  const V3<double> q1 = points[v[1]] - origin, q2 = points[v[2]] - origin;
  const V3<double> sum = plus_zero(cross(q1, q2));
  if (!(dot(sum, sum) <= kLargest)) return geometry(points, soup, f);
  const V3<double> e = q2 - q1;
  const double longest_squared = max_of(max_of(max_of(0.0, dot(q1, q1)), dot(e, e)), dot(q2, q2));
  return finish_geometry(origin, sum, plus_zero(q1) + q2, longest_squared, 3);
}

/// `geometry` of a quadrilateral, as triangle_geometry: the sum is (0 + cross(q1, q2)) +
/// cross(q2, q3) (not -0: a sum is -0 only of two -0), finite only when both terms are.
FacetGeometry quad_geometry(const std::vector<V3<double>>& points, const Soup& soup, int f) {
  const int* const v = soup.vertex.data() + soup.begin[f];
  const V3<double>& origin = points[v[0]];
  const V3<double> q1 = points[v[1]] - origin, q2 = points[v[2]] - origin,
                   q3 = points[v[3]] - origin;
  const V3<double> sum = plus_zero(cross(q1, q2)) + cross(q2, q3);
  if (!(dot(sum, sum) <= kLargest)) return geometry(points, soup, f);
  const V3<double> e1 = q2 - q1, e2 = q3 - q2;
  const double longest_squared =
      max_of(max_of(max_of(max_of(0.0, dot(q1, q1)), dot(e1, e1)), dot(e2, e2)), dot(q3, q3));
  return finish_geometry(origin, sum, (plus_zero(q1) + q2) + q3, longest_squared, 4);
}

/// Any facet's geometry by the function for its degree (the same values as `geometry`'s).
FacetGeometry facet_geometry(const std::vector<V3<double>>& points, const Soup& soup, int f) {
  const int d = soup.degree(f);
  return d == 3   ? triangle_geometry(points, soup, f)
         : d == 4 ? quad_geometry(points, soup, f)
                  : geometry(points, soup, f);
}

/// The geometry of two facets from their lanes (`geo[0]` and `geo[1]`): zeros, as
/// finish_geometry leaves them, for a lane without area.
void store_pair(Pair longest, Pair area, const V3<Pair>& normal, Pair offset, FacetGeometry* geo) {
  for (int i = 0; i < 2; ++i) {
    FacetGeometry& g = geo[i];
    g = FacetGeometry{};  // zeros
    g.longest_edge = longest[i];
    g.twice_area = area[i];
    if (g.twice_area > 0) {
      g.normal = {normal.x[i], normal.y[i], normal.z[i]};
      g.offset = offset[i];
    }
  }
}

/// triangle_geometry (Degree 3) or quad_geometry (4) of facets f and f + 1 at once, one in
/// each lane: each lane's operations are those of the one-facet function (a lane of a
/// packed operation is the scalar one, IEEE), in about half the instructions. A lane whose
/// facet has no area is given zeros as the one-facet function would (its quotients are
/// not used); a sum that is not finite takes the one-facet functions.
/// Also pass 1's filter of the two facets (`surely_apart` in clean_mesh), from the points
/// loaded once: whether each is apart, no pair of its corners within `far` (squared) nor
/// repeated. A corner's offset from the first, q = p - origin, is the negation of
/// origin - p (IEEE rounding is symmetric), so dot(q, q) is that pair's squared distance.
template <int Degree>
std::array<bool, 2> geometry_pair(const std::vector<V3<double>>& points, const Soup& soup, int f,
                                  FacetGeometry* geo, double far = 0) {
  const int* const v = soup.vertex.data() + soup.begin[f];
  const int* const w = v + Degree;  // facet f + 1's corners follow f's
  const auto load = [&](int k) {
    const V3<double>&p = points[v[k]], &q = points[w[k]];
    return V3<Pair>{Pair{p.x, q.x}, Pair{p.y, q.y}, Pair{p.z, q.z}};
  };
  const auto squared = [](const V3<Pair>& p, const V3<Pair>& q) {
    const V3<Pair> d = p - q;
    return dot(d, d);
  };
  const Pair zero{0, 0}, bound{far, far};
  const V3<Pair> origin = load(0), p1 = load(1), p2 = load(2);
  const V3<Pair> q1 = p1 - origin, q2 = p2 - origin;
  const Pair s1 = dot(q1, q1), s2 = dot(q2, q2);
  auto near = (s1 <= bound) | (s2 <= bound) | (squared(p1, p2) <= bound);
  V3<Pair> sum, centroid;
  Pair longest_squared;
  if constexpr (Degree == 3) {
    sum = plus_zero(cross(q1, q2));
    const V3<Pair> e = q2 - q1;
    longest_squared = pair_max(pair_max(pair_max(zero, s1), dot(e, e)), s2);
    centroid = plus_zero(q1) + q2;
  } else {
    const V3<Pair> p3 = load(3);
    const V3<Pair> q3 = p3 - origin;
    const Pair s3 = dot(q3, q3);
    near |= (s3 <= bound) | (squared(p1, p3) <= bound) | (squared(p2, p3) <= bound);
    sum = plus_zero(cross(q1, q2)) + cross(q2, q3);
    const V3<Pair> e1 = q2 - q1, e2 = q3 - q2;
    longest_squared =
        pair_max(pair_max(pair_max(pair_max(zero, s1), dot(e1, e1)), dot(e2, e2)), s3);
    centroid = (plus_zero(q1) + q2) + q3;
  }
  const auto repeated = [](const int* u) {
    if constexpr (Degree == 3) return (u[0] == u[1]) | (u[0] == u[2]) | (u[1] == u[2]);
    return (u[0] == u[1]) | (u[0] == u[2]) | (u[0] == u[3]) | (u[1] == u[2]) | (u[1] == u[3]) |
           (u[2] == u[3]);
  };
  const std::array<bool, 2> apart{!(near[0] | repeated(v)), !(near[1] | repeated(w))};
  const Pair squared_area = dot(sum, sum);
  if (!(squared_area[0] <= kLargest) || !(squared_area[1] <= kLargest)) {
    for (int g = f; g < f + 2; ++g)
      geo[g] = Degree == 3 ? triangle_geometry(points, soup, g) : quad_geometry(points, soup, g);
    return apart;
  }
  const Pair longest = pair_sqrt(longest_squared), area = pair_sqrt(squared_area);
  const V3<Pair> normal{sum.x / area, sum.y / area, sum.z / area};
  if constexpr (Degree == 3) {
    const Pair n{3, 3};
    centroid = {origin.x + centroid.x / n, origin.y + centroid.y / n, origin.z + centroid.z / n};
  } else {  // x * 0.25 is x / 4, as in finish_geometry
    const Pair quarter{0.25, 0.25};
    centroid = {origin.x + centroid.x * quarter, origin.y + centroid.y * quarter,
                origin.z + centroid.z * quarter};
  }
  store_pair(longest, area, normal, dot(normal, centroid), geo + f);
  return apart;
}

/// `geometry` of facets f and f + 1 at once, one in each lane, for polygons of any degrees
/// (each lane's operations are `geometry`'s: about half the instructions). The lane of the
/// facet with fewer corners goes on after its last one with zero offsets, which change
/// nothing in round-to-nearest (the mode the library runs in): their terms are +0, the
/// sums, begun at +0, are never -0 (a sum is -0 only of two -0), so adding +0 leaves them,
/// and the longest edge's maximum with +0 is the maximum (or its NaN) as it was.
void geometry_pair_any(const std::vector<V3<double>>& points, const Soup& soup, int f,
                       FacetGeometry* geo) {
  const int* const begin = soup.begin.data();
  const int* const u = soup.vertex.data() + begin[f];
  const int* const w = soup.vertex.data() + begin[f + 1];
  const int du = begin[f + 1] - begin[f], dw = begin[f + 2] - begin[f + 1];
  const int both = std::min(du, dw), d = std::max(du, dw);
  const V3<double>&ou = points[u[0]], &ow = points[w[0]];
  const V3<Pair> origin{Pair{ou.x, ow.x}, Pair{ou.y, ow.y}, Pair{ou.z, ow.z}};
  const Pair zero{0, 0};
  V3<Pair> sum{zero, zero, zero}, centroid{zero, zero, zero}, p{zero, zero, zero};
  Pair longest_squared = zero;
  // Offset of corner k of one lane from its first (+0 from its last corner on).
  const auto offset = [&](const int* v, int dv, int k, const V3<double>& o) {
    return k < dv ? points[v[k]] - o : V3<double>{0, 0, 0};
  };
  for (int k = 0; k < d; ++k) {
    V3<Pair> q;
    if (k + 1 < both) {
      const V3<double>&a = points[u[k + 1]], &b = points[w[k + 1]];
      q = V3<Pair>{Pair{a.x, b.x}, Pair{a.y, b.y}, Pair{a.z, b.z}} - origin;
    } else {
      const V3<double> a = offset(u, du, k + 1, ou), b = offset(w, dw, k + 1, ow);
      q = V3<Pair>{Pair{a.x, b.x}, Pair{a.y, b.y}, Pair{a.z, b.z}};
    }
    sum = sum + cross(p, q);
    const V3<Pair> e = q - p;
    longest_squared = pair_max(longest_squared, dot(e, e));
    centroid = centroid + p;
    p = q;
  }
  const Pair longest = pair_sqrt(longest_squared), area = pair_sqrt(dot(sum, sum));
  // finish_geometry's operations (x * 0.25 for a quadrilateral is x / 4 there).
  const V3<Pair> normal{sum.x / area, sum.y / area, sum.z / area};
  const Pair n{static_cast<double>(du), static_cast<double>(dw)};
  centroid = {origin.x + centroid.x / n, origin.y + centroid.y / n, origin.z + centroid.z / n};
  store_pair(longest, area, normal, dot(normal, centroid), geo + f);
}

bool is_thin(const FacetGeometry& g, double limit) {
  return g.twice_area <= 2 * limit * g.longest_edge;
}

struct Groups {
  std::vector<int> of;           // group (its lowest facet index) of each facet
  std::vector<int> next_member;  // the members of group g: g, next_member[g], ... until -1
  bool merged = false;
};

/// The edges (by their first corners) whose two facets, each alone, pass group_coplanar's
/// test, in ascending blocks of corners.
using PassedEdges = std::vector<std::vector<int>>;

/// Groups facets that are coplanar to within `limit`: a facet joins a neighbour's group
/// when all its vertices lie within `limit` of the plane of the group's largest facet,
/// or the group joins it the other way round. Needles (facets thinner than `limit`) have
/// no reliable plane of their own; they join a neighbour whose plane holds them. A facet
/// marked in `alone_only` (empty: none) stays a group of its own. `passed`: the edges that
/// pass with both facets alone, found here when unset (they do not depend on
/// `alone_only`), and kept for the next call on the same soup.
Groups group_coplanar(const std::vector<V3<double>>& points, const Soup& soup,
                      const Connectivity& k, const FacetGeometry* geo, double limit,
                      const std::vector<char>& alone_only, std::optional<PassedEdges>& passed) {
  const auto may_join = [&](int f) { return alone_only.empty() || !alone_only[f]; };
  const int nf = soup.size();
  Groups out;
  std::vector<int>& next_member = out.next_member;
  next_member.assign(nf, -1);
  // Plain pointers: loaded once, not through the captures for each test.
  const V3<double>* const point = points.data();
  const int *const vertex = soup.vertex.data(), *const begin = soup.begin.data();
  // All vertices of facet `g`, a group alone, within `limit` of the plane of facet `ref`;
  // `edge`: g's corner on the edge that the two share. Its corners from the one after the
  // shared edge on, as the edge's ends are on the plane when the groups already meet
  // there. Which corner fails first does not change the answer.
  const auto holds_alone = [=](int ref, int g, int edge) {
    const FacetGeometry& p = geo[ref];
    if (is_thin(p, limit)) return false;
    // A facet's corners are consecutive (next is the one after, or the first after the
    // last): found so rather than through `next`, whose loads would delay the first test.
    const int b = begin[g], e = begin[g + 1], d = e - b;
    int c = edge + 2 >= e ? edge + 2 - d : edge + 2;  // d >= 3
    for (int i = 0; i < d; ++i, c = c + 1 == e ? b : c + 1)
      if (std::abs(dot(p.normal, point[vertex[c]]) - p.offset) > limit) return false;
    return true;
  };
  // All vertices of group `g` within `limit` of the plane of facet `ref`; `edge`: g's corner
  // on the edge that the two groups share.
  auto holds = [&](int ref, int g, int edge) {
    if (next_member[g] < 0) return holds_alone(ref, g, edge);  // one facet, named by it
    const FacetGeometry& p = geo[ref];
    if (is_thin(p, limit)) return false;
    for (int f = g; f >= 0; f = next_member[f])
      for (int c = begin[f]; c < begin[f + 1]; ++c)
        if (std::abs(dot(p.normal, point[vertex[c]]) - p.offset) > limit) return false;
    return true;
  };
  const int nc = static_cast<int>(soup.vertex.size());
  // The groups are those of testing every edge (by its first corner) in order. While both
  // facets of an edge are alone (each its own group and reference), its test reads only
  // the two facets, not what the joins before it made: every edge is so tested beforehand,
  // in parallel, in fixed blocks of corners; the loop below then takes, in order, the
  // edges that passed (`passed`, few) and the later edges of each facet that joins a group
  // (`later`), whose test depends on the joins. An edge in neither has both facets alone
  // when its turn comes, and failed: it joins nothing. The test does not read `alone_only`
  // (join does): a second call, with more facets marked, reuses it (an opening of icosphere
  // level 6 by its rotated copy: 30 ms of random loads over 800,000 edges, for 180 passed).
  if (!passed) {
    passed.emplace((nc + kEdgeTestGrain - 1) / kEdgeTestGrain);
    parallel_chunks(static_cast<int>(passed->size()), 1, [&](int first_block, int last_block) {
      const int *twin = k.twin.data(), *face = k.face.data(), *prev = k.prev.data();
      for (int block = first_block; block < last_block; ++block)
        for (int c = block * kEdgeTestGrain; c < std::min(nc, (block + 1) * kEdgeTestGrain); ++c) {
          const int t = twin[c];
          if (t < c) continue;
          int a = face[c], b = face[t];
          int edge_b = t;
          if (geo[a].twice_area < geo[b].twice_area) {
            std::swap(a, b);
            edge_b = c;
          }
          // First b's point before the edge (off it), alone: holds_alone fails when any of
          // b's points is off a's plane, as nearly every edge does, and this point takes
          // fewer loads in a row than holds_alone's first. (Every facet is alone before the
          // joins.)
          const FacetGeometry& p = geo[a];
          if (std::abs(dot(p.normal, point[vertex[prev[edge_b]]]) - p.offset) > limit) continue;
          if (a != b && holds_alone(a, b, edge_b)) (*passed)[block].push_back(c);
        }
    });
  }
  out.of.resize(nf);
  if (std::all_of(passed->begin(), passed->end(), [](const auto& b) { return b.empty(); })) {
    // No edge passed (the usual case): no joins, each facet its own group, and the sets
    // below are not needed.
    std::iota(out.of.begin(), out.of.end(), 0);
    return out;
  }
  UnionFind sets(nf);
  std::vector<int> reference(nf), last_member(nf);
  std::iota(reference.begin(), reference.end(), 0);
  std::iota(last_member.begin(), last_member.end(), 0);
  std::vector<char> alone(nf, 1);
  std::priority_queue<int, std::vector<int>, std::greater<>> later;
  // Each facet's edges after `c`, which it joined a group at.
  const auto retest = [&](int f, int c) {
    for (int e = soup.begin[f]; e < soup.begin[f + 1]; ++e)
      if (std::min(e, k.twin[e]) > c) later.push(std::min(e, k.twin[e]));
  };
  const auto join = [&](int c) {
    const int t = k.twin[c];
    if (!may_join(k.face[c]) || !may_join(k.face[t])) return;
    const bool tested = alone[k.face[c]] && alone[k.face[t]];
    int a = sets.find(k.face[c]), b = sets.find(k.face[t]);
    if (a == b) return;
    int edge_b = t;  // b's corner on the edge
    if (geo[reference[a]].twice_area < geo[reference[b]].twice_area) {
      std::swap(a, b);
      edge_b = c;
    }
    // a has the larger reference facet.
    if (!tested && !holds(reference[a], b, edge_b)) return;
    const int root = std::min(a, b), other = std::max(a, b);
    sets.unite(a, b);  // names the joined set `root`
    reference[root] = reference[a];
    next_member[last_member[root]] = other;
    last_member[root] = last_member[other];
    for (const int g : {a, b})
      if (alone[g]) {
        alone[g] = 0;
        retest(g, c);
      }
    out.merged = true;
  };
  int done = -1;  // the last edge taken
  for (const std::vector<int>& block : *passed)
    for (const int c : block) {
      for (; !later.empty() && later.top() <= c; later.pop())
        if (later.top() > done) join(done = later.top());
      if (c > done) join(done = c);
    }
  for (; !later.empty(); later.pop())
    if (later.top() > done) join(done = later.top());
  for (int f = 0; f < nf; ++f) out.of[f] = sets.find(f);
  return out;
}

/// Corner (interior angle) test of a polygon against its plane's normal: no corner is
/// reflex by more than `limit`.
bool convex_polygon(const std::vector<V3<double>>& points, const int* cycle, int d,
                    const V3<double>& normal, double limit) {
  // Each corner's incoming side is the previous corner's outgoing one (the same difference).
  const V3<double>* a = &points[cycle[0]];
  const V3<double>* b = &points[cycle[1 % d]];
  V3<double> ab = *b - *a;
  for (int i = 0; i < d; ++i) {
    const V3<double>& c = points[cycle[i + 2 < d ? i + 2 : i + 2 - d]];
    const V3<double> bc = c - *b;
    // Height of b over the chord a-c times the chord's length, positive when the corner
    // at b is convex; a convex corner (most) needs no division.
    const double scaled_height = dot(cross(ab, bc), normal);
    const V3<double>& corner_a = *a;
    a = b;
    b = &c;
    ab = bc;
    if (scaled_height >= 0) continue;
    const V3<double> ac = c - corner_a;
    const double base = std::sqrt(dot(ac, ac));
    if (base > 0 && scaled_height / base < -limit) return false;
  }
  return true;
}

/// The twins of a merged soup's corners, read off the unmerged soup's, and which of them
/// `connect_with` still has to check. A merged corner whose chain is one boundary corner
/// c, between two kept vertices, has the chain of twin[c] as its twin, also one corner:
/// they are mutual and reverse by construction. A kept vertex whose edges all separate two
/// groups and lead to kept vertices has, in the merged soup, the fan it had (each of its
/// corners one chain, turning from one to the next over the same twins), which `connect`
/// found to be one, with no edge twice. Only the other corners and vertices are checked.
struct MergedTwins {
  Ints twin;
  std::vector<int> check_corner;   // merged corners, ascending
  std::vector<char> check_vertex;  // per point
};

/// Passes 2 and 3 on a closed manifold soup: the polygons of its coplanar groups go to
/// `out` (`changed` tells whether any merged; `out` is untouched if not). False when a
/// group is not one disc, its polygon is not convex or keeps fewer than three corners;
/// `strict`: also when a needle finds no group. `geo`: each facet's geometry. Where a merged
/// group's polygon is not convex, its facets are marked in `alone_only` (group_coplanar),
/// and where a polygon keeps fewer than three corners, the merged facets around the corners
/// it lost: for the caller to try again with them left as they are (and `passed` as this
/// call leaves it).
bool merge_coplanar(const std::vector<V3<double>>& points, const Soup& soup, const Connectivity& k,
                    std::optional<PassedEdges>& passed, const FacetGeometry* geo, double limit,
                    bool strict, Soup& merged, MergedTwins& merged_twins, bool& changed,
                    std::vector<char>& alone_only) {
  const int nf = soup.size();
  const Groups groups = group_coplanar(points, soup, k, geo, limit, alone_only, passed);
  if (strict)
    for (int f = 0; f < nf; ++f)
      if (is_thin(geo[f], limit) && groups.of[f] == f) {
        bool alone = true;
        for (int c = soup.begin[f]; c < soup.begin[f + 1] && alone; ++c)
          alone = groups.of[k.face[k.twin[c]]] != f;
        if (alone) return false;
      }
  const int nc = static_cast<int>(soup.vertex.size());
  const int np = static_cast<int>(points.size());
  // Vertices keep their place when at least three groups meet there. A vertex on no facet
  // of a group of several has as many groups around it as it has outgoing corners: its fan
  // (one, `connect` checked) passes each outgoing corner once, each in its own facet (no
  // facet of the soups simplify gets has a point twice: clean_mesh sends those to the
  // hull, and the hull's polygons are simple), and each of those facets is its own group.
  // So when no group merged, something changes only if a vertex has one or two outgoing
  // corners (a vertex in the middle of an edge; 1 cannot happen in a closed manifold of
  // polygons), read off `connect`'s counting sort without walking any fan.
  const int* const out_begin = k.out_begin.data();
  changed = groups.merged;
  for (int v = 0; v < np && !changed; ++v) {
    const int n = out_begin[v + 1] - out_begin[v];
    changed = n > 0 && n < 3;
  }
  if (!changed) return true;
  Ints corner_group(nc);  // looked up several times per corner below
  parallel_chunks(nf, kFacetGrain, [&](int first, int last) {
    for (int f = first; f < last; ++f)
      std::fill(corner_group.data() + soup.begin[f], corner_group.data() + soup.begin[f + 1],
                groups.of[f]);
  });
  const auto group = [&](int c) { return corner_group[c]; };
  // Only the vertices on a facet of a group of several walk their fan to count the groups
  // around them (each its own: in parallel); the others count their outgoing corners.
  std::vector<char> walk;
  if (groups.merged) {
    walk.assign(np, 0);
    for (int f = 0; f < nf; ++f)
      if (groups.of[f] != f || groups.next_member[f] >= 0)
        for (int c = soup.begin[f]; c < soup.begin[f + 1]; ++c) walk[soup.vertex[c]] = 1;
  }
  std::vector<char> keep(np, 0);
  parallel_chunks(np, kFanGrain, [&](int first, int last) {
    for (int v = first; v < last; ++v) {
      const int n = out_begin[v + 1] - out_begin[v];
      if (n == 0) continue;
      if (walk.empty() || !walk[v]) {
        keep[v] = n >= 3;
        continue;
      }
      const int c = k.last_out[v];
      int g1 = -1, g2 = -1, distinct = 0, e = c;
      do {
        const int g = group(e);
        if (g != g1 && g != g2) {
          if (g1 < 0)
            g1 = g;
          else if (g2 < 0)
            g2 = g;
          ++distinct;
        }
        e = k.twin[k.prev[e]];
      } while (e != c && distinct < 3);
      keep[v] = distinct >= 3;
    }
  });
  // The boundary of each group, walked from its first boundary corner.
  Soup out;
  // No more polygons and corners than the soup's: filled up to `polygons` and `size`
  // (push_back, not inlined, costs more than the rest of the walk of a triangle).
  out.begin.resize(nf + 1);
  out.vertex.resize(nc);
  out.source.resize(nf);
  int polygons = 0, size = 0;
  // A merged corner is a chain of boundary corners from a kept vertex to the next. The
  // chain of its twin starts where the twin of its chain's last corner does.
  Ints chain_of(nc);   // boundary corner starting a chain -> merged corner
  Ints chain_end(nc);  // merged corner -> its chain's last boundary corner
  // Merged corners of more than one boundary corner, vertices with an edge inside a group
  // or to a vertex that goes: what connect_with checks (see MergedTwins).
  // (A merged corner is lengthened from the walk of its polygon only, in order: the list
  // has each once.)
  std::vector<int> long_chain;
  std::vector<char> check_vertex(np, 0);
  const auto lengthen = [&](int m, int c) {
    chain_end[m] = c;
    if (long_chain.empty() || long_chain.back() != m) long_chain.push_back(m);
    check_vertex[out.vertex[m]] = 1;
  };
  // The polygons that are not a facet as it is (a merged group, or a facet that lost a
  // vertex), with their group's largest facet: the only ones whose corners need a test. A
  // facet left as it is has no test when nothing merges either (the soup is kept then).
  std::vector<std::pair<int, int>> to_test;
  bool dropped = false;  // a polygon kept fewer than three corners (see below)
  // Plain pointers: the writes through them could alias the vectors' own pointers, which
  // would then be loaded again for each corner.
  const int* const vertex = soup.vertex.data();
  const char* const kept = keep.data();
  int *const out_vertex = out.vertex.data(), *const chain_of_data = chain_of.data(),
             *const chain_end_data = chain_end.data();
  // The facets with a vertex that goes (few: those around the vertices inside a merged
  // group or in the middle of an edge), found over the fans of those vertices. A facet that
  // is its own group and has none is its polygon as it is: runs of such facets are copied
  // whole below, rather than corner by corner.
  std::vector<char> touched(nf, 0);
  for (int v = 0; v < np; ++v) {
    if (keep[v] || out_begin[v + 1] == out_begin[v]) continue;
    const int c = k.last_out[v];
    int e = c, steps = 0;
    do {
      touched[k.face[e]] = 1;
      e = k.twin[k.prev[e]];
    } while (e != c && ++steps <= nc);
  }
  const auto plain = [&](int f) {
    return groups.of[f] == f && groups.next_member[f] < 0 && !touched[f];
  };
  const int* const soup_begin = soup.begin.data();
  for (int g = 0; g < nf; ++g) {
    if (groups.of[g] != g) continue;
    if (plain(g)) {
      // Facets g to h - 1: each keeps all its corners, in order, and its source.
      int h = g + 1;
      while (h < nf && plain(h)) ++h;
      const int b = soup_begin[g], e = soup_begin[h], shift = size - b;
      for (int c = b; c < e; ++c) {
        out_vertex[c + shift] = vertex[c];
        chain_of_data[c] = c + shift;
        chain_end_data[c + shift] = c;
      }
      for (int f = g; f < h; ++f) {
        if (soup_begin[f + 1] - soup_begin[f] < 3) return false;
        out.source[polygons] = soup.source[f];
        out.begin[++polygons] = soup_begin[f + 1] + shift;
      }
      size += e - b;
      g = h - 1;
      continue;
    }
    const int first = size;
    int before_first = -1;  // the last corner walked before the first kept one
    const auto add = [&](int c) {
      const int v = vertex[c];
      if (kept[v]) {
        chain_of_data[c] = size;
        out_vertex[size] = v;
        chain_end_data[size++] = c;
      } else if (size == first) {
        before_first = c;
      } else {
        lengthen(size - 1, c);
      }
    };
    if (groups.next_member[g] < 0) {
      // A facet alone is its own boundary cycle: none of its edges has its twin in it (a
      // soup's facets have three corners or more, none repeated, so the reverse of an edge
      // is in another facet).
      for (int c = soup.begin[g]; c < soup.begin[g + 1]; ++c) add(c);
      if (size - first != soup.degree(g)) to_test.emplace_back(polygons, g);
      out.source[polygons] = soup.source[g];
    } else {
      // The group's first boundary corner and its number of boundary corners, and its
      // largest facet (the first of the largest in facet order; g is the first member),
      // which gives its source, from its members.
      int start = nc, boundary = 0, largest = g;
      for (int f = g; f >= 0; f = groups.next_member[f]) {
        const double area = geo[f].twice_area, most = geo[largest].twice_area;
        if (area > most || (area == most && f < largest)) largest = f;
        for (int c = soup.begin[f]; c < soup.begin[f + 1]; ++c)
          if (group(k.twin[c]) != g) {
            start = std::min(start, c);
            ++boundary;
          }
      }
      if (boundary == 0) return false;  // a group without boundary: everything is flat
      to_test.emplace_back(polygons, largest);
      out.source[polygons] = soup.source[largest];
      int c = start, steps = 0, walked = 0;
      do {
        // More corners than the group's boundary has: the walk cannot end well (and the
        // merged corners stay within the soup's).
        if (++walked > boundary) return false;
        add(c);
        // The next boundary corner: turn around the edge's end inside the group.
        int n = k.next[c];
        if (group(k.twin[n]) == g) check_vertex[soup.vertex[n]] = 1;  // an edge inside g
        while (group(k.twin[n]) == g) {
          n = k.next[k.twin[n]];
          if (++steps > nc) return false;
        }
        c = n;
        if (++steps > nc) return false;
      } while (c != start);
      // Turning to the next boundary corner is a permutation of them (a closed manifold):
      // the walk missed some when the group has a second boundary cycle, so is not a disc.
      if (walked != boundary) return false;
    }
    const int d = size - first;
    if (d < 3) {
      // Fewer than three corners kept: each vertex that goes has fewer than three groups
      // around it, where a small facet lies between facets that merged, nearly coplanar (an
      // opening by a tiny element: a facet a few 1e-8 across at a crease whose two sides each
      // merged). The merged facets at those vertices stay as they are in the next try, so the
      // vertices keep their three groups; the rest of this walk goes on, to mark every such
      // place in one try. Nothing to mark: the caller's fallback.
      if (alone_only.empty()) alone_only.assign(nf, 0);
      for (int f = g; f >= 0; f = groups.next_member[f])
        for (int c = soup.begin[f]; c < soup.begin[f + 1]; ++c) {
          if (kept[vertex[c]]) continue;
          int e = c, steps = 0;
          do {
            const int h = k.face[e];
            if (groups.of[h] != h || groups.next_member[h] >= 0) alone_only[h] = 1;
            e = k.twin[k.prev[e]];
          } while (e != c && ++steps <= nc);
        }
      dropped = true;
      if (!to_test.empty() && to_test.back().first == polygons) to_test.pop_back();
      size = first;
      continue;
    }
    if (before_first >= 0) lengthen(size - 1, before_first);  // the chain wraps
    out.begin[++polygons] = size;
  }
  out.begin.resize(polygons + 1);
  out.source.resize(polygons);
  // Each polygon's corner test, against the plane of its group's largest facet:
  // independent, so in parallel, after the walks.
  std::atomic<bool> convex{true};
  std::vector<char> reflex(to_test.size(), 0);  // to_test[i]'s polygon is not convex
  parallel_chunks(static_cast<int>(to_test.size()), kFacetGrain, [&](int first, int last) {
    for (int i = first; i < last; ++i) {
      const auto [m, largest] = to_test[i];
      if (!convex_polygon(points, out.vertex.data() + out.begin[m], out.degree(m),
                          geo[largest].normal, limit)) {
        reflex[i] = 1;
        convex.store(false, std::memory_order_relaxed);
      }
    }
  });
  if (!convex.load() || dropped) {
    // Coplanar within the tolerance, yet their union bends by more than it (thin facets
    // of an opening's tiny eroded edges beside a large facet): those groups' facets stay
    // as they are in the next try, as the merged facets around lost corners (marked above).
    if (alone_only.empty()) alone_only.assign(nf, 0);
    for (std::size_t i = 0; i < to_test.size(); ++i) {
      const int g = groups.of[to_test[i].second];
      if (reflex[i] && groups.next_member[g] >= 0)
        for (int f = g; f >= 0; f = groups.next_member[f]) alone_only[f] = 1;
    }
    return false;
  }
  out.vertex.resize(size);
  merged_twins.twin = Ints(size);
  for (int m = 0; m < size; ++m) merged_twins.twin[m] = chain_of[k.twin[chain_end[m]]];
  merged_twins.check_corner = std::move(long_chain);
  merged_twins.check_vertex = std::move(check_vertex);
  merged = std::move(out);
  return true;
}

/// The connectivity of a soup with the given twin candidates, or nothing when they are not
/// those `connect` would find (it then decides): each candidate must be the reverse edge,
/// pairing must be mutual, and each vertex must have one fan with no two edges to one vertex.
/// Then the soup is a closed, oriented 2-manifold whose reverse edges are unique, so
/// `connect` would succeed with these twins. Only the corners and vertices that `merged`
/// marks are checked: the others pass by construction (see MergedTwins).
std::optional<Connectivity> connect_with(int num_points, const Soup& soup, MergedTwins&& merged) {
  const int nc = static_cast<int>(soup.vertex.size());
  Connectivity k = facet_cycles(soup);
  k.twin = std::move(merged.twin);
  std::atomic<bool> reverse{true};
  const std::vector<int>& check_corner = merged.check_corner;
  parallel_chunks(static_cast<int>(check_corner.size()), kCornerGrain, [&](int first, int last) {
    const int *vertex = soup.vertex.data(), *next = k.next.data(), *twin = k.twin.data();
    for (int i = first; i < last; ++i) {
      const int c = check_corner[i], t = twin[c];
      if (t < 0 || t >= nc || t == c || twin[t] != c || vertex[t] != vertex[next[c]] ||
          vertex[next[t]] != vertex[c]) {
        reverse.store(false, std::memory_order_relaxed);
        return;
      }
    }
  });
  if (!reverse.load()) return std::nullopt;
  std::vector<int> out_count(num_points, 0), marks(num_points, -1);
  k.last_out = Ints(num_points);
  std::fill_n(k.last_out.data(), num_points, -1);
  // Plain pointers: the writes through them could alias the arrays' own pointers.
  const int *vertex = soup.vertex.data(), *next = k.next.data(), *prev = k.prev.data(),
            *twins = k.twin.data();
  int *count = out_count.data(), *mark = marks.data(), *leaving = k.last_out.data();
  const char* check = merged.check_vertex.data();
  for (int c = 0; c < nc; ++c) {
    ++count[vertex[c]];
    leaving[vertex[c]] = c;
  }
  // The orbit below is the same cycle from any of its corners: the fans are checked from
  // whichever corner is at hand, point by point.
  for (int v = 0; v < num_points; ++v) {
    if (!check[v] || count[v] == 0) continue;  // its fan needs no check, or is not used
    const int s = leaving[v];
    // Turning from an outgoing edge to the next is a permutation of the corners leaving v:
    // one fan when its orbit holds all of them.
    int c = s, steps = 0;
    do {
      int& m = mark[vertex[next[c]]];
      if (m == v) return std::nullopt;  // v -> w twice
      m = v;
      c = twins[prev[c]];
      ++steps;
    } while (c != s && steps <= count[v]);
    if (steps != count[v] || c != s) return std::nullopt;
  }
  return k;
}

/// Each facet's geometry, in `geo` (of soup.size() elements).
void geometries(const std::vector<V3<double>>& points, const Soup& soup, FacetGeometry* geo) {
  parallel_chunks(soup.size(), kFacetGrain, [&](int first, int last) {
    // Triangles and quadrilaterals (nearly all facets, in long runs: the branch is
    // predicted) by straight-line code: the same operations in the same order, two facets
    // at once when two of one degree follow each other (geometry_pair: about 40% less time
    // for the facets' geometry than one at a time).
    const int* const begin = soup.begin.data();
    for (int f = first; f < last; ++f) {
      const int d = begin[f + 1] - begin[f];
      if (f + 1 < last && begin[f + 2] - begin[f + 1] == d && (d == 3 || d == 4)) {
        if (d == 3)
          geometry_pair<3>(points, soup, f, geo);
        else
          geometry_pair<4>(points, soup, f, geo);
        ++f;
        continue;
      }
      if (d >= 5 && f + 1 < last && begin[f + 2] - begin[f + 1] >= 5) {
        geometry_pair_any(points, soup, f, geo);  // two polygons (an erosion's, mostly)
        ++f;
        continue;
      }
      geo[f] = facet_geometry(points, soup, f);
    }
  });
}

/// What pass 2 starts from: the soup's connectivity (nothing when it is not a closed
/// manifold) and its facets' geometry, when they were found beforehand (`geo` set).
struct Prepared {
  bool connected = false;  // whether `k` was looked for
  std::optional<Connectivity> k;
  std::unique_ptr<FacetGeometry[]> geo;
};

/// Passes 2 and 3, then connectivity of the result. Strict: nothing when the soup is not
/// a closed manifold or merging fails; else (hull facets) an unmerged soup is kept.
/// `soup` is moved into the result when it is the result, and left alone otherwise.
/// `pre`: the soup's connectivity and geometry, if already found.
/// Whether the surface is convex within `limit` around the facets marked in `alone_only`:
/// at each of their corners, every vertex of the facets around the corner's vertex lies at
/// most `limit` above the plane of each of them (needles, with no plane of their own,
/// aside). Facets left unmerged because their group's polygon bent (merge_coplanar) pass
/// when that bend was rounding noise; a soup that is not convex there (an L-shaped prism:
/// its top's two halves are one plane, its inner side edge is reflex) does not, and goes to
/// the hull as before.
bool convex_around(const std::vector<V3<double>>& points, const Soup& soup, const Connectivity& k,
                   const FacetGeometry* geo, double limit, const std::vector<char>& alone_only) {
  std::vector<int> fan;
  for (int f = 0; f < soup.size(); ++f) {
    if (!alone_only[f]) continue;
    for (int c = soup.begin[f]; c < soup.begin[f + 1]; ++c) {
      fan.clear();
      int e = c, steps = 0;
      do {
        fan.push_back(k.face[e]);
        e = k.twin[k.prev[e]];
      } while (e != c && ++steps <= static_cast<int>(soup.vertex.size()));
      for (int g : fan) {
        if (is_thin(geo[g], limit)) continue;
        for (int h : fan)
          for (int d = soup.begin[h]; d < soup.begin[h + 1]; ++d)
            if (dot(geo[g].normal, points[soup.vertex[d]]) - geo[g].offset > limit) return false;
      }
    }
  }
  return true;
}

// Tries of merge_coplanar, each leaving as they are the facets of the groups whose polygons
// were not convex, and the merged facets where a polygon kept fewer than three corners. A
// try goes on only while that set grows. The opening of icosphere level 5 by its rotated
// copy scaled by 1/4 took two tries; openings of random hulls of 16,000 to 64,000 points by
// random ones at 1e-5 of their size took up to six (each try leaves fewer groups bending,
// as the groups left re-form without the facets set aside).
constexpr int kMergeRounds = 16;

std::optional<std::pair<Soup, Connectivity>> simplify(const std::vector<V3<double>>& points,
                                                      Soup& soup, double limit, bool strict,
                                                      Prepared pre = {}) {
  std::optional<Connectivity>& k = pre.k;
  if (!pre.geo) {
    // The facets' geometry (for pass 2) does not depend on the connectivity: with threads
    // to spare, computed beside `connect` (the two loops side by side, rather than each
    // split into chunks too short to pay at a few thousand facets); else after it, if it
    // succeeds.
    const int nf = soup.size();
    pre.geo = std::make_unique_for_overwrite<FacetGeometry[]>(nf);
    if (nf >= kFacetGrain && tbb::this_task_arena::max_concurrency() > 1) {
      run_both([&] { geometries(points, soup, pre.geo.get()); },
               [&] { k = connect(static_cast<int>(points.size()), soup); });
    } else {
      k = connect(static_cast<int>(points.size()), soup);
      if (k) geometries(points, soup, pre.geo.get());
    }
  } else if (!pre.connected) {
    k = connect(static_cast<int>(points.size()), soup);
  }
  if (!k) return std::nullopt;
  const FacetGeometry* const geo = pre.geo.get();
  Soup merged;
  MergedTwins merged_twins;
  bool changed = false;
  // Facets left as they are where a merged polygon was not convex: a few tries, each
  // leaving more of them, before the caller's fallback.
  std::vector<char> alone_only;
  std::optional<PassedEdges> passed;  // (the same in each round)
  for (int round = 0;; ++round) {
    const std::size_t marked = std::count(alone_only.begin(), alone_only.end(), 1);
    if (merge_coplanar(points, soup, *k, passed, geo, limit, strict, merged, merged_twins, changed,
                       alone_only) &&
        (alone_only.empty() || convex_around(points, soup, *k, geo, limit, alone_only)))
      break;
    if (round + 1 < kMergeRounds &&
        static_cast<std::size_t>(std::count(alone_only.begin(), alone_only.end(), 1)) > marked)
      continue;
    if (strict) return std::nullopt;
    return std::make_pair(std::move(soup), std::move(*k));
  }
  if (!changed) return std::make_pair(std::move(soup), std::move(*k));
  if (strict) k.reset();  // no use for it any more: its memory serves the next one
  std::optional<Connectivity> km =
      connect_with(static_cast<int>(points.size()), merged, std::move(merged_twins));
  if (!km) km = connect(static_cast<int>(points.size()), merged);
  if (km) return std::make_pair(std::move(merged), std::move(*km));
  if (strict) return std::nullopt;
  return std::make_pair(std::move(soup), std::move(*k));
}

// From this many corners with two threads or more, `build` fills the mesh in parallel. Its
// passes do about 1.3 times the work of build_serial's one pass (with OpenMesh's resize,
// which stays serial, their best case at two threads is about 18% less time), and below
// this they were slower with two threads on a loaded machine (see docs/algorithm.md).
constexpr int kParallelBuildCorners = 1 << 17;

/// `build` in parallel passes, with the same numbering: an edge is numbered by the corners
/// before its first corner that are first corners of their edges (twin[c] >= c), counted in
/// fixed blocks of corners (a prefix sum over the blocks, so the numbers do not depend on
/// the threads); a vertex's halfedge is its last corner's, found in the serial pass that
/// marks the used points.
Mesh build_parallel(const std::vector<V3<double>>& points, const Soup& soup,
                    const Connectivity& k) {
  Mesh mesh;
  const int nc = static_cast<int>(soup.vertex.size());
  const int np = static_cast<int>(points.size());
  constexpr int kBlock = 4096;  // corners
  const int nb = (nc + kBlock - 1) / kBlock;
  const int* const last = k.last_out.data();  // the last corner at each point (-1: unused)
  std::vector<int> block_edges(nb + 1, 0);    // the first edge of each block
  const int* vertex = soup.vertex.data();
  const int* twin = k.twin.data();
  parallel_chunks(nb, 1, [&](int first, int end) {
    for (int b = first; b < end; ++b) {
      int n = 0;
      for (int c = b * kBlock; c < std::min(nc, (b + 1) * kBlock); ++c) n += twin[c] >= c;
      block_edges[b + 1] = n;
    }
  });
  std::partial_sum(block_edges.begin(), block_edges.end(), block_edges.begin());
  std::vector<int> handle(np);  // the mesh vertex of each point (unused points: not read)
  int num_used = 0;
  for (int v = 0; v < np; ++v)
    if (last[v] >= 0) handle[v] = num_used++;
  mesh.resize(num_used, block_edges[nb], soup.size());
  Point* point = mesh.property(mesh.points_pph()).data_vector().data();
  Ints halfedge(nc);  // of each corner
  const auto vh = [&](int c) { return Mesh::VertexHandle(handle[vertex[c]]); };
  const auto he = [&](int c) { return Mesh::HalfedgeHandle(halfedge[c]); };
  // The first corners of edges: their halfedges (2e for edge e); then the others (their
  // twins' opposites).
  parallel_chunks(nb, 1, [&](int first, int end) {
    for (int b = first; b < end; ++b) {
      int edge = block_edges[b];
      for (int c = b * kBlock; c < std::min(nc, (b + 1) * kBlock); ++c)
        if (twin[c] >= c) halfedge[c] = mesh.halfedge_handle(Mesh::EdgeHandle(edge++), 0).idx();
    }
  });
  parallel_chunks(nc, kCornerGrain, [&](int first, int end) {
    for (int c = first; c < end; ++c)
      if (twin[c] < c) halfedge[c] = mesh.opposite_halfedge_handle(he(twin[c])).idx();
  });
  // Both halfedges of an edge from its first corner, edge by edge: each thread writes a range
  // of edges (OpenMesh keeps an edge's halfedges side by side), not both sides of one line.
  parallel_chunks(nc, kCornerGrain, [&](int first, int end) {
    for (int c = first; c < end; ++c) {
      const int t = twin[c];
      if (t < c) continue;
      mesh.set_vertex_handle(he(c), vh(k.next[c]));
      mesh.set_vertex_handle(he(t), vh(c));
      mesh.set_face_handle(he(c), Mesh::FaceHandle(k.face[c]));
      mesh.set_face_handle(he(t), Mesh::FaceHandle(k.face[t]));
      mesh.set_next_halfedge_handle(he(c), he(k.next[c]));  // and the next one's previous
      mesh.set_next_halfedge_handle(he(t), he(k.next[t]));
    }
  });
  parallel_chunks(soup.size(), kFacetGrain, [&](int first, int end) {
    for (int f = first; f < end; ++f)  // as add_face: the cycle starts at vertex b
      mesh.set_halfedge_handle(Mesh::FaceHandle(f), he(soup.begin[f + 1] - 1));
  });
  parallel_chunks(np, kVertexGrain, [&](int first, int end) {
    for (int v = first; v < end; ++v) {
      if (last[v] < 0) continue;
      point[handle[v]] = Point(points[v].x, points[v].y, points[v].z);
      // A vertex's halfedge is its last corner's (as when faces are added in order).
      mesh.set_halfedge_handle(Mesh::VertexHandle(handle[v]), he(last[v]));
    }
  });
  return mesh;
}

/// The OpenMesh mesh of a closed manifold soup, built straight from its connectivity
/// (no per-face searches). Vertices in index order, faces in soup order, each face's
/// vertex cycle starting where the soup's does.
Mesh build_serial(const std::vector<V3<double>>& points, const Soup& soup, const Connectivity& k) {
  Mesh mesh;
  const int nc = static_cast<int>(soup.vertex.size());
  const int np = static_cast<int>(points.size());
  // The used points are those with a corner leaving them; the corners pair up into edges
  // (twins are mutual and distinct in a closed manifold soup).
  const int num_edges = nc / 2;
  const int* const last_out = k.last_out.data();
  int num_used = 0;
  for (int v = 0; v < np; ++v) num_used += last_out[v] >= 0;  // counted without a branch
  // Every point used (a sum's points are its facets' corners, so unless facets merge or
  // collapse): each point's mesh vertex is its index, and no lookup is needed per corner.
  const bool all_used = num_used == np;
  std::vector<int> handle;  // else the mesh vertex of each point (-1: unused)
  if (!all_used) {
    handle.resize(np);
    for (int v = 0, used = 0; v < np; ++v) handle[v] = last_out[v] >= 0 ? used++ : -1;
  }
  // Every element at once: OpenMesh grows each of its property arrays per added element.
  // The elements are numbered as add_vertex, new_edge and new_face would number them.
  mesh.resize(num_used, num_edges, soup.size());
  // The point array, looked up once (set_point looks its property up by a dynamic_cast).
  Point* point = mesh.property(mesh.points_pph()).data_vector().data();
  if (all_used)
    for (int v = 0; v < np; ++v) point[v] = Point(points[v].x, points[v].y, points[v].z);
  else
    for (int v = 0; v < np; ++v)
      if (handle[v] >= 0) point[handle[v]] = Point(points[v].x, points[v].y, points[v].z);
  Ints halfedge(nc);  // of each corner
  // Plain pointers: the mesh's writes could alias the vectors' own pointers, which would
  // then be loaded again for each corner.
  const int *const vertex = soup.vertex.data(), *const twin = k.twin.data(),
                   *const begin = soup.begin.data();
  int* const corner_halfedge = halfedge.data();
  const int nf = soup.size();
  // One pass, face by face (the corners in order): a face's halfedges are all known after
  // its own corners, as the twins of earlier corners or new edges. `vh`: the mesh vertex
  // of a corner's point.
  // (Always inlined: the pass was inlined or not by how much else the file holds, and a
  // call left each capture to be loaded again per corner, after the mesh's writes.)
  const auto fill = [&](const auto& vh) __attribute__((always_inline)) {
    const auto he = [&](int c) { return Mesh::HalfedgeHandle(corner_halfedge[c]); };
    int edge = 0;
    // Face f, of d corners from b (a corner's next is the one after it, or the first after
    // the last). Triangles and quadrilaterals (nearly all faces) take a constant d: their
    // loops are unrolled, as the exits of loops of three or four steps in irregular order
    // were often mispredicted.
    const auto add_face = [&](int f, int b, auto d) __attribute__((always_inline)) {
      const auto after = [&](int i) { return i + 1 == d ? b : b + i + 1; };
      for (int i = 0; i < d; ++i) {
        const int c = b + i, t = twin[c];
        if (t < c) {
          corner_halfedge[c] = mesh.opposite_halfedge_handle(he(t)).idx();
        } else {
          corner_halfedge[c] = mesh.halfedge_handle(Mesh::EdgeHandle(edge++), 0).idx();
          mesh.set_vertex_handle(he(c), vh(after(i)));
          mesh.set_vertex_handle(mesh.opposite_halfedge_handle(he(c)), vh(c));
        }
      }
      const Mesh::FaceHandle fh(f);
      for (int i = 0; i < d; ++i) {
        mesh.set_face_handle(he(b + i), fh);
        mesh.set_next_halfedge_handle(he(b + i), he(after(i)));
      }
      mesh.set_halfedge_handle(fh, he(b + d - 1));  // as add_face: the cycle starts at vertex b
    };
    for (int f = 0; f < nf; ++f) {
      const int b = begin[f], d = begin[f + 1] - b;
      if (d == 3)
        add_face(f, b, std::integral_constant<int, 3>{});
      else if (d == 4)
        add_face(f, b, std::integral_constant<int, 4>{});
      else
        add_face(f, b, d);
    }
  };
  if (all_used)
    fill([&](int c) { return Mesh::VertexHandle(vertex[c]); });
  else
    fill([&](int c) { return Mesh::VertexHandle(handle[vertex[c]]); });
  // A vertex's halfedge is its last corner's (as when faces are added in order), set once
  // per vertex rather than at each corner.
  if (all_used)
    for (int v = 0; v < np; ++v)
      mesh.set_halfedge_handle(Mesh::VertexHandle(v),
                               Mesh::HalfedgeHandle(corner_halfedge[last_out[v]]));
  else
    for (int v = 0; v < np; ++v)
      if (handle[v] >= 0)
        mesh.set_halfedge_handle(Mesh::VertexHandle(handle[v]),
                                 Mesh::HalfedgeHandle(corner_halfedge[last_out[v]]));
  return mesh;
}

/// The OpenMesh mesh of a closed manifold soup: build_parallel for large results with
/// threads to spare, else build_serial (the same mesh). Returned as temporaries: OpenMesh
/// meshes have no move constructor, and a named mesh returned from two places is copied.
Mesh build(const std::vector<V3<double>>& points, const Soup& soup, const Connectivity& k) {
  if (static_cast<int>(soup.vertex.size()) >= kParallelBuildCorners &&
      tbb::this_task_arena::max_concurrency() > 1)
    return build_parallel(points, soup, k);
  return build_serial(points, soup, k);
}

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using HullMesh = CGAL::Surface_mesh<Kernel::Point_3>;

/// The facets of the convex hull of the cluster points (exact predicates on the doubles),
/// each with the result facet it belongs to: among the facets its corners came from (those
/// shared by all its corners when there are any), the one whose normal is closest.
/// CGAL's hull is triangulated, and how it splits a flat facet depends on the order of its
/// internal pointers, which varies from run to run (and with threads); so its triangles are
/// grouped where they are exactly coplanar (orientation predicate), and each group becomes
/// its boundary polygon, starting at its lowest point; polygons are sorted. The result
/// does not depend on the triangulation.
Soup hull_facets(const std::vector<V3<double>>& points, const Soup& facets) {
  const int nf = facets.size();
  std::map<int, std::vector<int>> facets_of;  // point -> facets that have it as a corner
  for (int f = 0; f < nf; ++f)
    for (int c = facets.begin[f]; c < facets.begin[f + 1]; ++c)
      facets_of[facets.vertex[c]].push_back(f);
  std::vector<Kernel::Point_3> pts;
  std::map<Kernel::Point_3, int> point_of;
  for (auto& [v, fs] : facets_of) {
    std::sort(fs.begin(), fs.end());
    fs.erase(std::unique(fs.begin(), fs.end()), fs.end());
    pts.emplace_back(points[v].x, points[v].y, points[v].z);
    point_of.emplace(pts.back(), v);
  }
  HullMesh hull;
  CGAL::convex_hull_3(pts.begin(), pts.end(), hull);
  if (hull.number_of_faces() == 0) throw error("internal error: a result is flat");
  std::vector<V3<double>> facet_normal(nf);
  for (int f = 0; f < nf; ++f) {
    V3<double> sum{0, 0, 0};
    for (int c = facets.begin[f]; c < facets.begin[f + 1]; ++c)
      sum = sum +
            cross(points[facets.vertex[c]],
                  points[facets.vertex[c + 1 == facets.begin[f + 1] ? facets.begin[f] : c + 1]]);
    const double len = std::sqrt(dot(sum, sum));
    facet_normal[f] = len > 0 ? V3<double>{sum.x / len, sum.y / len, sum.z / len} : sum;
  }
  // Groups of exactly coplanar triangles (union-find over the hull's faces).
  using Face = HullMesh::Face_index;
  UnionFind groups(static_cast<int>(hull.number_of_faces()));
  const auto group = [&](HullMesh::Halfedge_index h) {
    return groups.find(static_cast<int>(Face(hull.face(h))));
  };
  const auto point_at = [&](HullMesh::Halfedge_index h) { return hull.point(hull.target(h)); };
  for (auto e : hull.edges()) {
    const auto h = hull.halfedge(e), o = hull.opposite(h);
    const int a = group(h), b = group(o);
    if (a == b) continue;
    if (CGAL::coplanar(point_at(h), point_at(o), point_at(hull.next(h)), point_at(hull.next(o))))
      groups.unite(a, b);
  }
  // Each group's boundary: one outgoing boundary edge per corner (a flat part of a convex
  // surface is a convex polygon), chained from the lowest point.
  std::map<int, std::map<int, int>> boundary;  // group -> (from point -> to point)
  for (auto h : hull.halfedges()) {
    const int g = group(h);
    if (g == group(hull.opposite(h))) continue;
    const int from = point_of.at(hull.point(hull.source(h)));
    if (!boundary[g].emplace(from, point_of.at(point_at(h))).second)
      throw error("internal error: a flat part of a hull is not a polygon");
  }
  std::vector<std::pair<std::vector<int>, int>> polygons;  // points, source
  for (const auto& [g, next] : boundary) {
    std::vector<int> cycle;
    int v = next.begin()->first;  // the lowest point
    do {
      cycle.push_back(v);
      const auto it = next.find(v);
      if (it == next.end() || cycle.size() > next.size())
        throw error("internal error: a flat part of a hull is not a polygon");
      v = it->second;
    } while (v != cycle.front());
    if (cycle.size() != next.size())
      throw error("internal error: a flat part of a hull is not a polygon");
    std::vector<int> common = facets_of.at(cycle[0]), all = common;
    V3<double> normal{0, 0, 0};  // Newell's, about the first corner
    for (std::size_t k = 1; k < cycle.size(); ++k) {
      const auto& fs = facets_of.at(cycle[k]);
      std::vector<int> both;
      std::set_intersection(common.begin(), common.end(), fs.begin(), fs.end(),
                            std::back_inserter(both));
      common = std::move(both);
      all.insert(all.end(), fs.begin(), fs.end());
      if (k + 1 < cycle.size())
        normal = normal + cross(points[cycle[k]] - points[cycle[0]],
                                points[cycle[k + 1]] - points[cycle[0]]);
    }
    const std::vector<int>& candidates = common.empty() ? all : common;
    int best = -1;
    double best_dot = -std::numeric_limits<double>::infinity();
    for (int f : candidates) {
      const double d = dot(normal, facet_normal[f]);
      if (d > best_dot || (d == best_dot && f < best)) {
        best_dot = d;
        best = f;
      }
    }
    polygons.emplace_back(std::move(cycle), best >= 0 ? facets.source[best] : -1);
  }
  std::sort(polygons.begin(), polygons.end());
  Soup out;
  for (const auto& [cycle, source] : polygons) out.add(cycle, source);
  return out;
}

/// A cycle of pass 1 that passes a point twice, split there into loops: a facet whose close
/// corners merged across it (the short diagonal of a thin parallelogram: two nearly
/// parallel edges of the operands summed) folds onto itself. Loops of fewer than three
/// points are collapsed onto an edge, whose two sides then meet, like a collapsed facet's
/// neighbours; `cycle` becomes the one loop left (empty if none). False when more than one
/// loop is left: the facet is pinched into several polygons, which the hull then decides.
/// `place` is all -1 for the points (grown as needed), and is left so.
bool split_collapsed(std::vector<int>& cycle, std::vector<int>& place) {
  std::vector<int> stack, kept;
  int loops = 0;
  for (const int v : cycle) {
    if (v >= static_cast<int>(place.size())) place.resize(v + 1, -1);
    if (place[v] >= 0) {
      // The loop from v's first visit to here: off the stack (v stays on it).
      const int from = place[v] + 1;
      if (static_cast<int>(stack.size()) - from + 1 >= 3) {
        ++loops;
        kept.assign(stack.begin() + from - 1, stack.end());
      }
      for (int i = from; i < static_cast<int>(stack.size()); ++i) place[stack[i]] = -1;
      stack.resize(from);
      continue;
    }
    place[v] = static_cast<int>(stack.size());
    stack.push_back(v);
  }
  for (const int v : stack) place[v] = -1;
  // What is left on the stack is the loop that the cycle's closing edge ends.
  if (stack.size() >= 3) {
    ++loops;
    kept = std::move(stack);
  }
  if (loops > 1) return false;
  cycle = std::move(kept);
  return true;
}

std::atomic<long> hull_fallbacks{0};

}  // namespace

long clean_mesh_hull_fallbacks() { return hull_fallbacks.load(std::memory_order_relaxed); }

Mesh clean_mesh(const std::vector<V3<double>>& points, const std::vector<int>& face_begin,
                std::vector<int> facet_corners, std::vector<int>* source) {
  constexpr int kPairwiseDegree = 16;  // facets up to this degree are checked corner by corner
  const int n = static_cast<int>(points.size());
  const int nf = static_cast<int>(face_begin.size()) - 1;
  // The facets as given: the soup when nothing merges (the usual case).
  Soup soup;
  soup.begin = face_begin;
  soup.vertex = std::move(facet_corners);
  const std::vector<int>& corners = soup.vertex;
  // The facets' geometry (pass 2's input) is found in pass 1's search, from the points it
  // loads, on the chance that the facets are the soup as they are; with threads to spare,
  // so is the soup's connectivity, beside pass 1 (rather than `simplify` splitting each
  // into chunks too short to pay at a few thousand facets). They are dropped if not.
  const bool ahead = nf >= kFacetGrain && tbb::this_task_arena::max_concurrency() > 1;
  Prepared pre;
  UnionFind clusters(0);  // of the n points, once needed (nothing is close, usually)
  double limit = 0;
  bool fine = false, any_close = false, as_given = false;
  // Pass 1's search for close corners, and whether the facets are the soup as they are.
  const auto find_close = [&] {
    V3<double> lo{0, 0, 0}, hi{0, 0, 0};
    if (n > 0) lo = hi = points[0];
    // The even and odd points in two boxes (half as long chains of dependent minima), then
    // joined: the same extremes (a NaN enters only as points[0]'s, in both; which zero is
    // kept may differ, and neither the span nor the magnitude below depends on it).
    V3<double> lo_odd = lo, hi_odd = hi;
    const auto extend = [](V3<double>& low, V3<double>& high, const V3<double>& p) {
      low = {std::min(low.x, p.x), std::min(low.y, p.y), std::min(low.z, p.z)};
      high = {std::max(high.x, p.x), std::max(high.y, p.y), std::max(high.z, p.z)};
    };
    int v = 0;
    for (; v + 1 < n; v += 2) {
      extend(lo, hi, points[v]);
      extend(lo_odd, hi_odd, points[v + 1]);
    }
    if (v < n) extend(lo, hi, points[v]);
    extend(lo, hi, lo_odd);
    extend(lo, hi, hi_odd);
    const V3<double> span = hi - lo;
    limit = kFeatureTolerance * std::sqrt(dot(span, span));
    // Points whose rounding unit exceeds the feature size (a result far from the origin for
    // its size) carry noise that merging cannot remove; the hull drops what of it is not
    // extreme, and gives a simpler mesh there. So a facet folded onto itself is split only
    // when the points are finer than the feature size, and otherwise left to the hull.
    const double magnitude = std::max({std::abs(lo.x), std::abs(lo.y), std::abs(lo.z),
                                       std::abs(hi.x), std::abs(hi.y), std::abs(hi.z)});
    fine = magnitude * std::numeric_limits<double>::epsilon() <= limit;
    // Pass 1: clusters of close corners, each represented by its lowest vertex.
    // Squared distances above `far` are beyond `limit` whatever the rounding of its square
    // (a margin of 2), so most pairs need no square root.
    const double limit_squared = limit * limit;
    const double far = limit_squared >= std::numeric_limits<double>::min()
                           ? 2 * limit_squared
                           : std::numeric_limits<double>::infinity();
    auto close = [&](int u, int w) {
      const V3<double> d = points[u] - points[w];
      const double distance_squared = dot(d, d);
      return distance_squared <= far && std::sqrt(distance_squared) <= limit;
    };
    // Calls pair(u, w) on the corners of facet f that are compared.
    auto for_pairs = [&](int f, const auto& pair) {
      const int b = face_begin[f], e = face_begin[f + 1];
      if (e - b <= kPairwiseDegree) {  // also across a facet: the diagonal of a thin parallelogram
        for (int c = b; c < e; ++c)
          for (int d = c + 1; d < e; ++d) pair(corners[c], corners[d]);
      } else {
        for (int c = b; c < e; ++c) pair(corners[c], corners[c + 1 == e ? b : c + 1]);
      }
    };
    // Triangles and quadrilaterals (nearly all facets): no pair is close when none is within
    // `far` nor repeated, decided from their points loaded once and without a branch per pair
    // (`close` of a pair is false unless its squared distance is at most `far`).
    const auto squared = [&](const V3<double>& p, const V3<double>& q) {
      const V3<double> d = p - q;
      return dot(d, d);
    };
    auto surely_apart = [&](int f) {
      const int b = face_begin[f], e = face_begin[f + 1];
      const int* v = corners.data() + b;
      if (e - b == 3) {
        const V3<double>&p0 = points[v[0]], &p1 = points[v[1]], &p2 = points[v[2]];
        return !((squared(p0, p1) <= far) | (squared(p0, p2) <= far) | (squared(p1, p2) <= far) |
                 (v[0] == v[1]) | (v[0] == v[2]) | (v[1] == v[2]));
      }
      if (e - b == 4) {
        const V3<double>&p0 = points[v[0]], &p1 = points[v[1]], &p2 = points[v[2]],
              &p3 = points[v[3]];
        return !((squared(p0, p1) <= far) | (squared(p0, p2) <= far) | (squared(p0, p3) <= far) |
                 (squared(p1, p2) <= far) | (squared(p1, p3) <= far) | (squared(p2, p3) <= far) |
                 (v[0] == v[1]) | (v[0] == v[2]) | (v[0] == v[3]) | (v[1] == v[2]) |
                 (v[1] == v[3]) | (v[2] == v[3]));
      }
      return false;
    };
    // Facets of up to kPairwiseDegree corners (an erosion's polygons, mostly): calls
    // pair(u, w) on the pairs that for_pairs gives from each corner that has one within
    // `far` (squared) after it — the only pairs that can be close, or repeated when the
    // points are finite — and returns true; false (nothing called) when a point is not
    // finite or the facet has more corners. Two pairs at a time from the points loaded once
    // (the pair by pair test loaded both points of each and branched on it: most of pass 1
    // on an erosion's polygons). A NaN after the last corner makes the odd pair at the end
    // never near.
    auto polygon_pairs = [&](int f, const auto& pair) {
      const int b = face_begin[f], d = face_begin[f + 1] - b;
      if (d > kPairwiseDegree) return false;
      const int* v = corners.data() + b;
      alignas(16) double x[kPairwiseDegree + 1], y[kPairwiseDegree + 1], z[kPairwiseDegree + 1];
      double finite = 0;  // 0 * a coordinate: NaN for an infinity or a NaN
      for (int k = 0; k < d; ++k) {
        const V3<double>& p = points[v[k]];
        x[k] = p.x, y[k] = p.y, z[k] = p.z;
        finite += 0 * p.x + 0 * p.y + 0 * p.z;
      }
      if (!(finite == 0)) return false;
      x[d] = y[d] = z[d] = std::numeric_limits<double>::quiet_NaN();
      const Pair bound{far, far};
      unsigned rows = 0;  // bit i: corner i has a pair within `far` after it
      for (int i = 0; i + 1 < d; ++i) {
        const Pair xi{x[i], x[i]}, yi{y[i], y[i]}, zi{z[i], z[i]};
        PairMask near{0, 0};
        for (int j = i + 1; j < d; j += 2) {
          // p_i - p_j, as `close` of corners i < j takes it
          const Pair dx = xi - Pair{x[j], x[j + 1]}, dy = yi - Pair{y[j], y[j + 1]},
                     dz = zi - Pair{z[j], z[j + 1]};
          near |= dx * dx + dy * dy + dz * dz <= bound;
        }
        rows |= static_cast<unsigned>((near[0] | near[1]) != 0) << i;  // no branch per row
      }
      for (; rows != 0; rows &= rows - 1) {  // (few)
        const int i = std::countr_zero(rows);
        for (int j = i + 1; j < d; ++j) pair(v[i], v[j]);
      }
      return true;
    };
    // The close pairs, found in parallel (each chunk's appended under a lock) and united
    // after: the sets, named by their lowest members, do not depend on the unions' order.
    // A corner repeated in a facet compared pair by pair counts too (it is close to itself
    // unless its point is not finite): the facets are then not the soup as they are.
    std::vector<std::pair<int, int>> close_pairs;
    std::mutex close_pairs_lock;
    std::atomic<bool> some_close{false};
    // Whether a facet has fewer than three corners or is compared by its sides alone (the
    // facets taken two at a time have three or four).
    std::atomic<bool> some_irregular{false};
    parallel_chunks(nf, kFacetGrain, [&](int first, int last) {
      bool found = false, irregular = false;
      std::vector<std::pair<int, int>> pairs;  // this chunk's close pairs
      bool here = false;                       // whether the facet tested last has close corners
      const auto check = [&](int u, int w) {
        if (u == w || close(u, w)) {
          here = true;
          if (u != w) pairs.emplace_back(u, w);
        }
      };
      const auto test = [&](int f, bool apart) {
        here = false;
        if (!apart) for_pairs(f, check);
        found = found || here;
      };
      // A polygon of five corners or more: whether it has close corners.
      const auto test_polygon = [&](int f) {
        here = false;
        if (!polygon_pairs(f, check)) for_pairs(f, check);
        found = found || here;
        return here;
      };
      FacetGeometry* const geo = pre.geo.get();
      for (int f = first; f < last; ++f) {
        // Two facets of one degree at once when they follow each other (nearly all), with
        // their geometry from the same points.
        const int d = face_begin[f + 1] - face_begin[f];
        if (f + 1 < last && (d == 3 || d == 4) && face_begin[f + 2] - face_begin[f + 1] == d) {
          const std::array<bool, 2> apart = d == 3 ? geometry_pair<3>(points, soup, f, geo, far)
                                                   : geometry_pair<4>(points, soup, f, geo, far);
          test(f, apart[0]);
          test(f + 1, apart[1]);
          ++f;
          continue;
        }
        if (d >= 5) {
          // Polygons (an erosion's, mostly), two at a time when they follow each other. A
          // facet with close corners is not the soup's as it is: no geometry.
          const bool pair = f + 1 < last && face_begin[f + 2] - face_begin[f + 1] >= 5;
          const bool near0 = test_polygon(f), near1 = pair && test_polygon(f + 1);
          if (pair && !near0 && !near1)
            geometry_pair_any(points, soup, f, geo);
          else
            for (int g = f; g < f + 1 + pair; ++g)
              if (!(g == f ? near0 : near1)) geo[g] = geometry(points, soup, g);
          for (int g = f; g < f + 1 + pair; ++g)
            irregular = irregular || face_begin[g + 1] - face_begin[g] > kPairwiseDegree;
          f += pair;
          continue;
        }
        if (d >= 3)  // (a facet of fewer corners is not the soup's)
          geo[f] = facet_geometry(points, soup, f);
        test(f, surely_apart(f));
        irregular = irregular || d < 3 || d > kPairwiseDegree;
      }
      if (found) some_close.store(true, std::memory_order_relaxed);
      if (!pairs.empty()) {
        const std::lock_guard<std::mutex> hold(close_pairs_lock);
        close_pairs.insert(close_pairs.end(), pairs.begin(), pairs.end());
      }
      if (irregular) some_irregular.store(true, std::memory_order_relaxed);
    });
    any_close = some_close.load();
    if (any_close) {
      clusters = UnionFind(n);
      for (const auto& [u, w] : close_pairs) clusters.unite(u, w);
    }
    // Nothing merged (the usual case): the facets are the soup as they are, unless one has a
    // repeated corner or fewer than three. Only a facet compared by its sides alone can still
    // have one (the others would have been marked above).
    bool given = !any_close;      // a local: `as_given` is the caller's
    std::vector<int> last_facet;  // the last facet a point was seen in, to find repeats
    const bool irregular = some_irregular.load();  // else every facet passes the loop below
    for (int f = 0; f < nf && given && irregular; ++f) {
      const int b = face_begin[f], e = face_begin[f + 1];
      given = e - b >= 3;
      if (e - b <= kPairwiseDegree) continue;
      if (last_facet.empty()) last_facet.assign(n, -1);
      for (int c = b; c < e && given; ++c) {
        given = last_facet[corners[c]] != f;
        last_facet[corners[c]] = f;
      }
    }
    as_given = given;
  };
  pre.geo = std::make_unique_for_overwrite<FacetGeometry[]>(nf);
  if (ahead) {
    run_both(find_close, [&] { pre.k = connect(n, soup); });
    pre.connected = true;
  } else {
    find_close();
  }
  bool repeated = false;
  if (as_given) {
    soup.source.resize(nf);
    std::iota(soup.source.begin(), soup.source.end(), 0);
  } else {
    // The connectivity found for the facets as given is not the soup's; their geometry is
    // that of the soup's facets that are a given facet as it is (the same corners from the
    // same first one, so the same values): kept for those, computed for the others.
    const std::unique_ptr<FacetGeometry[]> given_geo = std::move(pre.geo);
    pre = {};
    pre.geo = std::make_unique_for_overwrite<FacetGeometry[]>(nf);  // no more facets than given
    if (!any_close) clusters = UnionFind(n);                        // each point its own cluster
    Soup merged;
    std::vector<int> last_facet(n, -1);  // the last facet a point was seen in, to find repeats
    merged.vertex.reserve(corners.size());
    merged.source.reserve(nf);
    std::vector<int> cycle, place;  // place: of a point in `cycle` while it is split (-1: none)
    std::vector<int> changed;       // the soup's facets that are not a given one as it is
    for (int f = 0; f < nf; ++f) {
      cycle.clear();
      bool moved = false;  // a corner's point merged into another
      for (int c = face_begin[f]; c < face_begin[f + 1]; ++c) {
        const int v = clusters.find(corners[c]);
        moved = moved || v != corners[c];
        if (cycle.empty() || cycle.back() != v) cycle.push_back(v);
      }
      while (cycle.size() > 1 && cycle.front() == cycle.back()) cycle.pop_back();
      if (cycle.size() < 3) continue;  // collapsed onto an edge or a point: its neighbours meet
      bool twice = false;
      for (const int v : cycle) {
        twice = twice || last_facet[v] == f;
        last_facet[v] = f;
      }
      if (twice && !(fine && split_collapsed(cycle, place))) repeated = true;
      if (cycle.size() < 3) continue;
      // Nothing moved, dropped nor split: the cycle is the facet's corners.
      if (moved || twice || static_cast<int>(cycle.size()) != face_begin[f + 1] - face_begin[f])
        changed.push_back(merged.size());
      else
        pre.geo[merged.size()] = given_geo[f];
      merged.add(cycle, f);
    }
    soup = std::move(merged);  // `corners` is not read any more
    for (std::size_t i = 0; i < changed.size(); ++i) {
      const int m = changed[i], d = soup.degree(m);
      if (d >= 5 && i + 1 < changed.size() && changed[i + 1] == m + 1 && soup.degree(m + 1) >= 5) {
        geometry_pair_any(points, soup, m, pre.geo.get());
        ++i;
        continue;
      }
      pre.geo[m] = facet_geometry(points, soup, m);
    }
  }
  std::optional<std::pair<Soup, Connectivity>> result;
  if (!repeated) result = simplify(points, soup, limit, true, std::move(pre));
  if (!result) {
    hull_fallbacks.fetch_add(1, std::memory_order_relaxed);
    Soup hull = hull_facets(points, soup);
    result = simplify(points, hull, limit, false);
  }
  if (!result) throw error("internal error: the hull of a result could not be joined into a mesh");
  Mesh mesh = build(points, result->first, result->second);
  if (source) *source = std::move(result->first.source);
  return mesh;
}

}  // namespace morph::detail
