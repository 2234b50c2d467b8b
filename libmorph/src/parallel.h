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

namespace morph::detail {

/// Runs f() with at most `threads` worker threads (0: all cores).
template <class F>
auto run_with_threads(int threads, F&& f) {
  if (threads <= 0) return f();
  // More threads than cores buys nothing and makes TBB print a warning.
  tbb::task_arena arena(std::min(threads, tbb::info::default_concurrency()));
  return arena.execute(std::forward<F>(f));
}

/// Calls body(begin, end) over [0, n) in chunks of about `grain`, in parallel when n is
/// large enough to pay for it.
template <class Body>
void parallel_chunks(int n, int grain, const Body& body) {
  if (n <= grain) {
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
