// An exception thrown by a kernel body inside forall's OpenMP region ended the process
// (std::terminate: chad out of memory in its quadrature pass). It now leaves the loop as
// the serial loop would throw it, with its type and message, at every thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "dgtex/kernels/forall.h"
#include "thread_count_support.h"

namespace {

using dgtex::kernels::Execution;

// The message of the runtime_error a loop throws, or "" if it throws none.
template <class Loop>
std::string thrown_by(Loop&& loop) {
  try {
    loop();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(ForallExceptions, ABodysExceptionLeavesEveryLoopAtEveryThreadCount) {
  const auto body = [](std::int64_t i) {
    if (i == 37) throw std::runtime_error("index 37");
  };
  for (Execution execution : {Execution::serial, Execution::parallel})
    for (int threads : {1, 2, 3, 4}) {
      dgtex::test::with_threads(threads, [&] {
        EXPECT_EQ(thrown_by([&] { dgtex::kernels::forall(100, body, execution); }), "index 37") << threads;
        EXPECT_EQ(thrown_by([&] { dgtex::kernels::forall_dynamic(100, body, execution); }), "index 37") << threads;
        // In either of forall_then's two loops.
        const auto none = [](std::int64_t) {};
        EXPECT_EQ(thrown_by([&] { dgtex::kernels::forall_then(100, body, 10, none, execution); }), "index 37");
        EXPECT_EQ(thrown_by([&] { dgtex::kernels::forall_then(10, none, 100, body, execution); }), "index 37");
      });
    }
}

TEST(ForallExceptions, TheExceptionKeepsItsTypeAndTheLoopsRunOnAfterward) {
  const dgtex::test::ThreadCountGuard set_threads(3);
  EXPECT_THROW(dgtex::kernels::forall(64, [](std::int64_t i) {
                 if (i % 7 == 3) throw std::bad_alloc();
               }),
               std::bad_alloc);
  // The next loop runs every index: nothing of the failure is left behind.
  std::vector<int> ran(1000, 0);
  dgtex::kernels::forall(1000, [&](std::int64_t i) { ran[i] = 1; });
  EXPECT_EQ(std::count(ran.begin(), ran.end(), 1), 1000);
}

}  // namespace
