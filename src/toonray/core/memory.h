#pragma once
/// How a rendering process keeps the memory it frees.

namespace toonray {

/// Keeps the memory the process frees for its next allocations instead of handing it back to
/// the system. A frame allocates and frees arrays of tens of megabytes (the BVH build's, the ink
/// lines' per triangle); handed back, each page of them is faulted and cleared again by the
/// kernel at its next use, which costs about as much as the work done on it (docs/performance.md).
/// With glibc, allocations up to 32 MiB then come from the heap rather than a mapping of their
/// own, and the heap gives back its free top only beyond 1 GiB. Elsewhere nothing changes.
/// For a process that renders (the command line calls it first): a host application such as
/// Blender keeps its own allocator's policy.
void retain_freed_memory();

}  // namespace toonray
