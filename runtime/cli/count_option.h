#pragma once
// Range checks for numeric options. CLI11's PositiveNumber reports a refused 0 as "not in
// range 0.000000 to 1797...(309 digits)"; these name the integers an option takes.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "api_argument_checks.h"
#include "dgtex/texel_memory_estimate.h"

namespace dgtex::cli {

// A whole number in [low, high] as written: decimal digits, an optional sign. CLI11's Range
// called "1e3" and "2.5" out of range (1000 is not) and CLI11 read "0x10" as 16, which a
// report then showed as a thread count nobody typed.
inline CLI::Validator whole_number(long long low, long long high) {
  const std::string range = std::to_string(low) + " to " + std::to_string(high);
  return CLI::Validator(
      [low, high, range](std::string& value) -> std::string {
        const std::size_t first = !value.empty() && (value[0] == '-' || value[0] == '+') ? 1 : 0;
        const bool digits = value.size() > first && std::all_of(value.begin() + static_cast<std::ptrdiff_t>(first),
                                                                value.end(), [](unsigned char c) { return std::isdigit(c); });
        if (!digits) return "Value " + value + " is not a whole number in decimal digits";
        errno = 0;
        const long long number = std::strtoll(value.c_str(), nullptr, 10);
        if (errno == ERANGE || number < low || number > high) return "Value " + value + " not in range " + range;
        return "";
      },
      "INT in [" + range + "]");
}

// Any int as written (digits, a sign), for options whose range the library checks with
// its own message (sizes, divisions, steps of bench accuracy and laplace).
inline CLI::Validator whole_int() {
  return whole_number(std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
}

// A count of one or more (runs, steps, repeats): "Value 0 not in range 1 to 2147483647".
inline CLI::Validator at_least_one() { return whole_number(1, std::numeric_limits<int>::max()); }

// A count that may be zero where zero means "the default" (bench scenes' --steps).
inline CLI::Validator zero_or_more() { return whole_number(0, std::numeric_limits<int>::max()); }

// OpenMP thread counts, as `dgtex run --threads` takes them.
inline CLI::Validator thread_count() { return whole_number(1, 1024); }

// Whether a --threads-list increases; if not, prints one line naming it (the speed-ups are
// over the first count: a list such as 2,1 gave "speed-up 2 -> 1 threads").
inline bool thread_counts_increase(const CLI::App& app, const std::vector<int>& threads) {
  if (std::adjacent_find(threads.begin(), threads.end(), std::greater_equal<int>()) == threads.end()) return true;
  std::string list;
  for (const int t : threads) list += (list.empty() ? "" : ",") + std::to_string(t);
  std::fprintf(stderr,
               "%s: --threads-list: %s; expected increasing thread counts (the first is the base of the speed-ups), "
               "e.g. 1,2,4\n",
               app.get_name().c_str(), list.c_str());
  return false;
}

// A relative tolerance a double-precision solve can reach: detail::kMinRelativeTolerance <=
// t < 1 (0, a negative or NaN could never be met; 1 is met by any guess).
inline CLI::Validator relative_tolerance() {
  const std::string valid = "[" + detail::short_number(detail::kMinRelativeTolerance) + ", 1)";
  return CLI::Validator(
      [valid](std::string& value) -> std::string {
        double t = 0;
        if (!CLI::detail::lexical_cast(value, t) || !(t >= detail::kMinRelativeTolerance && t < 1))
          return "Value " + value + " is not a relative tolerance a double-precision solve can reach; expected a " +
                 "number in " + valid + ", e.g. 1e-8";
        return "";
      },
      valid);
}

// A colour component in [0, 1] (NaN refused).
inline CLI::Range colour_component() { return CLI::Range(0.0, 1.0); }

// The memory a command's option checks compare sizes with (available_memory_bytes); a bad
// DGTEX_MEMORY_LIMIT_MB is that command's bad input: one line on stderr and nullopt (exit
// code 2), where the exception would have ended the process.
inline std::optional<std::int64_t> memory_for_options(const CLI::App& app) {
  try {
    return available_memory_bytes();
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "%s: %s\n", app.get_name().c_str(), e.what());
    return std::nullopt;
  }
}

// The most items of `bytes_each` bytes that fit `available` bytes (available_memory_bytes,
// texel_memory_estimate.h), or -1 when `count` of them fit or there is no figure (-1): a
// size a benchmark allocates ended the command with a bare "std::bad_alloc".
inline std::int64_t most_that_fit(std::int64_t count, std::int64_t bytes_each, std::int64_t available) {
  return available < 0 || count <= available / bytes_each ? -1 : available / bytes_each;
}

}  // namespace dgtex::cli
