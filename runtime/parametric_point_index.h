#pragma once
// Internal: finds a quadrature point of an earlier basis by its parametric coordinates.
// Why: between two bases of a progressive cut, 92-94 % of an enriched element's quadrature
// points are the same points (the cells away from the cut's new piece merge as before:
// chad, spiral1, spiral6 and the slinky over their runs), so the projection onto the new
// basis can read the old basis's values there instead of evaluating it again.
// Points match only when both coordinates are bitwise equal: a miss is always safe (the
// caller evaluates), a hit names a point where every evaluation gives the same bits.
#include <cstdint>
#include <cstring>
#include <vector>

namespace dgtex::detail {

class ParametricPointIndex {
 public:
  ParametricPointIndex() = default;
  // points: (xi1, xi2, weight) per point, `count` points; kept by pointer (must outlive this).
  ParametricPointIndex(const double* points, std::int64_t count) : points_(points), count_(count) {
    std::size_t size = 16;
    while (size < 2 * static_cast<std::size_t>(count)) size *= 2;
    slots_.assign(size, -1);
    mask_ = size - 1;
    for (std::int64_t p = 0; p < count; ++p) {
      std::size_t s = slot_of(points[3 * p], points[3 * p + 1]);
      while (slots_[s] >= 0 && !same(slots_[s], points[3 * p], points[3 * p + 1])) s = (s + 1) & mask_;
      if (slots_[s] < 0) slots_[s] = static_cast<std::int32_t>(p);  // a repeated point keeps its first index
    }
  }

  // Index of the point at (xi1, xi2), or -1. `hint`: the index to try first (both bases list
  // their points cell by cell in the same order, so a run of shared points is found by
  // comparing the point after the last one found, without touching the table).
  std::int64_t find(double xi1, double xi2, std::int64_t hint = -1) const {
    if (slots_.empty()) return -1;
    if (hint >= 0 && hint < count_ && same(hint, xi1, xi2)) return hint;
    for (std::size_t s = slot_of(xi1, xi2);; s = (s + 1) & mask_) {
      const std::int32_t p = slots_[s];
      if (p < 0 || same(p, xi1, xi2)) return p;
    }
  }

 private:
  static std::uint64_t bits(double x) {
    std::uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
  }
  // Parametric coordinates share most of their high bits (and texel-aligned ones their low
  // bits), so both are mixed through every bit (splitmix64's finaliser) before masking.
  static std::uint64_t mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::size_t slot_of(double xi1, double xi2) const {
    return static_cast<std::size_t>(mix(bits(xi1) ^ mix(bits(xi2)))) & mask_;
  }
  bool same(std::int64_t p, double xi1, double xi2) const {
    return bits(points_[3 * p]) == bits(xi1) &&
           bits(points_[3 * p + 1]) == bits(xi2);
  }

  const double* points_ = nullptr;
  std::int64_t count_ = 0;  // fewer than 2^31 (an element's quadrature points)
  std::vector<std::int32_t> slots_;
  std::size_t mask_ = 0;
};

}  // namespace dgtex::detail
