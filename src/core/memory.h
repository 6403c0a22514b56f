// Process-wide allocator settings.
#pragma once

#include <malloc.h>

namespace convoy {

// Frames of a megabyte or more are allocated and freed every step. Left to glibc's defaults,
// each would be a fresh mmap whose pages all fault in again, which on a paravirtualised VM
// costs more than the copy itself. Keep such blocks in the heap and reuse them.
inline void tune_allocator_for_frames() {
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
}

}  // namespace convoy
