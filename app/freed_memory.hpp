#pragma once
// Freed memory kept in the process for reuse, by nelf and by the games `nelf run` starts. A live
// frame's views, and the buffer Mesa's software OpenGL allocates at each swap, are blocks of a
// megabyte or more freed a few frames later; glibc hands such blocks back to the kernel (mmap above
// its threshold, the heap's top trimmed), so each frame's buffers were new pages, every one a page
// fault: milliseconds a frame before nelf has it, half a game's frame rate in a virtual machine
// (docs/PERFORMANCE.md, live games). Kept, they are reused: blocks up to 32 MiB (a 4K RGBA8 frame)
// come from the heap, and up to 256 MiB free at its top stays there.
#include <string>

namespace nelf::app {

// For nelf itself (glibc's mallopt).
void keep_freed_memory();

// The same settings as GLIBC_TUNABLES for a game nelf starts, before `user_tunables` (the user's
// own GLIBC_TUNABLES, null or empty when unset), which win: glibc takes the last setting of a name.
std::string freed_memory_tunables(const char* user_tunables);

}  // namespace nelf::app
