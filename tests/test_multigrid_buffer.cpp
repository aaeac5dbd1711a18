// The multigrid's array allocator (runtime/multigrid_buffer.h): every MultigridBuffer(n)
// holds n zeros, also when its block comes back from the cache with old values in it, for
// heap-sized, cached and mapped sizes; blocks are reused for the same size, mapped ones
// for any size of as many 2 MiB granules, and for a larger request within the room a fresh
// mapping leaves (an eighth) or a smaller one of at least half their capacity, which they
// keep when they come back; a request no cached block serves gives cached mapped blocks
// back to the system before it maps its own, unless a cached mapped block of at least half
// its size can be grown to it (its pages kept). Granules faulted in ahead
// (prefault_mapped_blocks, dgtex/step_memory.h) serve fresh mapped blocks without page faults.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "multigrid_buffer.h"

#if defined(__linux__)
#include <sys/resource.h>
#endif

namespace {

using dgtex::detail::MultigridBuffer;

#if defined(__linux__)
long minor_faults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}
#endif

bool all_zero(const MultigridBuffer& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return x == 0.0 && !std::signbit(x); });
}

TEST(MultigridBuffer, FreshBuffersAreZeroForEverySizeClass) {
  // Below the cache bound, cached, and mapped in 2 MiB granules (>= 1 MiB), odd sizes included.
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1000}, std::size_t{8192}, std::size_t{70001},
                        std::size_t{131072}, std::size_t{300007}}) {
    for (int round = 0; round < 3; ++round) {
      MultigridBuffer v(n);
      ASSERT_EQ(v.size(), n);
      EXPECT_TRUE(all_zero(v)) << "size " << n << " round " << round;
      std::fill(v.begin(), v.end(), -7.5);  // leave garbage for the next round's block
    }
  }
}

TEST(MultigridBuffer, ReleasedBlocksAreReusedForTheSameSize) {
  const std::size_t n = 200000;  // 1.6 MB: mapped and cached
  const double* first = nullptr;
  {
    MultigridBuffer v(n);
    first = v.data();
    v[n / 2] = 3.0;
  }
  MultigridBuffer again(n);
  EXPECT_EQ(again.data(), first);  // the cached block, not a new mapping
  EXPECT_TRUE(all_zero(again));
#if defined(__linux__)
  // A mapped block is 2 MiB aligned.
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(again.data()) % (std::uintptr_t{2} << 20), 0u);
#endif
}

TEST(MultigridBuffer, MappedBlocksAreReusedForSizesOfAsManyGranules) {
#if defined(__linux__)
  // 1.6 MB and 1.9 MB both take one 2 MiB granule; 2.4 MB takes two.
  dgtex::detail::release_cached_blocks();  // blocks of the tests before would serve some
  const double* first = nullptr;
  {
    MultigridBuffer v(200000);
    first = v.data();
    std::fill(v.begin(), v.end(), -1.0);
  }
  {
    MultigridBuffer larger(237500);
    EXPECT_EQ(larger.data(), first);
    EXPECT_TRUE(all_zero(larger));
  }
  // Two pages do not fit the cached one: it goes back to the system (its address may be
  // mapped again) and a fresh block is mapped.
  EXPECT_EQ(dgtex::detail::cached_block_bytes(), std::size_t{2} << 20);
  MultigridBuffer two_pages(300000);
  EXPECT_EQ(dgtex::detail::cached_block_bytes(), 0u);
  EXPECT_TRUE(all_zero(two_pages));
#else
  GTEST_SKIP() << "mapped blocks are Linux only";
#endif
}

TEST(MultigridBuffer, MappedBlocksServeAGrowingCutAndKeepTheirCapacity) {
#if defined(__linux__)
  constexpr std::size_t mib = std::size_t{1} << 20, per_mib = mib / sizeof(double);
  dgtex::detail::release_cached_blocks();
  const double* first = nullptr;
  {
    MultigridBuffer v(15 * per_mib);  // 16 MiB of granules asked for, 18 MiB mapped
    first = v.data();
    std::fill(v.begin(), v.end(), -2.0);
  }
  {
    MultigridBuffer grown(17 * per_mib);  // a next model a little larger: the same block
    EXPECT_EQ(grown.data(), first);
    EXPECT_TRUE(all_zero(grown));
    std::fill(grown.begin(), grown.end(), -3.0);
  }
  {
    MultigridBuffer smaller(17 * per_mib / 2);  // 10 MiB of pages: served by the 18 MiB block
    EXPECT_EQ(smaller.data(), first);
    EXPECT_TRUE(all_zero(smaller));
  }
  {
    MultigridBuffer again(17 * per_mib);  // it came back as 18 MiB, not as the 10 it served
    EXPECT_EQ(again.data(), first);
    EXPECT_TRUE(all_zero(again));
  }
  // 4 MiB: not served by the 18 MiB block (more than twice), which goes back to the system
  // to make room for the new mapping.
  EXPECT_EQ(dgtex::detail::cached_block_bytes(), 18 * mib);
  MultigridBuffer other(3 * per_mib);
  EXPECT_EQ(dgtex::detail::cached_block_bytes(), 0u);
  EXPECT_TRUE(all_zero(other));
#else
  GTEST_SKIP() << "mapped blocks are Linux only";
#endif
}

// A cut's rest sums outgrow the room of their blocks every few steps (two blocks at a time:
// the last model's and the next one's). A request that no cached block serves but that a
// cached mapped block of at least half its size could hold once grown takes that block,
// moved to a mapping of the request's fresh capacity: its pages come along (only the new
// tail is faulted in), where a fresh block faulted in every page.
TEST(MultigridBuffer, ACachedMappedBlockTooSmallForARequestIsGrownWithItsPages) {
#if defined(__linux__)
  constexpr std::size_t mib = std::size_t{1} << 20;
  dgtex::detail::release_cached_blocks();
  const std::size_t small = 15 * mib, large = 20 * mib;
  {
    auto* block = static_cast<unsigned char*>(dgtex::detail::acquire_zeroed_block(small));  // 18 MiB mapped
    std::fill(block, block + small, 0x5a);
    dgtex::detail::release_block(block, small);
  }
  ASSERT_EQ(dgtex::detail::cached_block_bytes(), 18 * mib);
  unsigned char* grown = nullptr;
  {
    const dgtex::detail::SkipCachedBlockZeroing look_at_what_it_holds;
    grown = static_cast<unsigned char*>(dgtex::detail::acquire_zeroed_block(large));
  }
  EXPECT_EQ(dgtex::detail::cached_block_bytes(), 0u);  // the 18 MiB block was taken
  EXPECT_TRUE(std::all_of(grown, grown + small, [](unsigned char b) { return b == 0x5a; })) << "its old pages";
  EXPECT_TRUE(std::all_of(grown + 18 * mib, grown + large, [](unsigned char b) { return b == 0; })) << "the new tail";
  const long faults_before = minor_faults();
  std::fill(grown, grown + large, 0x33);  // every page written
  const long faults = minor_faults() - faults_before;
#if !defined(__SANITIZE_ADDRESS__)  // ASan's shadow pages fault in beside the block's
  // Only the 5 MiB the old block had never written (1280 pages; a fresh block: 5120).
  EXPECT_LT(faults, 5 * 256 + 64) << "20 MiB written, 15 of them in the grown block's old pages";
#else
  (void)faults;
#endif
  dgtex::detail::release_block(grown, large);
  // Cached with the capacity of a fresh block for 20 MiB (an eighth more, in granules), so
  // the zeroed buffers of the next models take it as it is.
  EXPECT_EQ(dgtex::detail::cached_block_bytes(), 24 * mib);
  MultigridBuffer next(21 * mib / sizeof(double));
  EXPECT_EQ(reinterpret_cast<const unsigned char*>(next.data()), grown);
  EXPECT_TRUE(all_zero(next));
#else
  GTEST_SKIP() << "mapped blocks are Linux only";
#endif
}

TEST(MultigridBuffer, PrefaultedGranulesServeFreshMappedBlocksWithoutPageFaults) {
#if defined(__linux__)
  constexpr std::size_t mib = std::size_t{1} << 20, per_mib = mib / sizeof(double);
  dgtex::detail::release_cached_blocks();  // no cached block may serve the request below
  dgtex::detail::prefault_mapped_blocks(7 * mib);
  EXPECT_EQ(dgtex::detail::prefaulted_block_bytes(), 8 * mib);  // whole granules
  dgtex::detail::prefault_mapped_blocks(2 * mib);  // less than is left: kept as it is
  EXPECT_EQ(dgtex::detail::prefaulted_block_bytes(), 8 * mib);
  const long faults_before = minor_faults();
  const double* block = nullptr;
  {
    MultigridBuffer v(3 * per_mib);  // 3 MiB and its eighth of room: 4 MiB of the granules
    block = v.data();
    EXPECT_EQ(dgtex::detail::prefaulted_block_bytes(), 4 * mib);
    EXPECT_TRUE(all_zero(v));
    std::fill(v.begin(), v.end(), 5.0);  // all its 768 pages written
  }
  const long faults = minor_faults() - faults_before;
#if !defined(__SANITIZE_ADDRESS__)  // ASan's shadow pages fault in beside the block's
  EXPECT_LT(faults, 16) << "3 MiB written in prefaulted granules";
#else
  (void)faults;
#endif
  // Back from the cache, not from the granules left.
  MultigridBuffer again(3 * per_mib);
  EXPECT_EQ(again.data(), block);
  EXPECT_TRUE(all_zero(again));
  EXPECT_EQ(dgtex::detail::prefaulted_block_bytes(), 4 * mib);
  dgtex::detail::prefault_mapped_blocks(16 * mib);  // more than is left: topped up
  EXPECT_EQ(dgtex::detail::prefaulted_block_bytes(), 16 * mib);
#else
  GTEST_SKIP() << "mapped blocks are Linux only";
#endif
}

}  // namespace
