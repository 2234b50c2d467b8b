// The apps' and the benchmark's setting of the C library's allocator: a host program's choice,
// never the library's (libmorph leaves its host's allocator alone).
#pragma once

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace morph::cli {

/// Keeps memory freed by one operation for the next instead of handing it back to the system.
/// A morphology operation allocates and frees a few hundred arrays, about 2 MB for a
/// 2000-facet result and far more for large ones. With glibc's defaults the free top of the
/// heap goes back to the system whenever it passes 128 KB (M_TRIM_THRESHOLD) and is taken
/// again, page fault by page fault, by the next operation; whether that happens on every
/// operation depends on where long-lived blocks happened to land. Measured on icosphere
/// 5120 (+) a rotated copy: 720 page faults and 3.78 ms per sum with the defaults, 3 and 3.03 ms
/// with these settings; outputs are the same. Costs: up to 64 MB of freed memory stays with
/// the process, and blocks below 32 MB come from the heap rather than from fresh mappings.
inline void keep_freed_memory() {
#if defined(__GLIBC__)
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest allowed value on 64-bit systems
#endif
}

}  // namespace morph::cli
