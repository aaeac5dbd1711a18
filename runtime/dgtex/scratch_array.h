#pragma once
// Internal (ShellModel's assembly workspace): an array of doubles whose entries are
// unspecified until written, for kernel outputs of which the kernels write every entry that
// is read later.
// Why: the enriched local blocks are padded to the widest basis of the model, and the edge
// blocks' padding slots are neither written nor read (fracture: 39 MB of enriched edge
// blocks, 23 % of it used, because one element of 205 has 20 basis functions and most have
// 7-12; the element kernels write their padding as 0). As a std::vector every page was
// faulted in and zero-filled at each new model (every basis change); here the memory comes
// from malloc untouched, so pages that hold only edge-block padding are never faulted in.
// Fracture's first assembly, after the accordion and the slinky in one process: 70 -> 42-48
// ms (2-core machine, session 34, three alternations); huge-page blocks from the block
// cache, which zero whole 2 MiB pages, sat in between.
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
