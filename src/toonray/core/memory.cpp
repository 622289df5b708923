#include "toonray/core/memory.h"

#include <cstdlib>  // defines __GLIBC__ with glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace toonray {

void retain_freed_memory() {
#if defined(__GLIBC__)
    // 32 MiB is the largest threshold glibc accepts on 64-bit systems; setting it also stops
    // glibc from moving it, and the trim threshold, as blocks are freed.
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

}  // namespace toonray
