// The lookup of an earlier basis's quadrature points by their coordinates
// (runtime/parametric_point_index.h, used by ShellModel::moments_of_fields): every point is
// found at its index, from the table or from a hint; a point that differs in any bit (the
// last mantissa bit, the sign of zero) is not; a repeated point is found at one of its
// indices; an empty index finds nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "parametric_point_index.h"

using dgtex::detail::ParametricPointIndex;

namespace {

// Points as the quadrature lays them out: (xi1, xi2, weight), here texel-aligned (-1 + k / 128,
// whose low mantissa bits are all zero), two thirds of them moved by a Gauss offset.
std::vector<double> quadrature_like_points(int count) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int> texel(0, 255);
  std::vector<double> points;
  for (int p = 0; p < count; ++p) {
    const double offset = (p % 3 == 0) ? 0.0 : (p % 3 == 1 ? 1.0 : -1.0) / (2 * std::sqrt(3.0) * 128);
    points.insert(points.end(), {-1 + texel(random) / 128.0 + offset, -1 + texel(random) / 128.0 - offset, 1.0});
  }
  return points;
}

}  // namespace

TEST(ParametricPointIndex, FindsEveryPointAndNothingElse) {
  const std::vector<double> points = quadrature_like_points(5000);
  const std::int64_t count = static_cast<std::int64_t>(points.size() / 3);
  const ParametricPointIndex index(points.data(), count);
  for (std::int64_t p = 0; p < count; ++p) {
    const std::int64_t found = index.find(points[3 * p], points[3 * p + 1]);
    ASSERT_GE(found, 0) << "point " << p;
    // Repeated coordinates (texel-aligned draws may repeat) give the first such point.
    EXPECT_EQ(points[3 * found], points[3 * p]);
    EXPECT_EQ(points[3 * found + 1], points[3 * p + 1]);
    EXPECT_LE(found, p);
  }
  for (std::int64_t p = 0; p < count; p += 7) {
    EXPECT_EQ(index.find(std::nextafter(points[3 * p], 2.0), points[3 * p + 1]), -1);
    EXPECT_EQ(index.find(points[3 * p], std::nextafter(points[3 * p + 1], -2.0)), -1);
  }
  EXPECT_EQ(index.find(3.0, 3.0), -1);
}

TEST(ParametricPointIndex, AHintIsTakenOnlyWhereItsPointMatches) {
  const std::vector<double> points = {0.0, 0.5, 1.0, 0.25, 0.5, 1.0, 0.25, 0.75, 1.0};
  const ParametricPointIndex index(points.data(), 3);
  EXPECT_EQ(index.find(0.25, 0.5, 1), 1);
  EXPECT_EQ(index.find(0.25, 0.75, 1), 2);  // a wrong hint: the table answers
  EXPECT_EQ(index.find(0.25, 0.75, 7), 2);  // a hint past the end
  EXPECT_EQ(index.find(-0.0, 0.5, 0), -1);  // -0 is not 0: no bitwise match
  EXPECT_EQ(index.find(0.0, 0.5, -1), 0);
}

TEST(ParametricPointIndex, AnEmptyIndexFindsNothing) {
  const ParametricPointIndex none;
  EXPECT_EQ(none.find(0.0, 0.0), -1);
  const ParametricPointIndex empty(nullptr, 0);
  EXPECT_EQ(empty.find(0.0, 0.0, 0), -1);
}
