// The fixed-point plane data of an erosion (libmorph/src/wide_exact.h): normals, offsets and
// signs of dot products must be exactly the Mpzf values, in both word sizes (a small frame and
// a large one), and a normal's double-double copy within its bound, on nearly degenerate
// triangles, points scaled by 2^+-200, shifted far from the origin, with zeros, tiny
// coordinates and subnormals; a frame it cannot hold (an infinity, doubles too far apart) must
// say so.
#include "wide_exact.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>

namespace {

using namespace morph::detail;

struct Case {
  V3<double> p, q, r, b;
};

/// Checks fixed::Normal against Mpzf on the triangle (p, q, r) and the point b; whether the
/// frame was small, large, or not ok (0, 1, 2).
int check(const Case& c) {
  const V3<double>&p = c.p, &q = c.q, &r = c.r, &b = c.b;
  const fixed::Frame frame{p.x, p.y, p.z, q.x, q.y, q.z, r.x, r.y, r.z, b.x, b.y, b.z};
  if (!frame.ok) return 2;
  const V3<ExactN> n = cross(exact_difference(q, p), exact_difference(r, p));
  const fixed::Normal f(frame, p, q, p, r);
  V3<ExactN> fn;
  f.set_normal(0, fn);
  CHECK(fn.x == n.x);
  CHECK(fn.y == n.y);
  CHECK(fn.z == n.z);
  V3<ExactN> doubled;
  f.set_normal(1, doubled);
  CHECK(doubled.x == n.x + n.x);
  CHECK(doubled.z == n.z + n.z);
  std::array<DD, 3> dd;
  if (f.normal_dd(1, dd)) {
    // Within 2^-104 of |hi| (HalfSpace::normal_dd asks 2^-101), |lo| at most half an ulp.
    const ExactN* exact[3] = {&doubled.x, &doubled.y, &doubled.z};
    for (int k = 0; k < 3; ++k) {
      const ExactN error = ExactN(dd[k].hi) + ExactN(dd[k].lo) - *exact[k];
      CHECK(CGAL::abs(error) * ExactN(0x1p104) <= CGAL::abs(ExactN(dd[k].hi)));
      const double half_ulp = 0.5 * std::abs(std::nextafter(dd[k].hi, 0.0) - dd[k].hi);
      CHECK(std::abs(dd[k].lo) <= half_ulp);
    }
  } else {
    const bool in_range = frame.small && std::abs(frame.unit) < 400;
    CHECK_FALSE(in_range);
  }
  const ExactN offset = dot(n, exact_difference(p, b));
  ExactN fo;
  f.set_dot(0, p, &b, fo);
  CHECK(fo == offset);
  CHECK(f.sign_dot(p, b) == CGAL::sign(offset));
  CHECK(f.sign_dot(b, q) == CGAL::sign(dot(n, exact_difference(b, q))));
  ExactN at_b;
  f.set_dot(1, b, nullptr, at_b);
  const ExactN expected = dot(n, to_exact_n(b));
  CHECK(at_b == expected + expected);
  return frame.small ? 0 : 1;
}

V3<double> scaled(const V3<double>& v, int e) {
  return {std::ldexp(v.x, e), std::ldexp(v.y, e), std::ldexp(v.z, e)};
}

}  // namespace

TEST_CASE("fixed-point plane data equals the Mpzf values on adversarial triangles") {
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> spread(-70, 70);
  int routes[3] = {0, 0, 0};
  const auto point = [&](int mode) {
    V3<double> v{unit(rng), unit(rng), unit(rng)};
    if (mode == 1) v = {std::ldexp(v.x, spread(rng)), std::ldexp(v.y, spread(rng)), v.z};
    if (mode == 2) v = {v.x + 1e6, v.y - 3e5, v.z};  // far from the origin
    if (rng() % 6 == 0) v.y = 0;
    if (rng() % 7 == 0) v.z = -0.0;
    return v;
  };
  for (int it = 0; it < 4000; ++it) {
    const int mode = it % 3;
    Case c{point(mode), point(mode), point(mode), point(mode)};
    if (it % 4 == 1) {
      // Nearly degenerate: q and r within a few ulps of p (a sliver, nearly zero normal).
      c.q = {std::nextafter(c.p.x, 2.0), c.p.y, std::nextafter(c.p.z, -2.0)};
      c.r = {c.p.x, std::nextafter(c.p.y, 2.0), std::nextafter(c.p.z, 2.0)};
    }
    if (it % 4 == 2) {
      // b on the plane through p, q, r (offset zero): b = p + (q - p) + (r - p) when exact.
      c.q = {c.p.x + 0.5, c.p.y, c.p.z};
      c.r = {c.p.x, c.p.y + 0.25, c.p.z};
      c.b = {c.p.x + 0.5, c.p.y + 0.25, c.p.z};
    }
    const int e = (it % 5 - 2) * 100;  // scaled by 2^-200 .. 2^200
    for (V3<double>* v : {&c.p, &c.q, &c.r, &c.b}) *v = scaled(*v, e);
    ++routes[check(c)];
  }
  // Both word sizes and the refusal were exercised.
  CHECK(routes[0] > 100);
  CHECK(routes[1] > 100);
  CHECK(routes[2] > 10);
}

TEST_CASE("fixed-point frames refuse what they cannot hold") {
  REQUIRE(fixed::exponent_shift_works());  // else every frame refuses (this CGAL's Mpzf)
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(fixed::Frame{1.0, inf}.ok);
  CHECK_FALSE(fixed::Frame{1.0, nan}.ok);
  CHECK_FALSE(fixed::Frame{1.0, 0x1p-120}.ok);  // 2^121 apart: beyond 116 bits
  const fixed::Frame wide{1.0, 0x1p-100};
  CHECK(wide.ok);
  CHECK_FALSE(wide.small);
  const fixed::Frame near{0.75, 0x1p-50, 0.0, -0.0};
  CHECK(near.small);
  CHECK(near.small_at(0.75) == std::int64_t{3} << 48);
  CHECK(near.small_at(-0.0) == 0);
  // Subnormals: exact in the large frame, never small (2^1074 is no double).
  const double tiny = std::numeric_limits<double>::denorm_min();
  const fixed::Frame sub{tiny, 3 * tiny};
  CHECK(sub.ok);
  CHECK_FALSE(sub.small);
  Case c{{tiny, 0, 0}, {0, 2 * tiny, 0}, {0, 0, 5 * tiny}, {-tiny, tiny, 0}};
  CHECK(check(c) == 1);
  // All zero: a zero normal and offset.
  Case z{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  CHECK(check(z) == 0);
}
