#pragma once
// The instruction-set paths of kernels/vector_path.h that this machine runs, best first:
// the tests check each one against its kernel's reference.
#include <vector>

#include "dgtex/kernels/vector_path.h"

namespace dgtex::testing_support {

inline std::vector<kernels::VectorPath> supported_vector_paths() {
  std::vector<kernels::VectorPath> paths;
  for (kernels::VectorPath path :
       {kernels::VectorPath::best, kernels::VectorPath::avx512, kernels::VectorPath::avx2, kernels::VectorPath::baseline})
    if (kernels::vector_path_supported(path)) paths.push_back(path);
  return paths;
}

}  // namespace dgtex::testing_support
