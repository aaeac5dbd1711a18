#pragma once
// Which instruction-set path a kernel with several runs: AVX-512, AVX2 (with FMA) or
// baseline x86-64, chosen at run time. Kernels with paths are compiled without FMA
// contraction and keep lanes apart, so every path rounds alike (bitwise the same results on
// any machine); where one fuses multiply-adds (the Gram sums), it fuses the same operations
// on every path and in its reference, explicitly.
// best: the widest the machine supports; the others are for tests and must be supported
// (vector_path_supported).
namespace dgtex::kernels {

enum class VectorPath { best, avx512, avx2, baseline };

bool vector_path_supported(VectorPath path);
// `path`, or for best the widest path the machine supports (found once per process).
VectorPath widest(VectorPath path);

// A kernel family's function for `path` (cheap: call it per kernel call).
template <class Kernel>
Kernel kernel_of(VectorPath path, Kernel avx512, Kernel avx2, Kernel baseline) {
  switch (widest(path)) {
    case VectorPath::avx512: return avx512;
    case VectorPath::avx2: return avx2;
    default: return baseline;
  }
}

}  // namespace dgtex::kernels
