// Two doubles operated on lane by lane (GCC and Clang vector extensions), for code that does one
// element's arithmetic for two elements at once (the operand check's faces, the joining step's
// facets). Each lane's operation is the scalar one (IEEE), so each lane's value is the value the
// scalar code would compute: callers rely on that for bit-identical results.
#pragma once

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cmath>

namespace morph::detail {

using Pair = double __attribute__((vector_size(16)));

/// std::sqrt lane by lane (one instruction for both).
inline Pair pair_sqrt(Pair x) {
#if defined(__SSE2__)
  return _mm_sqrt_pd(x);
#else
  return Pair{std::sqrt(x[0]), std::sqrt(x[1])};
#endif
}

/// std::max(a, b) (b if a < b, else a: the same for zeros of either sign and NaNs) in one
/// instruction, never a branch (for maxima whose winner is irregular).
inline double max_of(double a, double b) {
#if defined(__SSE2__)
  return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(b), _mm_set_sd(a)));  // b > a ? b : a
#else
  return std::max(a, b);
#endif
}

/// max_of lane by lane.
inline Pair pair_max(Pair a, Pair b) {
#if defined(__SSE2__)
  return _mm_max_pd(b, a);  // b > a ? b : a, lane by lane
#else
  return Pair{max_of(a[0], b[0]), max_of(a[1], b[1])};
#endif
}

/// |x| lane by lane (the sign bit cleared, as std::abs).
inline Pair pair_abs(Pair x) {
  using Bits = long long __attribute__((vector_size(16)));
  constexpr Bits kMagnitude{0x7fffffffffffffffLL, 0x7fffffffffffffffLL};
  return reinterpret_cast<Pair>(reinterpret_cast<Bits>(x) & kMagnitude);
}

/// Whether both lanes of h are <= bound (false for a NaN, as the scalar test).
inline bool both_at_most(Pair h, Pair bound) {
#if defined(__SSE2__)
  return _mm_movemask_pd(_mm_cmple_pd(h, bound)) == 3;
#else
  return h[0] <= bound[0] && h[1] <= bound[1];
#endif
}

/// {a[1], b[0]}: the high lane of a and the low lane of b (one instruction), for values that
/// run on from one pair into the next.
inline Pair pair_high_low(Pair a, Pair b) {
#if defined(__SSE2__)
  return _mm_shuffle_pd(a, b, 1);
#else
  return Pair{a[1], b[0]};
#endif
}

/// The lanes of a comparison of Pairs (a > b and so on: all bits set where it holds).
using PairMask = decltype(Pair{} > Pair{});

/// Whether both lanes of a comparison's mask hold.
inline bool both_true(PairMask mask) {
#if defined(__SSE2__)
  return _mm_movemask_pd(reinterpret_cast<__m128d>(mask)) == 3;
#else
  return mask[0] != 0 && mask[1] != 0;
#endif
}

/// Whether a == b, c == d or e == f in either lane (as the scalar ==: false for a NaN), in one
/// branch.
inline bool any_equal(Pair a, Pair b, Pair c, Pair d, Pair e, Pair f) {
#if defined(__SSE2__)
  const __m128d equal =
      _mm_or_pd(_mm_or_pd(_mm_cmpeq_pd(a, b), _mm_cmpeq_pd(c, d)), _mm_cmpeq_pd(e, f));
  return _mm_movemask_pd(equal) != 0;
#else
  return a[0] == b[0] || a[1] == b[1] || c[0] == d[0] || c[1] == d[1] || e[0] == f[0] ||
         e[1] == f[1];
#endif
}

}  // namespace morph::detail
