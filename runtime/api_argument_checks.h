#pragma once
// Argument checks of the public runtime classes: a wrong size or index from a program
// linking dgtex throws std::invalid_argument naming the function, the argument, its value
// and what is valid, instead of reading or writing out of bounds. O(1); not for kernels.
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/shape_functions.h"

namespace dgtex::detail {

// The smallest relative tolerance the solvers are asked for (the CLI's --tolerance options,
// bench accuracy's sweeps): below it round-off stalls a double-precision solve (the
// multigrid's residual near 1e-14), and 1e-300 failed only after the work began.
inline constexpr double kMinRelativeTolerance = 1e-12;

// A value in a message, "%g" ("-0.005", "nan", "inf").
inline std::string short_number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

// A point in a message, "[1, 0.5, -0.005]".
inline std::string short_point(const double x[3]) {
  return "[" + short_number(x[0]) + ", " + short_number(x[1]) + ", " + short_number(x[2]) + "]";
}

// "ShellModel::interpolate: u has 3 entries; expected num_dofs() = 84"
inline void check_size(const char* function, const char* argument, std::size_t size, const char* expected_name,
                       std::size_t expected) {
  if (size == expected) return;
  throw std::invalid_argument(std::string(function) + ": " + argument + " has " + std::to_string(size) +
                              " entries; expected " + expected_name + " = " + std::to_string(expected));
}

// "ShellModel::interpolate: element 99 is out of range; expected 0..15 (num_elements() = 16)"
inline void check_index(const char* function, const char* argument, long long index, const char* count_name,
                        long long count) {
  if (index >= 0 && index < count) return;
  throw std::invalid_argument(std::string(function) + ": " + argument + " " + std::to_string(index) +
                              " is out of range; expected 0.." + std::to_string(count - 1) + " (" + count_name +
                              " = " + std::to_string(count) + ")");
}

// "ShellModel::interpolate: xi (1.5, 0) is outside the reference element; quad8 needs ..."
// (extrapolated through the shape functions; NaN reached a cast to int in the texel lookup)
inline void check_parametric_point(const char* function, kernels::ElementType type, const double xi[2]) {
  if (kernels::inside_reference_element(type, xi[0], xi[1])) return;
  throw std::invalid_argument(std::string(function) + ": xi (" + short_number(xi[0]) + ", " + short_number(xi[1]) +
                              ") is outside the reference element; " + kernels::reference_element_rule(type));
}

// "ShellSimulation: external_force[17] is nan; expected a finite number"
inline void check_finite(const char* function, const char* argument, const double* values, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i]))
      throw std::invalid_argument(std::string(function) + ": " + argument + "[" + std::to_string(i) + "] is " +
                                  short_number(values[i]) + "; expected a finite number");
}

}  // namespace dgtex::detail
