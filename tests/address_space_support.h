#pragma once
// The process's address-space limit (RLIMIT_AS, `ulimit -v`) lowered to a little above its
// size for one test, and restored.
#include <sys/resource.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <string>

namespace dgtex::test {

// Sets the limit to the process's virtual size plus `room` (bytes) until restore() or
// destruction; why_not() says why it could not (ASan's terabytes of shadow reservations,
// no /proc/self/statm, a hard limit below that), and is "" once the limit is set.
class ScopedAddressSpaceLimit {
 public:
  explicit ScopedAddressSpaceLimit(std::int64_t room) {
#if defined(__SANITIZE_ADDRESS__)
    why_not_ = "ASan reserves terabytes of address space for its shadow memory";
    (void)room;
#else
    std::ifstream statm("/proc/self/statm");
    long long pages = 0;
    if (!(statm >> pages)) {
      why_not_ = "no /proc/self/statm";
      return;
    }
    const std::int64_t used = static_cast<std::int64_t>(pages) * sysconf(_SC_PAGESIZE);
    if (getrlimit(RLIMIT_AS, &original_) != 0) {
      why_not_ = "getrlimit(RLIMIT_AS) failed";
      return;
    }
    if (original_.rlim_max != RLIM_INFINITY && static_cast<std::int64_t>(original_.rlim_max) < used + room) {
      why_not_ = "the hard address-space limit leaves less than the room asked for";
      return;
    }
    rlimit limited = original_;
    limited.rlim_cur = static_cast<rlim_t>(used + room);
    if (setrlimit(RLIMIT_AS, &limited) != 0) {
      why_not_ = "setrlimit(RLIMIT_AS) failed";
      return;
    }
    set_ = true;
#endif
  }
  ~ScopedAddressSpaceLimit() { restore(); }
  ScopedAddressSpaceLimit(const ScopedAddressSpaceLimit&) = delete;
  ScopedAddressSpaceLimit& operator=(const ScopedAddressSpaceLimit&) = delete;

  const std::string& why_not() const { return why_not_; }
  void restore() {
    if (set_) setrlimit(RLIMIT_AS, &original_);
    set_ = false;
  }

 private:
  rlimit original_{};
  bool set_ = false;
  std::string why_not_;
};

}  // namespace dgtex::test
