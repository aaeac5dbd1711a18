#pragma once
// Internal (ShellModel's assembly workspace): an array of doubles whose entries are
// unspecified until written, for kernel outputs of which the kernels write every entry that
// is read later.
// Why: the local blocks are rewritten by every assembly, so zero-filling them at each new
// model (every basis change), as a std::vector does, is wasted work. It mattered most while
// the enriched edge blocks were padded to the widest basis of the model (until session 62;
// fracture: 39 MB, 23 % of it used, because one element of 205 has 20 basis functions and
// most have 7-12): its first assembly, after the accordion and the slinky in one process,
// 70 -> 42-48 ms (2-core machine, session 34, three alternations). The edge blocks are
// compact now (kernels/enriched_edge_kernel.h); the enriched element blocks are still
// padded, their padding written as 0 by the kernels.
#include <cstddef>
#include <cstdlib>
#include <memory>

namespace dgtex::detail {

class ScratchArray {
 public:
  // Makes the array `count` doubles long and returns it (nullptr for 0). Its entries are
  // unspecified, also when the size stays: the caller writes each one before reading it.
  // Under the poisoning test hook (detail::set_poison_unzeroed_blocks, runtime/
  // multigrid_buffer.h) a new array is all NaN, so that a read before a write shows up.
  double* resize(std::size_t count);
  void clear() noexcept { block_.reset(), size_ = 0; }

  double* data() const noexcept { return block_.get(); }
  std::size_t size() const noexcept { return size_; }

 private:
  struct Free {
    void operator()(double* block) const noexcept { std::free(block); }
  };
  std::unique_ptr<double, Free> block_;
  std::size_t size_ = 0;
};

}  // namespace dgtex::detail
