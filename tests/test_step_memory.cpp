// Memory reserved for the first steps (dgtex/step_memory.h): what SceneRun reserves for a
// scene's texel fields; a larger reservation tops the heap up to all of it; chad's first
// steps with the reservation fault in almost no page (20k in its first four steps without
// it, 41 with it: session 60, 2-core VM), nor do the accordion's, whose cuts its OpenMP
// threads trace before the reservation (2.9k in its first step before session 65, 10 since).
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "dgtex/step_memory.h"
#include "thread_count_support.h"

#if defined(__linux__)
#include <sys/resource.h>
#endif

namespace {

using namespace dgtex;

constexpr std::int64_t mib = std::int64_t{1} << 20;

TexelFields quad8_cut(int resolution, int region_elements) {
  TexelFields fields;
  fields.type = ElementType::quad8;
  fields.resolution = resolution;
  fields.cuts.fields = 1;
  fields.cuts.region_elements = region_elements;
  return fields;
}

TEST(StepMemory, SixTimesTheFieldsBoundWithinTheCaps) {
  const TexelFields chad = quad8_cut(256, 4);  // 4 tiles of 256^2 texels, 64 bytes each
  EXPECT_EQ(texel_memory_lower_bound(chad), 16 * mib);
  EXPECT_EQ(step_memory_bytes(chad, -1), 96 * mib);  // memory available unknown
  EXPECT_EQ(step_memory_bytes(chad, 4096 * mib), 96 * mib);
  EXPECT_EQ(step_memory_bytes(chad, 200 * mib), 50 * mib);  // a quarter of what is available
  EXPECT_EQ(step_memory_bytes(quad8_cut(1024, 64), -1), 512 * mib);
  EXPECT_EQ(step_memory_bytes(TexelFields{}, -1), 0);  // no fields
}

[[maybe_unused]] long minor_faults() {  // unused where ASan skips the tests below
#if defined(__linux__)
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
#else
  return 0;
#endif
}

// Page faults in the first `steps` steps of an example scene run with the reservation.
[[maybe_unused]] long faults_in_first_steps(const std::string& scene, int steps) {
  SceneRunOptions options;
  options.reserve_step_memory = true;
  SceneRun run(load_scene(std::string(DGTEX_SOURCE_DIR "/examples/scenes/") + scene), options);
  const long before = minor_faults();
  for (int step = 0; step < steps; ++step) run.step();
  return minor_faults() - before;
}

// More than the memory available, faulted in page by page, got the process killed under
// the kernel's overcommit instead of a std::bad_alloc: refused before anything is touched.
TEST(StepMemory, AReservationBeyondTheMemoryAvailableIsRefused) {
  ::setenv("DGTEX_MEMORY_LIMIT_MB", "64", 1);  // this test's own process (one per test)
  try {
    reserve_step_memory(65 * mib);
    ADD_FAILURE() << "65 MiB of 64 reserved";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("reserve_step_memory: 68157440 bytes is more than the 67108864 bytes"),
              std::string::npos)
        << e.what();
  }
  ::unsetenv("DGTEX_MEMORY_LIMIT_MB");
}

TEST(StepMemory, ALargerReservationTopsTheHeapUpToAllOfIt) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "ASan's allocator takes no malloc settings";
#elif !defined(__linux__) || !defined(__GLIBC__)
  GTEST_SKIP() << "the heap's part of the reservation is glibc's";
#else
  reserve_step_memory(48 * mib);   // 32 MiB of heap
  reserve_step_memory(144 * mib);  // 96 MiB of heap: the first 32 again, and 64 more
  const long before = minor_faults();
  std::vector<char*> pieces;
  for (int k = 0; k < 20; ++k) {  // 80 MiB in pieces below glibc's mmap threshold
    char* piece = static_cast<char*>(std::malloc(4 * mib));
    ASSERT_NE(piece, nullptr);
    volatile char* bytes = piece;  // freed unread below: plain stores could be dropped
    for (std::int64_t b = 0; b < 4 * mib; b += 4096) bytes[b] = 1;
    pieces.push_back(piece);
  }
  const long faults = minor_faults() - before;
  for (char* piece : pieces) std::free(piece);
  EXPECT_LT(faults, 200) << "80 MiB written in the reserved heap (20k pages)";
#endif
}

TEST(StepMemory, ChadsFirstStepsFaultInAlmostNoPageWithTheReservation) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "ASan's allocator takes no malloc settings and keeps its own shadow pages";
#elif !defined(__linux__) || !defined(__GLIBC__)
  GTEST_SKIP() << "the heap's part of the reservation is glibc's";
#else
  EXPECT_LT(faults_in_first_steps("chad.json", 4), 1000) << "page faults in chad's first four steps";
#endif
}

TEST(StepMemory, ThreadsThatTracedCutsBeforeTheReservationShareItsHeap) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "ASan's allocator takes no malloc settings and keeps its own shadow pages";
#elif !defined(__linux__) || !defined(__GLIBC__)
  GTEST_SKIP() << "the heap's part of the reservation is glibc's";
#else
  // The accordion's 18 cuts are traced on every OpenMP thread before its set-up knows how
  // much to reserve. A thread whose first allocation came before glibc's arenas were limited
  // to one keeps a heap of its own, which the reservation does not reach: the accordion's
  // first step then faulted in 2.9k pages (its worker thread's rest sums), 10 with the
  // settings made first (SceneRun calls prepare_step_memory before anything else).
  const test::ThreadCountGuard set_threads(2);  // a worker thread, also on a machine of one core
  EXPECT_LT(faults_in_first_steps("accordion.json", 2), 500) << "page faults in the accordion's first two steps";
#endif
}

}  // namespace
