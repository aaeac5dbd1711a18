#include "multigrid_buffer.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <mutex>
#include <unordered_map>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace dgtex::detail {
namespace {

constexpr std::size_t granule = std::size_t{2} << 20;  // mapped blocks: 2 MiB-aligned, whole granules
constexpr std::size_t min_mapped_bytes = std::size_t{1} << 20;
constexpr std::size_t min_cached_bytes = std::size_t{64} << 10;
constexpr std::size_t max_cached_total = std::size_t{128} << 20;
constexpr int max_cached_blocks = 64;

bool mapped(std::size_t bytes) {
#if defined(__linux__)
  return bytes >= min_mapped_bytes;
#else
  (void)bytes;
  return false;
#endif
}

std::size_t mapped_bytes(std::size_t bytes) { return (bytes + granule - 1) / granule * granule; }

// The size a block is cached under: what it really holds. A mapped block is whole 2 MiB
// granules, so a request a little larger or smaller than the one it was made for can take it
// (a progressive cut's models ask for slightly different sizes from step to step).
std::size_t block_capacity(std::size_t bytes) { return mapped(bytes) ? mapped_bytes(bytes) : bytes; }

// A fresh mapped block is made an eighth larger than asked for (address space only: pages
// nobody writes are never faulted in), so that a cut's next, slightly larger model can take
// it from the cache. The slinky's rest sums grow from 4 to 22 MB over its run.
std::size_t fresh_capacity(std::size_t bytes) { return mapped(bytes) ? mapped_bytes(bytes + bytes / 8) : bytes; }

// A cached mapped block serves a request of at least half its capacity.
bool serves(std::size_t capacity, std::size_t needed) { return capacity >= needed && capacity / 2 <= needed; }

#if defined(__linux__)
// `size` bytes (whole granules) of fresh address space, 2 MiB-aligned.
char* map_granules(std::size_t size) {
  // Over-map by one granule, then unmap the unaligned head and the tail.
  void* raw = mmap(nullptr, size + granule, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  char* base = static_cast<char*>(raw);
  char* aligned = base + (granule - reinterpret_cast<std::uintptr_t>(base) % granule) % granule;
  if (aligned > base) munmap(base, aligned - base);
  char* end = aligned + size;
  if (base + size + granule > end) munmap(end, base + size + granule - end);
  return aligned;
}
#endif

// Granules faulted in ahead of use (prefault_mapped_blocks): fresh mapped blocks are cut from
// the front while it lasts. A block cut from it is unmapped like any other (munmap takes
// part of a mapping).
struct PrefaultedGranules {
  std::mutex mutex;
  char* next = nullptr;
  char* end = nullptr;
};
PrefaultedGranules& prefaulted() {
  static PrefaultedGranules* instance = new PrefaultedGranules;
  return *instance;
}
void* take_prefaulted(std::size_t size) {
  PrefaultedGranules& p = prefaulted();
  const std::lock_guard<std::mutex> lock(p.mutex);
  if (static_cast<std::size_t>(p.end - p.next) < size) return nullptr;
  void* block = p.next;
  p.next += size;
  return block;
}

void* fresh_block(std::size_t bytes) {
#if defined(__linux__)
  if (mapped(bytes)) {
    // No madvise(MADV_HUGEPAGE) since session 58: on virtual machines whose free 2 MiB
    // blocks go back to the host, a fresh huge page is backed again on its first touch, and
    // the advised blocks made the accordion's first step 247-306 instead of 152-160 ms and
    // the first T = 1024 multigrid solve of a process 783-881 instead of 74-77 ms
    // (multigrid_buffer.h).
    return map_granules(fresh_capacity(bytes));
  }
#endif
  void* block = std::calloc(bytes == 0 ? 1 : bytes, 1);
  if (!block) throw std::bad_alloc();
  return block;
}

// capacity: the block's own (block_capacity, or what BlockCache::handed_out recorded).
void free_block(void* block, std::size_t bytes, std::size_t capacity) noexcept {
#if defined(__linux__)
  if (mapped(bytes)) {
    munmap(block, capacity);
    return;
  }
#endif
  (void)capacity;
  std::free(block);
}

struct BlockCache {
  std::mutex mutex;
  struct Entry {
    void* block;
    std::size_t bytes;  // capacity
    std::size_t asked;  // the size it was last asked for (free_block's argument)
  };
  Entry entries[max_cached_blocks];  // oldest first
  int count = 0;
  std::size_t total = 0;

  Entry take(int k) {
    const Entry e = entries[k];
    std::copy(entries + k + 1, entries + count, entries + k);
    --count;
    total -= e.bytes;
    return e;
  }
  // Mapped blocks in use whose capacity is not block_capacity of the size they were asked
  // for (fresh ones with room to grow, cached ones handed to a smaller request).
  std::unordered_map<void*, std::size_t> handed_out;
};

// Blocks taken out of the cache, given back to the system (outside its lock).
void free_entries(const BlockCache::Entry* entries, int count) noexcept {
  for (int k = 0; k < count; ++k) free_block(entries[k].block, entries[k].asked, entries[k].bytes);
}

// Never destroyed: arrays released during static destruction still find it (the process
// returns the cached blocks to the system at exit).
BlockCache& cache() {
  static BlockCache* instance = new BlockCache;
  return *instance;
}

thread_local bool skip_cached_zeroing = false;
std::atomic<bool> poison_unzeroed{false};

}  // namespace

SkipCachedBlockZeroing::SkipCachedBlockZeroing() { skip_cached_zeroing = true; }
SkipCachedBlockZeroing::~SkipCachedBlockZeroing() { skip_cached_zeroing = false; }
void set_poison_unzeroed_blocks(bool poison) noexcept { poison_unzeroed = poison; }
bool poison_unzeroed_blocks() noexcept { return poison_unzeroed; }

std::size_t cached_block_bytes() noexcept {
  BlockCache& c = cache();
  const std::lock_guard<std::mutex> lock(c.mutex);
  return c.total;
}

void release_cached_blocks() noexcept {
  BlockCache& c = cache();
  BlockCache::Entry returned[max_cached_blocks];
  int count = 0;
  {
    const std::lock_guard<std::mutex> lock(c.mutex);
    while (c.count > 0) returned[count++] = c.take(0);
  }
  free_entries(returned, count);
}

namespace {
template <class Buffer>
Buffer frame_zeroed(std::size_t nx_padded, std::size_t ny_padded) {
  using Real = typename Buffer::value_type;
  Buffer v;
  {
    const SkipCachedBlockZeroing skip;
    v = Buffer(nx_padded * ny_padded);
  }
  if (ny_padded == 0) return v;
  Real* a = v.data();
  std::fill(a, a + nx_padded, Real(0));
  std::fill(a + (ny_padded - 1) * nx_padded, a + ny_padded * nx_padded, Real(0));
  for (std::size_t j = 1; j + 1 < ny_padded; ++j) {
    a[j * nx_padded] = Real(0);
    a[j * nx_padded + nx_padded - 1] = Real(0);
  }
  return v;
}
}  // namespace

MultigridBuffer frame_zeroed_buffer(std::size_t nx_padded, std::size_t ny_padded) {
  return frame_zeroed<MultigridBuffer>(nx_padded, ny_padded);
}
FloatMultigridBuffer frame_zeroed_float_buffer(std::size_t nx_padded, std::size_t ny_padded) {
  return frame_zeroed<FloatMultigridBuffer>(nx_padded, ny_padded);
}

namespace {

// A block that held earlier data, handed out: zeroed, or (SkipCachedBlockZeroing) left as it
// is, or filled with NaN bytes where the tests poison unzeroed blocks.
void zero_reused(void* block, std::size_t bytes) {
  if (!skip_cached_zeroing)
    std::memset(block, 0, bytes);
  else if (poison_unzeroed)
    std::memset(block, 0xff, bytes);  // all-ones bytes: a NaN as double and as float
}

// For a mapped request no cached block serves: the largest cached mapped block of at least
// half the capacity it needs, moved (mremap) to a fresh 2 MiB-aligned mapping of
// fresh_capacity(bytes). Its pages go with it, so only the new tail is faulted in, instead of
// every page of a fresh block. Why: a progressive cut's rest sums outgrow the room of their
// blocks every few steps, two blocks at once (the last model's rest data is read while the
// next model's is summed); each fresh 16-21 MB block was 4-5k page faults, +5 ms on spiral6's
// steps 168-169 and 173-174, its slowest. Null where none qualifies or a mapping fails.
void* grow_cached_block(std::size_t bytes) {
#if defined(__linux__)
  BlockCache& c = cache();
  const std::size_t needed = block_capacity(bytes), capacity = fresh_capacity(bytes);
  BlockCache::Entry old{};
  {
    const std::lock_guard<std::mutex> lock(c.mutex);
    int best = -1;
    for (int k = 0; k < c.count; ++k) {
      const std::size_t held = c.entries[k].bytes;
      if (mapped(c.entries[k].asked) && held < needed && 2 * held >= needed && (best < 0 || held > c.entries[best].bytes))
        best = k;
    }
    if (best < 0) return nullptr;
    old = c.take(best);
  }
  char* target = nullptr;
  try {
    target = map_granules(capacity);
  } catch (const std::bad_alloc&) {
    free_block(old.block, old.asked, old.bytes);
    return nullptr;
  }
  // MREMAP_FIXED replaces the mapping at target (the aligned address space just taken).
  void* moved = mremap(old.block, old.bytes, capacity, MREMAP_MAYMOVE | MREMAP_FIXED, target);
  if (moved == MAP_FAILED) {
    munmap(target, capacity);
    free_block(old.block, old.asked, old.bytes);
    return nullptr;
  }
  return moved;
#else
  (void)bytes;
  return nullptr;
#endif
}

}  // namespace

void* acquire_zeroed_block(std::size_t bytes) {
  if (bytes < min_cached_bytes) return fresh_block(bytes);
  BlockCache& c = cache();
  const std::size_t needed = block_capacity(bytes);
  void* block = nullptr;
  {
    const std::lock_guard<std::mutex> lock(c.mutex);
    // The same capacity, the most recently cached first; else (mapped blocks) the smallest
    // that serves the request.
    int best = -1;
    for (int k = c.count - 1; k >= 0; --k) {
      const std::size_t capacity = c.entries[k].bytes;
      if (capacity == needed) {
        best = k;
        break;
      }
      if (mapped(bytes) && serves(capacity, needed) && (best < 0 || capacity < c.entries[best].bytes)) best = k;
    }
    if (best >= 0) {
      const std::size_t capacity = c.entries[best].bytes;
      if (capacity != needed) c.handed_out[c.entries[best].block] = capacity;  // may throw: nothing changed yet
      block = c.take(best).block;
    }
  }
  if (block) {
    zero_reused(block, bytes);
    return block;
  }
  // A fresh block: from the prefaulted granules while they last, else a cached mapped block
  // grown to it, else newly mapped (or calloc).
  bool grown = false;
  if (mapped(bytes)) block = take_prefaulted(fresh_capacity(bytes));
  if (!block && mapped(bytes)) {
    block = grow_cached_block(bytes);
    grown = block != nullptr;
  }
  if (!block && mapped(bytes)) {
    // Cached mapped blocks, oldest first, as much as the new mapping takes, go back to the
    // system first: it hands their pages, which the host has backed, to the new mapping.
    // Kept, they made the accordion's first rest sums (88 MB) fault in pages the host had
    // to back anew after the other scenes of a `bench scenes` run: 129-144 -> 164-176 ms.
    BlockCache::Entry returned[max_cached_blocks];
    int count = 0;
    {
      const std::lock_guard<std::mutex> lock(c.mutex);
      std::size_t freed = 0;
      for (int k = 0; k < c.count && freed < fresh_capacity(bytes);)
        if (mapped(c.entries[k].asked)) freed += c.entries[k].bytes, returned[count++] = c.take(k);
        else ++k;
    }
    free_entries(returned, count);
  }
  if (!block) block = fresh_block(bytes);
  const std::size_t capacity = fresh_capacity(bytes);
  if (capacity != needed) {
    try {
      const std::lock_guard<std::mutex> lock(c.mutex);
      c.handed_out[block] = capacity;
    } catch (...) {
      free_block(block, bytes, capacity);
      throw;
    }
  }
  if (grown) zero_reused(block, bytes);
  return block;
}

void prefault_mapped_blocks(std::size_t bytes) {
#if defined(__linux__)
  const std::size_t size = mapped_bytes(bytes);
  PrefaultedGranules& p = prefaulted();
  const std::lock_guard<std::mutex> lock(p.mutex);
  const std::size_t left = static_cast<std::size_t>(p.end - p.next);
  if (left >= size) return;
  if (left > 0) munmap(p.next, left);
  p.next = p.end = nullptr;
  char* block = map_granules(size);
  // One call instead of a fault per page (Linux 5.14); else a write per page.
#ifdef MADV_POPULATE_WRITE
  if (madvise(block, size, MADV_POPULATE_WRITE) != 0)
#endif
    for (std::size_t k = 0; k < size; k += 4096) block[k] = 0;
  p.next = block;
  p.end = block + size;
#else
  (void)bytes;
#endif
}

std::size_t prefaulted_block_bytes() noexcept {
  PrefaultedGranules& p = prefaulted();
  const std::lock_guard<std::mutex> lock(p.mutex);
  return static_cast<std::size_t>(p.end - p.next);
}

void release_block(void* block, std::size_t bytes) noexcept {
  if (!block) return;
  std::size_t capacity = block_capacity(bytes);
  if (bytes >= min_cached_bytes) {
    BlockCache& c = cache();
    BlockCache::Entry evicted[max_cached_blocks];
    int evictions = 0;
    {
      const std::lock_guard<std::mutex> lock(c.mutex);
      const auto recorded = c.handed_out.find(block);
      if (recorded != c.handed_out.end()) {
        capacity = recorded->second;
        c.handed_out.erase(recorded);
      }
      if (capacity <= max_cached_total) {
        // The oldest blocks make room: the cache had filled with a multigrid's small arrays,
        // and nearly every released block of a cut's rest sums was unmapped (the slinky: 120
        // of its ~130).
        while (c.count == max_cached_blocks || c.total + capacity > max_cached_total) evicted[evictions++] = c.take(0);
        c.entries[c.count++] = {block, capacity, bytes};
        c.total += capacity;
        block = nullptr;
      }
    }
    free_entries(evicted, evictions);
    if (!block) return;
  }
  free_block(block, bytes, capacity);
}

}  // namespace dgtex::detail
