// Private: the one place libmorph touches TBB. Loops run sequentially below a cut-off,
// and every loop body that evaluates predicates sets its own rounding mode.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <exception>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

namespace morph::detail {

/// The cap a caller set on TBB's threads with tbb::global_control (max_allowed_parallelism),
/// or more than any arena has. An arena's max_concurrency does not see it, and the loops that
/// choose a sequential or a side-by-side path by the arena's count would otherwise take the
/// side-by-side one with a single thread to run it (each operand's check and build then run one
/// after the other, the build redoing what the check found: 40% more time).
inline int global_thread_limit() {
  return static_cast<int>(std::min<std::size_t>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism), 1 << 20));
}

/// The calling thread's arena of `threads` threads (at most the number of cores and the
/// global cap), made on
/// first use and kept: a new arena per operation costs tens of microseconds at two threads
/// (its worker is requested and woken again each time), a lot for small operands. One per
/// calling thread, so concurrent callers each get their threads, as with an arena per call.
inline tbb::task_arena& arena_for(int threads) {
  // More threads than cores buys nothing and makes TBB print a warning.
  const int n = std::max(
      1, std::min({threads, tbb::info::default_concurrency(), global_thread_limit()}));
  thread_local std::vector<std::unique_ptr<tbb::task_arena>> arenas;
  if (static_cast<int>(arenas.size()) <= n) arenas.resize(n + 1);
  if (!arenas[n]) arenas[n] = std::make_unique<tbb::task_arena>(n);
  return *arenas[n];
}

/// arena.execute(f), its result made in place in the returned object. OpenMesh meshes have
/// no move constructor, so a result returned out of task_arena::execute was a deep copy
/// (about 25 us for the 2180 facets of icosphere 320 + 1280, and some 200 KB beside the
/// original, which made glibc grow and trim its heap more). R must be default
/// constructible: `out` is made, then remade by f() inside the arena.
template <class R, class F>
R execute_in_place(tbb::task_arena& arena, F& f) {
  R out;  // the one return statement: constructed in the caller's result (NRVO)
  arena.execute([&] {
    std::destroy_at(&out);
    try {
      ::new (static_cast<void*>(&out)) R(f());  // a prvalue: no copy, no move
    } catch (...) {
      // `out` must be alive again when the exception unwinds through this frame. Not
      // allowed to throw: a failure here (out of memory) ends the program.
      [&]() noexcept { ::new (static_cast<void*>(&out)) R(); }();
      throw;
    }
  });
  return out;
}

/// Runs f() with at most `threads` worker threads (0: all cores), and never more than a
/// tbb::global_control cap allows: f() sees the threads it gets as its arena's concurrency.
template <class F>
auto run_with_threads(int threads, F&& f) {
  using R = decltype(f());
  if (threads <= 0) {
    // All the calling arena's threads, unless the global cap is below them.
    const int limit = global_thread_limit();
    if (limit >= tbb::this_task_arena::max_concurrency()) return f();
    threads = limit;
  }
  if constexpr (std::is_void_v<R>)
    return arena_for(threads).execute(std::forward<F>(f));
  else
    return execute_in_place<R>(arena_for(threads), f);
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
