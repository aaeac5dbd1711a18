#include "dgtex/kernels/vector_path.h"

namespace dgtex::kernels {

bool vector_path_supported(VectorPath path) {
  __builtin_cpu_init();
  switch (path) {
    case VectorPath::avx512: return __builtin_cpu_supports("avx512f");
    // The AVX2 path of the Gram sums fuses multiply-adds (every AVX2 CPU but a few has FMA).
    case VectorPath::avx2: return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    default: return true;
  }
}

VectorPath widest(VectorPath path) {
  if (path != VectorPath::best) return path;
  // Asked once (thread-safe): kernels pick their path on every call.
  static const VectorPath machine = vector_path_supported(VectorPath::avx512) ? VectorPath::avx512
                                    : vector_path_supported(VectorPath::avx2) ? VectorPath::avx2
                                                                              : VectorPath::baseline;
  return machine;
}

}  // namespace dgtex::kernels
