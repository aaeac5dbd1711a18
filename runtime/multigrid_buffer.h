#pragma once
// Internal: the allocator of the Laplace multigrid's level and CG arrays, also used for the
// rotation clusters' rest sums (shell_model.cpp).
// Why: a hierarchy is built per solve, and its arrays (T = 1024: ~95 MB in ~55 arrays) were
// fresh 4 KiB pages, faulted in one by one and then zero-filled by vector::assign: 18k page
// faults per setup at open T = 1024, ~800 at T = 256 (10% of a whole T = 256 solve).
// - Released blocks of 64 KiB and more are cached per size (see acquire_zeroed_block), so
//   repeated solves on tiles of one size reuse them without faults.
// - Fresh blocks of 1 MiB and more are mapped 2 MiB-aligned, in whole 2 MiB granules (the
//   size of a transparent huge page, which the kernel gives them only where THP is
//   "always"). Until session 58 they were also advised for huge pages (madvise), which had
//   paid when the host had backed the memory (open T = 1024, 1 thread: 221 -> 187 ms) but
//   cost far more when it had not: a VM's free 2 MiB blocks go back to the host and are
//   backed again on first touch. Session 58, this 2-core VM, in one sitting, with the advice
//   against without it: the first T = 1024 multigrid solve of a process 783-881 against
//   74-77 ms, the accordion's first step 247-306 against 152-160 ms, the steps/s the same
//   or better without (examples/bench_scenes_history.md).
// - Blocks come zeroed (kernel, calloc, or one memset for a cached block), and construct()
//   without arguments writes nothing, so `MultigridBuffer(n)` is n zeros in one pass at most.
//   Only a fresh MultigridBuffer(n) is guaranteed zero: never grow one with resize().
// All together with the other memory changes of laplace_multigrid.cpp: open T = 256
// 8.4 -> 7.0 ms, T = 1024 224 -> 176 ms (setup + solve, CPU time, 1 thread).
#include <cstddef>
#include <new>
#include <utility>
#include <vector>

namespace dgtex::detail {

// Zeroed memory for multigrid arrays: bytes >= 1 MiB mapped in 2 MiB granules, smaller
// blocks from calloc. Released blocks of 64 KiB and more are kept (at most 64 blocks and
// 128 MiB per process, the oldest given back to make room; thread-safe) and handed out
// again, zero-filled, for the same size (mapped blocks: the same number of granules): solves
// on tiles of one size (bench repeats, the elements of one enrichment) then pay no page
// faults or munmap/mmap after the first setup. A fresh mapped block has an eighth more room
// (address space only), and a cached mapped block also serves a request of a different size
// that fits and needs at least half of it: a cut's rest sums, a little larger or smaller
// from model to model, take the last model's block (the slinky: 124 of 131 blocks from the
// cache instead of ~10; its system time 0.78-0.84 -> 0.38-0.46 s). A mapped request no
// cached block serves takes the largest cached mapped block of at least half the size it
// needs, grown to it with its pages (mremap: only the new tail is faulted in; spiral6's run
// after its first step 36k -> 10k page faults, the slinky's 33k -> 10k); else it first gives
// cached mapped blocks back to the system, oldest first, as much as it maps, so that the
// mapping gets pages the host has backed.
void* acquire_zeroed_block(std::size_t bytes);
void release_block(void* block, std::size_t bytes) noexcept;
// Faults in `bytes` (whole 2 MiB granules) now, for fresh mapped blocks to take before they
// map new memory: the first multigrid solves of a run then touch no page for the first time
// (dgtex/step_memory.h). Tops up what is left of an earlier call to `bytes`, or keeps it
// where it is as large. Linux only (elsewhere it does nothing). Throws std::bad_alloc.
void prefault_mapped_blocks(std::size_t bytes);
// The prefaulted bytes no block has taken yet.
std::size_t prefaulted_block_bytes() noexcept;

// While an instance lives on a thread, blocks that thread takes from the cache are not
// zero-filled (fresh blocks still are): for arrays whose every entry the owner writes before
// reading it. Used by frame_zeroed_buffer(); never nest it around other allocations.
class SkipCachedBlockZeroing {
 public:
  SkipCachedBlockZeroing();
  ~SkipCachedBlockZeroing();
  SkipCachedBlockZeroing(const SkipCachedBlockZeroing&) = delete;
  SkipCachedBlockZeroing& operator=(const SkipCachedBlockZeroing&) = delete;
};
// Test hooks: the bytes of the blocks the cache holds now (their capacities); every cached
// block given back to the system.
std::size_t cached_block_bytes() noexcept;
void release_cached_blocks() noexcept;
// Test hook: with poisoning on, the blocks that SkipCachedBlockZeroing leaves unzeroed are
// filled with NaN instead, so a read before the first write shows up in results (also the
// arrays of dgtex/scratch_array.h).
void set_poison_unzeroed_blocks(bool poison) noexcept;
bool poison_unzeroed_blocks() noexcept;
// Poisoning on for the life of the object.
struct PoisonUnzeroedBlocksScope {
  PoisonUnzeroedBlocksScope() noexcept { set_poison_unzeroed_blocks(true); }
  ~PoisonUnzeroedBlocksScope() { set_poison_unzeroed_blocks(false); }
  PoisonUnzeroedBlocksScope(const PoisonUnzeroedBlocksScope&) = delete;
  PoisonUnzeroedBlocksScope& operator=(const PoisonUnzeroedBlocksScope&) = delete;
};

template <class T>
struct ZeroedBlockAllocator {
  using value_type = T;

  ZeroedBlockAllocator() = default;
  template <class U>
  ZeroedBlockAllocator(const ZeroedBlockAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) { return static_cast<T*>(acquire_zeroed_block(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { release_block(p, n * sizeof(T)); }

  // Value-initialisation without a write: allocate() hands out zeroed memory.
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  template <class U>
  bool operator==(const ZeroedBlockAllocator<U>&) const noexcept { return true; }
  template <class U>
  bool operator!=(const ZeroedBlockAllocator<U>&) const noexcept { return false; }
};

// A multigrid array (level vectors, operator and interpolation coefficients, CG vectors).
using MultigridBuffer = std::vector<double, ZeroedBlockAllocator<double>>;
// The float preconditioner cycle's level arrays (LaplaceMultigridOptions::single_precision_min_texels).
using FloatMultigridBuffer = std::vector<float, ZeroedBlockAllocator<float>>;

// A padded nx_padded x ny_padded grid array (multigrid_grid.h layout) whose ghost frame is
// zero and whose interior is unspecified (left from the block's last use; NaN when
// poisoned): for level arrays the setup or the solve overwrites completely before any read.
// Why: zero-filling cached blocks was 13% of a T = 1024 setup (memset of ~80 MB).
MultigridBuffer frame_zeroed_buffer(std::size_t nx_padded, std::size_t ny_padded);
FloatMultigridBuffer frame_zeroed_float_buffer(std::size_t nx_padded, std::size_t ny_padded);

}  // namespace dgtex::detail
