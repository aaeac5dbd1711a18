#include "cholmod_lock.h"

#include <cholmod.h>
#include <omp.h>

#include <cstdint>
#include <stdexcept>
#include <string>

#include "address_space.h"

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

void reserve_blas_workspace(const CholmodLock&) {
  static bool reserved = false;  // guarded by the lock the caller holds
  if (reserved) return;
  const std::int64_t left = address_space_left();
  if (left >= 0 && left < kBlasWorkspaceAddressSpace) {
    const long long mib = 1 << 20, missing = (kBlasWorkspaceAddressSpace - left + mib - 1) / mib;
    throw std::runtime_error("sparse Cholesky factorisation: OpenBLAS needs " +
                             std::to_string(kBlasWorkspaceAddressSpace / mib) +
                             " MiB of address space for its workspace, and " + std::to_string(left / mib) +
                             " MiB are left under the process's address-space limit (ulimit -v): raise the limit by " +
                             std::to_string(missing) + " MiB or more");
  }
  cholmod_common common;
  cholmod_start(&common);
  common.supernodal = CHOLMOD_SUPERNODAL;
  common.print = 0;
  common.error_handler = nullptr;
  cholmod_sparse* one = cholmod_speye(1, 1, CHOLMOD_REAL, &common);
  if (one) {
    one->stype = -1;
    if (cholmod_factor* factor = cholmod_analyze(one, &common)) {
      cholmod_factorize(one, factor, &common);  // dpotrf on one supernode: OpenBLAS's workspace
      cholmod_free_factor(&factor, &common);
    }
    cholmod_free_sparse(&one, &common);
  }
  cholmod_finish(&common);
  reserved = true;
}

}  // namespace dgtex::detail
