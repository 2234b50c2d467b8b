// Private: the one place libmorph touches TBB. Loops run sequentially below a cut-off,
// and every loop body that evaluates predicates sets its own rounding mode.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <exception>
#include <memory>
#include <vector>

namespace morph::detail {

/// The calling thread's arena of `threads` threads (at most the number of cores), made on
/// first use and kept: a new arena per operation costs tens of microseconds at two threads
/// (its worker is requested and woken again each time), a lot for small operands. One per
/// calling thread, so concurrent callers each get their threads, as with an arena per call.
inline tbb::task_arena& arena_for(int threads) {
  // More threads than cores buys nothing and makes TBB print a warning.
  const int n = std::min(threads, tbb::info::default_concurrency());
  thread_local std::vector<std::unique_ptr<tbb::task_arena>> arenas;
  if (static_cast<int>(arenas.size()) <= n) arenas.resize(n + 1);
  if (!arenas[n]) arenas[n] = std::make_unique<tbb::task_arena>(n);
  return *arenas[n];
}

/// Runs f() with at most `threads` worker threads (0: all cores).
template <class F>
auto run_with_threads(int threads, F&& f) {
  if (threads <= 0) return f();
  return arena_for(threads).execute(std::forward<F>(f));
}

/// Calls body(begin, end) over [0, n) in chunks of about `grain`, in parallel when n is
/// large enough to pay for it and the arena has more than one thread (a TBB loop costs a
/// few microseconds even with nothing to share; one thread calls body(0, n) directly).
template <class Body>
void parallel_chunks(int n, int grain, const Body& body) {
  if (n <= grain || tbb::this_task_arena::max_concurrency() == 1) {
    if (n > 0) body(0, n);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, n, grain),
                    [&](const tbb::blocked_range<int>& r) { body(r.begin(), r.end()); });
}

/// Runs f() and g(), concurrently when there are threads to spare. If both throw, f's
/// exception is the one rethrown (not whichever came first), so errors are deterministic.
template <class F, class G>
void run_both(const F& f, const G& g) {
  std::exception_ptr ef, eg;
  tbb::parallel_invoke(
      [&] {
        try {
          f();
        } catch (...) {
          ef = std::current_exception();
        }
      },
      [&] {
        try {
          g();
        } catch (...) {
          eg = std::current_exception();
        }
      });
  if (ef) std::rethrow_exception(ef);
  if (eg) std::rethrow_exception(eg);
}

}  // namespace morph::detail
