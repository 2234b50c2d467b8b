// Private: a once-per-flag claim, for values made lazily by whichever thread reads first.
#pragma once

#include <atomic>
#include <thread>

namespace morph::detail {

// The states of a once-flag (run_once).
namespace once_state {
constexpr unsigned char kNone = 0, kRunning = 1, kDone = 2;
}

/// Runs f once for a flag (kNone, kRunning, kDone), in whichever thread asks first, the others
/// waiting for it: an atomic claim. std::call_once makes a futex system call each time it runs
/// f (glibc wakes waiters unconditionally), which cost more than most of what it guards. A
/// claim whose f throws (out of memory) is given back before the exception leaves: a thread
/// waiting for it then claims it in turn instead of waiting forever.
template <class F>
[[gnu::noinline]] void run_once(std::atomic<unsigned char>& state, const F& f) {
  for (;;) {
    unsigned char expected = once_state::kNone;
    if (state.compare_exchange_strong(expected, once_state::kRunning, std::memory_order_acquire)) {
      try {
        f();
      } catch (...) {
        state.store(once_state::kNone, std::memory_order_release);
        throw;
      }
      state.store(once_state::kDone, std::memory_order_release);
      return;
    }
    if (expected == once_state::kDone) return;
    std::this_thread::yield();
  }
}

}  // namespace morph::detail
