#include "dgtex/scratch_array.h"

#include <algorithm>
#include <limits>
#include <new>

#include "multigrid_buffer.h"

namespace dgtex::detail {

double* ScratchArray::resize(std::size_t count) {
  if (count == size_) return data();
  clear();  // first, so that the heap can hand the memory out again
  if (count == 0) return nullptr;
  if (count > std::numeric_limits<std::size_t>::max() / sizeof(double)) throw std::bad_alloc();
  // malloc, not new double[count]() or a vector: no write to the memory.
  block_.reset(static_cast<double*>(std::malloc(count * sizeof(double))));
  if (!block_) throw std::bad_alloc();
  size_ = count;
  if (poison_unzeroed_blocks()) std::fill_n(block_.get(), count, std::numeric_limits<double>::quiet_NaN());
  return data();
}

}  // namespace dgtex::detail
