#include "dgtex/step_memory.h"

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "multigrid_buffer.h"

namespace dgtex {
namespace {

constexpr std::int64_t mib = std::int64_t{1} << 20;
constexpr std::size_t page = 4096;

#if defined(__GLIBC__)
// Below glibc's largest mmap threshold (32 MiB on 64-bit), so that the chunks come from the
// heap and stay in it once freed.
constexpr std::size_t heap_chunk = std::size_t{16} << 20;

// The most heap an earlier call faulted in (it stays: nothing is trimmed any more).
std::int64_t heap_reserved = 0;
std::mutex heap_mutex;

void keep_freed_memory() {
  static std::once_flag once;
  std::call_once(once, [] {
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
    mallopt(M_ARENA_MAX, 1);
  });
}

// Allocated and written page by page, then freed: the pages stay in the heap for the
// steps' allocations. A top-up takes all `bytes` again: the chunks first get the free pages
// an earlier call faulted in (written again, without faults), then new ones.
void fault_in_heap(std::int64_t bytes) {
  const std::lock_guard<std::mutex> lock(heap_mutex);
  if (bytes <= heap_reserved) return;
  std::vector<char*> chunks;
  bool failed = false;
  for (std::int64_t taken = 0; taken < bytes; taken += static_cast<std::int64_t>(heap_chunk)) {
    char* chunk = static_cast<char*>(std::malloc(heap_chunk));
    if (!chunk) {
      failed = true;
      break;
    }
    // Volatile: the stores go to memory freed unread below, which a compiler may drop.
    volatile char* pages = chunk;
    for (std::size_t k = 0; k < heap_chunk; k += page) pages[k] = 0;
    chunks.push_back(chunk);
  }
  for (char* chunk : chunks) std::free(chunk);
  if (failed) throw std::bad_alloc();
  heap_reserved = bytes;
}
#endif

}  // namespace

void prepare_step_memory() {
#if defined(__GLIBC__)
  keep_freed_memory();
#endif
}

void reserve_step_memory(std::int64_t bytes) {
  if (bytes <= 0) return;
  // Faulted in page by page, more than the memory available is not a std::bad_alloc under
  // the kernel's overcommit but a process killed part way.
  if (const std::int64_t available = available_memory_bytes(); available >= 0 && bytes > available)
    throw std::invalid_argument("reserve_step_memory: " + std::to_string(bytes) + " bytes is more than the " +
                                std::to_string(available) +
                                " bytes of memory available; reserve less (step_memory_bytes takes at most a quarter)");
  prepare_step_memory();
#if defined(__GLIBC__)
  fault_in_heap(bytes - bytes / 3);
#endif
  detail::prefault_mapped_blocks(static_cast<std::size_t>(bytes / 3));
}

std::int64_t step_memory_bytes(const TexelFields& fields, std::int64_t available_bytes) {
  const std::int64_t bytes = std::min(6 * texel_memory_lower_bound(fields), 512 * mib);
  return available_bytes >= 0 ? std::min(bytes, available_bytes / 4) : bytes;
}

}  // namespace dgtex
