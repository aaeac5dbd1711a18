#include "cholmod_lock.h"

namespace dgtex::detail {

std::unique_lock<std::mutex> lock_cholmod() {
  static std::mutex mutex;
  return std::unique_lock<std::mutex>(mutex);
}

}  // namespace dgtex::detail
