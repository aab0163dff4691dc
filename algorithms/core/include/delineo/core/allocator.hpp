#pragma once
// Process set-up of the C library's allocator, for the programs that run the algorithms on large
// images (the CLI, the GUI, the benchmarks). The algorithms themselves never call it.

namespace delineo::core {

// Buffers of up to 32 MB (a 2800² float image) are taken from the heap and reused once freed,
// instead of being mapped fresh for each (a page fault per 4 KiB) and unmapped when freed; up to
// 128 MB freed at the top of the heap are kept for the next ones. A match's stages allocate and
// free many image-sized buffers: at 1000² / 128 d a CLI match took ~15 k fewer page faults and
// ~4 % less CPU (docs/stereo.md, "Threads, progress, cancel, memory"). Call it first thing in
// main(), once; returns whether the allocator took the settings (false where the C library is
// not glibc).
bool tuneAllocatorForLargeImages();

}  // namespace delineo::core
