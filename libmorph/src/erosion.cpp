// Erosion by duality: A (-) B as the intersection of A's facet half-spaces moved inwards
// by B's support values, and the closing (A (+) B) (-) B, as inputs to the exact half-space
// intersection (halfspace_intersection.cpp): the half-spaces, the points known to lie on
// their planes (KnownPoints) and the expected result (ExpectedVertices).
#include <morph/error.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numeric>
#include <optional>
#include <span>
#include <vector>

#include "fims.h"
#include "gauss_map.h"
#include "halfspace_intersection.h"
#include "parallel.h"
#include "wide_exact.h"

namespace morph::detail {

namespace {

/// <n, p> for a vertex p = X / W of a polytope, as value / weight (weight > 0).
struct Homogeneous {
  ExactN value, weight;
};
Homogeneous homogeneous_dot(const Polytope& P, const V3<ExactN>& n, int v) {
  if (P.exact_points.empty()) return {dot(n, to_exact_n(P.points[v])), ExactN(1)};
  return {dot(n, P.exact_points.X(v)), P.exact_points.W(v)};
}
/// The Newell normal of triangle f of a polytope with double points.
V3<ExactN> triangle_normal(const Polytope& A, int f) {
  const V3<double>& p = A.points[A.corner(f, 0)];
  return cross(exact_difference(A.points[A.corner(f, 1)], p),
               exact_difference(A.points[A.corner(f, 2)], p));
}
/// Sign of p - q, by cross-multiplication unless both weights are 1.
int compare(const Homogeneous& p, const Homogeneous& q) {
  if (p.weight == 1 && q.weight == 1) return CGAL::compare(p.value, q.value);
  return CGAL::compare(p.value * q.weight, q.value * p.weight);
}
bool same(const Homogeneous& p, const Homogeneous& q) { return compare(p, q) == 0; }

}  // namespace

namespace {

/// Whether the eroded polytope is a sum by the element (its sum_pairs name the element's
/// vertices).
enum class SumOfB : bool { no, yes };

/// The vertices of B that may attain h_B in the direction located at `loc`: the
/// contributing vertex, both ends of an edge, or every corner of a facet (a facet only
/// planar within the tolerance holds some of them below its plane: checked exactly).
void candidate_vertices(const Polytope& B, const Location& loc, std::vector<int>& out) {
  out.clear();
  switch (loc.kind) {
    case Location::Kind::vertex:
      out.push_back(loc.index);
      break;
    case Location::Kind::edge:
      out.push_back(B.edges[loc.index].from);
      out.push_back(B.edges[loc.index].to);
      break;
    case Location::Kind::face:
      for (int k = 0; k < B.degree(loc.index); ++k) out.push_back(B.corner(loc.index, k));
      break;
  }
}

/// The facet cycles that erosion_points walks: facet f's corners are the vertices
/// corner_vertex[face_begin[f]] .. (a polytope's, or a sum's numbered pairs).
struct Cycles {
  const std::vector<int>& face_begin;
  const std::vector<int>& corner_vertex;
  int num_vertices;
  int num_faces() const { return static_cast<int>(face_begin.size()) - 1; }
};

/// erosion_points on facet cycles: `pair_of(v)` is vertex v's pair (X's vertex, B's vertex)
/// when the eroded polytope is a sum X (+) B (`sum`; nx bounds X's vertices),
/// `point_of(v, b, known, k)` sets known point k to the exact v - b: its X, W, Xi and Wi
/// (under a RoundingGuard), or when `as_dd` its dd alone (round-to-nearest; the enclosures
/// are made here from it), and `others_of(f)` is the span of facet f's further vertices of B
/// attaining h_B.
template <class PairOf, class PointOf, class OthersOf>
KnownPoints known_points(const Cycles& A, bool sum, int nx, const PairOf& pair_of,
                         const PointOf& point_of, bool as_dd, const std::vector<int>& contributing,
                         const OthersOf& others_of, const std::vector<char>& on_plane) {
  KnownPoints known;
  const int nf = A.num_faces(), nv = A.num_vertices;
  // Lists of (b, point) per vertex of A and, for a sum, per vertex of X.
  struct Node {
    int b, point, next;
  };
  std::vector<Node> nodes;
  std::vector<int> head(nv, -1), head_x(nx, -1);
  std::vector<std::pair<int, int>> creator;  // (v, b) that first named each point
  known.begin.assign(nf + 1, 0);
  for (int f = 0; f < nf; ++f) {
    for (int c = A.face_begin[f]; c < A.face_begin[f + 1]; ++c) {
      if (!on_plane[c]) continue;
      const int v = A.corner_vertex[c];
      const std::uint64_t pair = sum ? pair_of(v) : 0;
      const std::span<const int> others = others_of(f);
      for (int i = -1; i < static_cast<int>(others.size()); ++i) {
        const int b = i < 0 ? contributing[f] : others[i];
        const bool own = sum && pair_second(pair) == b;
        int& first = own ? head_x[pair_first(pair)] : head[v];
        int point = -1;
        for (int q = first; q >= 0 && point < 0; q = nodes[q].next)
          if (own || nodes[q].b == b) point = nodes[q].point;
        if (point < 0) {
          point = static_cast<int>(creator.size());
          creator.emplace_back(v, b);
          nodes.push_back({b, point, first});
          first = static_cast<int>(nodes.size()) - 1;
        }
        known.point.push_back(point);
      }
    }
    known.begin[f + 1] = static_cast<int>(known.point.size());
  }
  // Only a point on three planes or more can be a vertex: the others are dropped.
  std::vector<int> count(creator.size(), 0);
  for (int k : known.point) ++count[k];
  std::vector<int> renumber(creator.size(), -1);
  int np = 0;
  for (std::size_t k = 0; k < creator.size(); ++k)
    if (count[k] >= 3) {
      renumber[k] = np;
      creator[np++] = creator[k];
    }
  creator.resize(np);
  int kept = 0;
  for (int f = 0, j = 0; f < nf; ++f) {
    for (; j < known.begin[f + 1]; ++j)
      if (renumber[known.point[j]] >= 0) known.point[kept++] = renumber[known.point[j]];
    known.begin[f + 1] = kept;
  }
  known.point.resize(kept);
  if (as_dd) {
    known.dd.resize(np);
  } else {
    known.X.resize(np);
    known.W.resize(np);
  }
  known.Xi.resize(np);
  known.Wi.resize(np);
  parallel_chunks(np, 512, [&](int begin, int end) {
    if (!as_dd) {
      RoundingGuard guard;
      for (int k = begin; k < end; ++k) point_of(creator[k].first, creator[k].second, known, k);
      return;
    }
    {
      RoundingGuard nearest(CGAL_FE_TONEAREST);
      for (int k = begin; k < end; ++k) point_of(creator[k].first, creator[k].second, known, k);
    }
    RoundingGuard guard;
    const auto enclosure = [](const DD& c) { return Interval(c.hi) + Interval(c.lo); };
    for (int k = begin; k < end; ++k) {
      const V3<DD>& d = known.dd[k];
      known.Xi[k] = {enclosure(d.x), enclosure(d.y), enclosure(d.z)};
      known.Wi[k] = Interval(1);
    }
  });
  return known;
}

/// The known points of an erosion: facet f of A passes, after moving, through v - b for
/// each corner v of f on its plane (`on_plane`, per corner of A) and each vertex b of B
/// attaining h_B(N_f) (contributing[f], and others[f] when there are more). Points are numbered by
/// (v, b), or, when A = X (+) B is a sum by this B (`sum`: A's sum_pairs), by the vertex of X
/// when b is v's own summand (v - b is then that vertex of X).
KnownPoints erosion_points(const Polytope& A, const Polytope& B,
                           const std::vector<int>& contributing,
                           const std::vector<std::vector<int>>& others,
                           const std::vector<char>& on_plane, SumOfB sum_of_b) {
  if (!B.exact_points.empty()) return {};
  const bool sum = sum_of_b == SumOfB::yes;
  int nx = 0;
  if (sum)
    for (std::uint64_t key : A.sum_pairs) nx = std::max(nx, pair_first(key) + 1);
  const auto pair_of = [&](int v) { return A.sum_pairs[A.vertex_source[v]]; };
  // Double points: each v - b exactly as a double-double (two_sum, exact where the
  // difference does not overflow: every coordinate below 2^1022).
  const auto below = [](const std::vector<V3<double>>& points) {
    return std::all_of(points.begin(), points.end(), [](const V3<double>& p) {
      return std::abs(p.x) < 0x1p1022 && std::abs(p.y) < 0x1p1022 && std::abs(p.z) < 0x1p1022;
    });
  };
  const bool as_dd = A.exact_points.empty() && below(A.points) && below(B.points);
  const auto point_of = [&](int v, int b, KnownPoints& known, int k) {
    if (as_dd) {
      const V3<double>&p = A.points[v], &q = B.points[b];
      known.dd[k] = {two_sum(p.x, -q.x), two_sum(p.y, -q.y), two_sum(p.z, -q.z)};
    } else {
      const ExactN& w = A.exact_points.W(v);
      const V3<ExactN> bn = to_exact_n(B.points[b]);
      known.X[k] = A.exact_points.X(v) - (w == 1 ? bn : V3<ExactN>{bn.x * w, bn.y * w, bn.z * w});
      known.W[k] = w;
      known.Xi[k] = to_interval_n(known.X[k]);
      known.Wi[k] = to_interval_n(known.W[k]);
    }
  };
  const auto others_of = [&](int f) { return std::span<const int>(others[f]); };
  return known_points(Cycles{A.face_begin, A.corner_vertex, A.num_vertices()}, sum, nx, pair_of,
                      point_of, as_dd, contributing, others_of, on_plane);
}

}  // namespace

void HalfSpace::set_exact_from_words(const HalfSpace& h) {
  const ExactWords& w = h.words;
  Values& v = h.values();
  fixed::set_exact(V3<fixed::i128>{w.n[0], w.n[1], w.n[2]}, w.normal_exp, v.normal);
  fixed::set_exact(fixed::Int<3>{{w.d[0], w.d[1], w.d[2]}}, w.offset_exp, v.offset);
}

namespace {

/// Each vertex's span (wide_exact.h) for the fixed-point frames of its facets, found once
/// rather than in each frame the vertex is in (about six for a triangulated A).
std::vector<fixed::Span> vertex_spans(const Polytope& P) {
  std::vector<fixed::Span> spans(P.num_vertices());
  parallel_chunks(P.num_vertices(), 1024, [&](int begin, int end) {
    for (int v = begin; v < end; ++v) spans[v].add(P.points[v]);
  });
  return spans;
}

/// Sets a new half-space h (exact values zero) to the fixed-point plane of normal n scaled
/// by 2^doubling and offset <n, top - *sub> (<n, top> without sub). In a small frame, when
/// both double-double copies are made, its exact values are left lazy (their words kept:
/// most are never read, the filters and the precise stage taking the copies); otherwise
/// they are made Mpzf now. The same values either way.
void set_fixed_plane(HalfSpace& h, const fixed::Normal& n, int doubling, const V3<double>& top,
                     const V3<double>* sub) {
  h.has_normal_dd = n.normal_dd(doubling, h.normal_dd);
  ExactWords& w = h.words;
  V3<fixed::i128> normal;
  fixed::Int<3> offset;
  // (<n, top - 0> is small_words' <n, top>.)
  if (h.has_normal_dd && n.small_words(doubling, top, sub ? *sub : V3<double>{0, 0, 0}, normal,
                                       w.normal_exp, offset, w.offset_exp)) {
    RoundingGuard nearest(CGAL_FE_TONEAREST);
    if (fixed::to_dd(offset, w.offset_exp, h.offset_dd)) {
      w.n = {normal.x, normal.y, normal.z};
      w.d = {offset.w[0], offset.w[1], offset.w[2]};
      h.has_offset_dd = h.lazy = true;
      return;
    }
  }
  n.set_normal(doubling, h.normal());
  h.has_offset_dd = n.set_dot(doubling, top, sub, h.offset(), &h.offset_dd);
}

ErosionInput erosion_input(const Polytope& A, const Polytope& B, SumOfB sum_of_b,
                           ExpectedVertices expected) {
  const std::vector<Location> loc = locate_all(A, B);
  const int nf = A.num_faces();
  HalfSpaces hs(nf);
  std::vector<char> on_plane(A.corner_vertex.size(), 0);  // per corner of A
  std::vector<int> contributing(nf);                      // the vertex of B moving f
  std::vector<std::vector<int>> others(nf);               // more vertices of B attaining h_B(N_f)
  // (For the fixed-point frames below.)
  const std::vector<fixed::Span> spans = A.given_normals.empty() && B.exact_points.empty()
                                             ? vertex_spans(A)
                                             : std::vector<fixed::Span>();
  parallel_chunks(nf, 64, [&](int begin, int end) {
    std::vector<Homogeneous> dots;
    std::vector<int> candidates;
    for (int f = begin; f < end; ++f) {
      const int b = location_vertex(B, loc[f]);
      contributing[f] = b;
      candidate_vertices(B, loc[f], candidates);
      char* on = &on_plane[A.face_begin[f]];
      HalfSpace& h = hs[f];
      h.source = A.face_source[f];
      h.element = B.vertex_source[b];
      // For a normal of double differences and an element of double points: another
      // candidate c attains h_B iff <n, c - b> = 0 (the exact normal made here when lazy and
      // there is another: B's edge or facet along it, rare).
      const auto add_others_on_plane = [&]() {
        for (int c : candidates)
          if (c != b &&
              CGAL::sign(dot(h.exact_normal(), exact_difference(B.points[c], B.points[b]))) == 0)
            others[f].push_back(c);
      };
      // A fixed-point plane (wide_exact.h) with the offset <n, top - pb>.
      const auto set_fixed = [&](const fixed::Normal& n, const V3<double>& top,
                                 const V3<double>& pb) { set_fixed_plane(h, n, 0, top, &pb); };
      if (A.degree(f) == 3 && A.given_normals.empty() && B.exact_points.empty()) {
        // A triangle of double points (A's are then all doubles) and an element of double
        // points: its Newell normal is (q - p) x (r - p), the same value in fewer products,
        // its corners lie exactly on that plane, and h_A - h_B = <n, p - b> in one dot
        // product; differences of doubles as exact_difference.
        const V3<double>&p = A.points[A.corner(f, 0)], &q = A.points[A.corner(f, 1)],
              &r = A.points[A.corner(f, 2)], &pb = B.points[b];
        on[0] = on[1] = on[2] = 1;
        // In fixed point (wide_exact.h) when the doubles allow, else in Mpzf: the same values.
        // The normal's and the offset's double-double copies from their exact words (the
        // normal's from the doubles otherwise): cheaper than from the exact values.
        fixed::Span span = spans[A.corner(f, 0)];
        span.add(spans[A.corner(f, 1)]);
        span.add(spans[A.corner(f, 2)]);
        span.add(pb);
        const fixed::Frame frame(span);
        if (frame.ok) {
          const fixed::Normal n(frame, p, q, p, r);
          set_fixed(n, p, pb);
          if (!h.has_normal_dd) set_normal_dd(h, p, q, r);
        } else {
          set_normal_dd(h, p, q, r);
          h.normal() = triangle_normal(A, f);
          h.offset() = dot(h.normal(), exact_difference(p, pb));
        }
        add_others_on_plane();
        continue;
      }
      if (A.degree(f) == 4 && A.given_normals.empty() && A.exact_points.empty() &&
          B.exact_points.empty()) {
        // A quadrilateral of double points (often not exactly planar: a UV sphere's): its
        // Newell normal, sum of p_k x p_k+1, is exactly the cross product of its diagonals
        // (p2 - p0) x (p3 - p1), A.exact_normal(f)'s value in two differences and one cross
        // product. h_A is attained at the corners p_k with the largest <n, p_k - p0> (exact
        // dots of double differences, as the triangle's), and h_A - h_B = <n, p_best - b>.
        const auto corner = [&](int k) -> const V3<double>& { return A.points[A.corner(f, k)]; };
        const V3<double>&p0 = corner(0), &p1 = corner(1), &p2 = corner(2), &p3 = corner(3),
              &pb = B.points[b];
        // n is orthogonal to both diagonals, so <n, p2 - p0> = 0 and <n, p3 - p1> = 0: the
        // heights are 0, h, 0, h for h = <n, p1 - p0>, and its sign alone gives the top
        // corners: 1 and 3 when h > 0, 0 and 2 when h < 0, all four when the quadrilateral is
        // planar.
        const auto set_top = [&](int sign) {
          const int top = sign > 0 ? 1 : 0;
          for (int k = 0; k < 4; ++k) on[k] = sign == 0 || k % 2 == top;
          return top;
        };
        // In fixed point (wide_exact.h) when the doubles allow.
        fixed::Span span = spans[A.corner(f, 0)];
        for (int k = 1; k < 4; ++k) span.add(spans[A.corner(f, k)]);
        span.add(pb);
        const fixed::Frame frame(span);
        if (frame.ok) {
          const fixed::Normal n(frame, p0, p2, p1, p3);
          const int top = set_top(n.sign_dot(p1, p0));
          set_fixed(n, top == 1 ? p1 : p0, pb);
          add_others_on_plane();
          continue;
        }
        h.normal() =
            cross(exact_difference(corner(2), corner(0)), exact_difference(corner(3), corner(1)));
        // The sign of h by intervals, exact when they cannot tell.
        int sign;
        {
          RoundingGuard guard;
          sign = interval_sign(
              dot(to_interval_n(h.normal()), to_interval(corner(1)) - to_interval(corner(0))));
        }
        if (sign == 2) sign = CGAL::sign(dot(h.normal(), exact_difference(corner(1), corner(0))));
        const int top = set_top(sign);
        h.offset() = dot(h.normal(), exact_difference(corner(top), B.points[b]));
        add_others_on_plane();
        continue;
      }
      const V3<ExactN> n =
          A.degree(f) == 3 && A.given_normals.empty() ? triangle_normal(A, f) : A.exact_normal(f);
      // h_A(N_f) = max over f's corners of <n, X> / W, compared by cross-multiplication
      // (W > 0; W = 1 for double points, and for the exact sums of a closing): no
      // rationals, no gcd. A triangle of double points holds its corners exactly on the
      // plane of its Newell normal.
      int best = 0;
      if (A.degree(f) == 3 && A.given_normals.empty()) {
        dots.assign(1, homogeneous_dot(A, n, A.corner(f, 0)));
        on[0] = on[1] = on[2] = 1;
      } else {
        dots.clear();
        for (int k = 0; k < A.degree(f); ++k) {
          dots.push_back(homogeneous_dot(A, n, A.corner(f, k)));
          if (k > 0 && compare(dots[k], dots[best]) > 0) best = k;
        }
        for (int k = 0; k < A.degree(f); ++k) on[k] = k == best || same(dots[k], dots[best]);
      }
      const Homogeneous& top = dots[best];
      // h_A - h_B = (p V - q W) / (W V) for h_A = p / W, h_B = q / V.
      const Homogeneous hb = homogeneous_dot(B, n, b);
      for (int c : candidates) {
        if (c != b && same(homogeneous_dot(B, n, c), hb)) others[f].push_back(c);
      }
      h.normal() = n;
      if (top.weight == 1 && hb.weight == 1) {
        h.offset() = top.value - hb.value;
      } else {
        h.offset() = top.value * hb.weight - hb.value * top.weight;
        h.set_denominator(top.weight * hb.weight);
      }
    }
  });
  ErosionInput in;
  in.known = erosion_points(A, B, contributing, others, on_plane, sum_of_b);
  // A point usually inside: A's vertex centroid minus B's.
  V3<double> ca{0, 0, 0}, cb{0, 0, 0};
  for (const auto& p : A.points) ca = ca + p;
  for (const auto& p : B.points) cb = cb + p;
  const double ka = 1.0 / A.num_vertices(), kb = 1.0 / B.num_vertices();
  in.hint = {ca.x * ka - cb.x * kb, ca.y * ka - cb.y * kb, ca.z * ka - cb.z * kb};
  in.halfspaces = std::move(hs);
  // Each plane through its triangle's corners exactly (the branch above for every facet):
  // the guess's signs that A's own convexity makes certain are not tested.
  // (Only triangles: three corners a facet, as check_gauss_map tells them.)
  const bool exact_triangles = A.given_normals.empty() && A.exact_points.empty() &&
                               B.exact_points.empty() &&
                               A.corner_vertex.size() == 3 * static_cast<std::size_t>(nf);
  if (expected.fans_of_operand && exact_triangles) expected.moved_by = std::move(contributing);
  in.expected = std::move(expected);
  return in;
}

MaybePolytope intersect(const ErosionInput& in, const IntersectOptions& options) {
  return intersect_halfspaces(in.halfspaces, in.hint, options, in.known, in.expected);
}

/// A's vertex fans as the polygons of a guess, with A's edges between their facets (each
/// polygon's sides joined by edge, ExpectedVertices::edge).
ExpectedVertices fans_of(const Polytope& A) {
  ExpectedVertices fans;
  fans.begin = A.fan_begin;
  fans.facets = A.fan_face;
  fans.edge = A.fan_edge;
  fans.edges = A.num_edges();
  return fans;
}

}  // namespace

MaybePolytope erode_polytope(const Polytope& A, const Polytope& B,
                             const IntersectOptions& options) {
  // Facet f of A is half-space f: A's fans are the polygons of the guess. The input is
  // shared with the result, whose lazy exact points (an opening) read its planes and known
  // points rather than copies.
  ExpectedVertices guess = fans_of(A);
  guess.fans_of_operand = true;
  const auto in =
      std::make_shared<const ErosionInput>(erosion_input(A, B, SumOfB::no, std::move(guess)));
  return intersect_halfspaces(in->halfspaces, in->hint, options, in->known, in->expected, in);
}

MaybePolytope erode_sum(const Polytope& S, const Polytope& A, const Polytope& B,
                        const IntersectOptions& options) {
  return intersect(erode_sum_input(S, A, B), options);
}

ErosionInput erode_sum_input(const Polytope& S, const Polytope& A, const Polytope& B) {
  // S's facet of each facet f of A: the one made from SumFacets facet f (translated).
  std::vector<int> facet_of(A.num_faces(), -1);
  for (int g = 0; g < S.num_faces(); ++g)
    if (S.face_source[g] < A.num_faces()) facet_of[S.face_source[g]] = g;
  ExpectedVertices expected;
  if (std::find(facet_of.begin(), facet_of.end(), -1) == facet_of.end()) {
    expected = fans_of(A);
    expected.split = false;
    for (int& f : expected.facets) f = facet_of[f];
  }
  return erosion_input(S, B, S.sum_pairs.empty() ? SumOfB::no : SumOfB::yes, std::move(expected));
}

namespace {

/// Whether facet f of P (double points) is exactly planar; its exact Newell normal into
/// `normal` (when not null) if it is. A triangle is, and its normal is (q - p) x (r - p), the
/// same value.
bool planar_normal(const Polytope& P, int f, V3<ExactN>* normal) {
  if (P.degree(f) == 3) {
    if (normal) *normal = triangle_normal(P, f);
    return true;
  }
  std::vector<V3<ExactN>> cycle;
  cycle.reserve(P.degree(f));
  for (int k = 0; k < P.degree(f); ++k) cycle.push_back(to_exact_n(P.points[P.corner(f, k)]));
  const V3<ExactN> n =
      newell_normal<ExactN>(P.degree(f), [&](int i) -> const V3<ExactN>& { return cycle[i]; });
  const V3<double>& p = P.points[P.corner(f, 0)];
  for (int k = 1; k < P.degree(f); ++k)
    if (CGAL::sign(dot(n, exact_difference(P.points[P.corner(f, k)], p))) != 0) return false;
  if (normal) *normal = n;
  return true;
}

/// Whether the cycle of `d` vertices of P read by vertex_at(k) is facet f's (f >= 0), in the
/// same order from any start.
template <class VertexAt>
bool same_cycle(const Polytope& P, int f, int d, const VertexAt& vertex_at) {
  if (f < 0 || P.degree(f) != d) return false;
  int start = 0;
  while (start < d && P.corner(f, start) != vertex_at(0)) ++start;
  if (start == d) return false;
  for (int k = 1; k < d; ++k)
    if (P.corner(f, (start + k) % d) != vertex_at(k)) return false;
  return true;
}

}  // namespace

Closing close_polytope(const Polytope& A, const Polytope& B, const IntersectOptions& options) {
  SumFacets sum = fims_facets(A, B);
  if (std::optional<ErosionInput> in = closing_input(sum, A, B))
    return {intersect(*in, options), std::move(sum.origins)};
  // A facet of A or B is planar only within the tolerance (see the header).
  std::optional<Polytope> S;
  try {
    S = sum_polytope(A, B, sum);
  } catch (const not_convex&) {
    // S's normals fold: the rounded route below.
  }
  if (S && S->num_faces() == sum.num_faces()) {
    // A's vertices split where its facets are only nearly planar: the guess goes on from
    // there (split), its flips and the check's repair taking off the facets of S that
    // vanish and putting in those that cut it.
    ErosionInput in = erode_sum_input(*S, A, B);
    in.expected.split = true;
    return {intersect(in, options), std::move(sum.origins)};
  }
  LabelledMesh rounded = sum_mesh(A, B, std::move(sum));
  const Polytope R = make_operand(rounded.mesh, "A (+) B");
  return {erode_polytope(R, B, options), std::move(rounded.origins)};
}

std::optional<ErosionInput> closing_input(const SumFacets& sum, const Polytope& A,
                                          const Polytope& B) {
  const int nf = sum.num_faces(), na = A.num_faces();
  const bool doubles = A.exact_points.empty() && B.exact_points.empty();
  HalfSpaces hs(nf);
  std::vector<int> contributing(nf);
  // Facet g's further vertices of B attaining h_B: a span of B's corners (those of a facet
  // after its first) or of one[g] (an edge's other end); no list per facet to allocate.
  std::vector<std::span<const int>> others(nf);
  std::vector<int> one(nf);
  std::atomic<bool> general{!doubles};
  // (For the fixed-point frames below: A's, B's and S's, a dozen or more per vertex.)
  const std::vector<fixed::Span> spans_a = doubles ? vertex_spans(A) : std::vector<fixed::Span>(),
                                 spans_b = doubles ? vertex_spans(B) : std::vector<fixed::Span>();
  // Each facet of S is usually translated (one vertex of B: A's facet, in A's order), a
  // corner (one vertex of A: a facet of B) or a parallelogram (an edge of each). A's and B's
  // facets must be exactly planar (each is checked where it lies in S: A's facet g in S's
  // facet g, B's in the one facet of S along its normal); otherwise the closing goes through
  // S.
  parallel_chunks(doubles ? nf : 0, 64, [&](int begin, int end) {
    for (int g = begin; g < end && !general.load(std::memory_order_relaxed); ++g) {
      const int c0 = sum.face_begin[g], d = sum.face_begin[g + 1] - c0;
      const auto i_at = [&](int k) { return pair_first(sum.corners[c0 + k]); };
      const auto j_at = [&](int k) { return pair_second(sum.corners[c0 + k]); };
      bool one_i = true, one_j = true;
      for (int k = 1; k < d; ++k) {
        one_i = one_i && i_at(k) == i_at(0);
        one_j = one_j && j_at(k) == j_at(0);
      }
      HalfSpace& h = hs[g];
      int b = -1;
      // B's facet f's corners after its first; edge e's other end.
      const auto facet_others = [&](int f) {
        others[g] = {&B.corner_vertex[B.face_begin[f] + 1],
                     static_cast<std::size_t>(B.degree(f) - 1)};
      };
      const auto edge_other = [&](int e) {
        one[g] = B.edges[e].to;
        others[g] = {&one[g], 1};
      };
      bool found = false;   // h's normal is S's normal n (the faces along n exactly planar)
      bool simple = false;  // translated, corner or parallelogram: n from A's or B's facet
      // h's offset is <n, a> for a corner (a, b_j) of the facet (see below).
      const V3<double>& a = A.points[i_at(0)];
      bool offset_set = false;
      // h's normal 2^doubling (x1 - x0) x (y1 - y0) and offset <n, a> in fixed point
      // (wide_exact.h) when the doubles allow, lazy as the erosion's (set_fixed_plane: making
      // the exact values and their enclosures was a third of the closing's input); false
      // when they do not. `span`: that of x0, x1, y0 and y1 (a's is added here).
      const auto fixed_plane = [&](const V3<double>& x0, const V3<double>& x1, const V3<double>& y0,
                                   const V3<double>& y1, int doubling, fixed::Span span) {
        span.add(spans_a[i_at(0)]);
        const fixed::Frame frame(span);
        if (!frame.ok) return false;
        const fixed::Normal n(frame, x0, x1, y0, y1);
        offset_set = true;
        set_fixed_plane(h, n, doubling, a, nullptr);
        return true;
      };
      // planar_normal into h's normal; a triangle's (its normal (q - p) x (r - p)) in fixed
      // point first.
      const auto planar = [&](const Polytope& P, int f) {
        if (P.degree(f) == 3) {
          const V3<double>& p = P.points[P.corner(f, 0)];
          const std::vector<fixed::Span>& spans = &P == &A ? spans_a : spans_b;
          fixed::Span span = spans[P.corner(f, 0)];
          span.add(spans[P.corner(f, 1)]);
          span.add(spans[P.corner(f, 2)]);
          if (fixed_plane(p, P.points[P.corner(f, 1)], p, P.points[P.corner(f, 2)], 0, span))
            return true;
        }
        return planar_normal(P, f, &h.normal());
      };
      if (one_j && g < na && same_cycle(A, g, d, i_at)) {
        simple = true;
        found = planar(A, g);
        b = j_at(0);
      } else if (one_i) {
        const int e = d >= 3 ? B.edge_between(j_at(0), j_at(1)) : -1;
        const int f = e < 0 ? -1 : B.edges[e].from == j_at(0) ? B.edges[e].left : B.edges[e].right;
        if (same_cycle(B, f, d, j_at)) {
          simple = true;
          found = planar(B, f);
          b = B.corner(f, 0);
          facet_others(f);
        }
      } else if (d == 4) {
        // A parallelogram: each side moves one operand's vertex, alternately. Its Newell
        // normal is twice (P1 - P0) x (P2 - P1).
        bool parallelogram = true;
        const V3<double>* side[2][2];  // side k runs from side[k][0] to side[k][1]
        fixed::Span span;              // theirs
        for (int k = 0; k < 4 && parallelogram; ++k) {
          const int l = (k + 1) % 4;
          const bool moves_a = i_at(k) != i_at(l), moves_b = j_at(k) != j_at(l);
          const bool like_first = moves_a == (i_at(0) != i_at(1));
          parallelogram = moves_a != moves_b && like_first == (k % 2 == 0);
          if (parallelogram && k < 2) {
            side[k][0] = moves_a ? &A.points[i_at(k)] : &B.points[j_at(k)];
            side[k][1] = moves_a ? &A.points[i_at(l)] : &B.points[j_at(l)];
            span.add(moves_a ? spans_a[i_at(k)] : spans_b[j_at(k)]);
            span.add(moves_a ? spans_a[i_at(l)] : spans_b[j_at(l)]);
          }
        }
        const int e = parallelogram ? B.edge_between(j_at(0), j_at(2)) : -1;
        if (e >= 0) {
          simple = true;
          if (!fixed_plane(*side[0][0], *side[0][1], *side[1][0], *side[1][1], 1, span)) {
            const V3<ExactN> m = cross(exact_difference(*side[0][1], *side[0][0]),
                                       exact_difference(*side[1][1], *side[1][0]));
            h.normal() = {m.x + m.x, m.y + m.y, m.z + m.z};
          }
          found = true;
          b = B.edges[e].from;
          edge_other(e);
        }
      }
      if (!simple) {
        // Parallel features summed into one polygon (f + an edge or a facet of B, a facet
        // of B + an edge of A, parallel edges): B's face along n is spanned by the distinct
        // j (a vertex, an edge, or a whole facet of B), moved as erode moves it, and n is
        // the Newell normal of the exact sums, as sum_polytope makes it. A's facet g, and
        // B's facet, must be planar as above.
        std::vector<int> is, js;
        for (int k = 0; k < d; ++k) {
          if (std::find(is.begin(), is.end(), i_at(k)) == is.end()) is.push_back(i_at(k));
          if (std::find(js.begin(), js.end(), j_at(k)) == js.end()) js.push_back(j_at(k));
        }
        // A's face along n: facet g of A (FIMS's translated facets come first, in A's
        // order), or a vertex or an edge.
        bool known_face = g < na ? planar_normal(A, g, nullptr) : is.size() <= 2;
        if (js.size() == 1) {
          b = js[0];
        } else if (js.size() == 2) {
          const int e = B.edge_between(js[0], js[1]);
          known_face = known_face && e >= 0;
          if (e >= 0) {
            b = B.edges[e].from;
            edge_other(e);
          }
        } else {
          int f = -1;
          for (int s = B.fan_begin[js[0]]; s < B.fan_begin[js[0] + 1] && f < 0; ++s) {
            const int c = B.fan_face[s];
            if (B.degree(c) != static_cast<int>(js.size())) continue;
            bool all = true;
            for (int k = 0; k < B.degree(c) && all; ++k)
              all = std::find(js.begin(), js.end(), B.corner(c, k)) != js.end();
            if (all) f = c;
          }
          known_face = known_face && f >= 0 && planar_normal(B, f, nullptr);
          if (known_face) {
            b = B.corner(f, 0);
            facet_others(f);
          }
        }
        if (known_face) {
          std::vector<V3<ExactN>> cycle(d);
          for (int k = 0; k < d; ++k)
            cycle[k] = to_exact_n(A.points[i_at(k)]) + to_exact_n(B.points[j_at(k)]);
          h.normal() =
              newell_normal<ExactN>(d, [&](int k) -> const V3<ExactN>& { return cycle[k]; });
          found = true;
        }
      }
      if (!found) {
        general.store(true, std::memory_order_relaxed);
        break;
      }
      // Every corner (i, j) of the facet lies on its plane, and j on B's face for its normal:
      // h_S - h_B = <n, a_i + b_j> - <n, b_j> = <n, a_i>.
      if (!offset_set) h.offset() = dot(h.normal(), to_exact_n(a));
      h.source = g;
      h.element = B.vertex_source[b];
      contributing[g] = b;
    }
  });
  if (general) return std::nullopt;
  // S's vertices, numbered as sum_polytope numbers them; each facet's corners all on its
  // plane.
  std::vector<std::uint64_t> pairs;
  std::vector<int> corner_vertex;
  index_vertices(sum, A.num_vertices(), B.num_vertices(), pairs, corner_vertex);
  const std::vector<char> on_plane(corner_vertex.size(), 1);
  const auto pair_of = [&](int v) { return pairs[v]; };
  const auto point_of = [&](int v, int b, KnownPoints& known, int k) {
    // (a_i + b_j) - b: a_i when b is j (most points: A's vertices), whose enclosure is the
    // double itself, as to_interval_n gives it (no conversion back from Mpzf).
    const int i = pair_first(pairs[v]), j = pair_second(pairs[v]);
    known.W[k] = ExactN(1);
    known.Wi[k] = Interval(1);
    if (j == b) {
      known.X[k] = to_exact_n(A.points[i]);
      known.Xi[k] = to_interval(A.points[i]);
      return;
    }
    known.X[k] = to_exact_n(A.points[i]) + (to_exact_n(B.points[j]) - to_exact_n(B.points[b]));
    known.Xi[k] = to_interval_n(known.X[k]);
  };
  ErosionInput in;
  in.known = known_points(
      Cycles{sum.face_begin, corner_vertex, static_cast<int>(pairs.size())}, true, A.num_vertices(),
      pair_of, point_of, false, contributing, [&](int g) { return others[g]; }, on_plane);
  // A's vertices, each with S's facets of its facets around it (the same facets by index).
  in.expected = fans_of(A);
  in.expected.split = false;
  // The hint erode gives S: its vertex centroid (the rounded sums) minus B's.
  V3<double> ca{0, 0, 0}, cb{0, 0, 0};
  for (const std::uint64_t key : pairs) {
    const V3<double>&a = A.points[pair_first(key)], &b = B.points[pair_second(key)];
    ca = ca + V3<double>{a.x + b.x, a.y + b.y, a.z + b.z};
  }
  for (const auto& p : B.points) cb = cb + p;
  const double ka = 1.0 / static_cast<double>(pairs.size()), kb = 1.0 / B.num_vertices();
  in.hint = {ca.x * ka - cb.x * kb, ca.y * ka - cb.y * kb, ca.z * ka - cb.z * kb};
  in.halfspaces = std::move(hs);
  return in;
}

}  // namespace morph::detail
