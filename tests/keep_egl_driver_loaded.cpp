// Linked into the rendering tests (tests/CMakeLists.txt): one EGL context that lives until
// the process exits, so that Mesa's driver stays loaded. Each time the last context's
// eglTerminate unloads llvmpipe's driver, the driver leaves a 128-byte block it allocated
// behind, which LeakSanitizer reports from an unloaded module ("<unknown module>"), so no
// suppression can name it. Kept loaded, the driver's globals still hold the block at exit,
// and the sanitizer build checks the rendering tests for leaks like the others. (It also
// spares each later context the driver's reload: ~8 ms, against ~1.3 ms beside a live one.)
#include <gtest/gtest.h>

#include "dgtex/egl_context.h"

namespace {

// A global, not a member: gtest deletes its environments at exit, and a context reachable
// from nothing would be a leak of its own.
const dgtex::EglContext* context_kept_until_exit = nullptr;

class KeepEglDriverLoaded : public testing::Environment {
 public:
  // In SetUp, not at static initialisation: listing the tests (gtest_discover_tests) opens
  // no context.
  void SetUp() override {
    if (!context_kept_until_exit) context_kept_until_exit = new dgtex::EglContext;
  }
};

[[maybe_unused]] testing::Environment* const registered = testing::AddGlobalTestEnvironment(new KeepEglDriverLoaded);

}  // namespace
