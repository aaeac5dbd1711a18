#include "cholmod_lock.h"

#include <omp.h>

namespace dgtex::detail {

namespace {
std::mutex& cholmod_mutex() {
  static std::mutex mutex;
  return mutex;
}
}  // namespace

CholmodLock::CholmodLock() : lock_(cholmod_mutex()), max_active_levels_(omp_get_max_active_levels()) {
  omp_set_max_active_levels(0);
}

CholmodLock::~CholmodLock() { omp_set_max_active_levels(max_active_levels_); }

}  // namespace dgtex::detail
