#include "toonray/ink/chunks.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace toonray::ink {

void return_free_memory() {
#if defined(__GLIBC__)
    // Also releases free pages inside the arenas, not only at their tops (glibc 2.8 on).
    malloc_trim(0);
#endif
}

}  // namespace toonray::ink
