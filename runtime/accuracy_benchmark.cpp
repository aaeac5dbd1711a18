// Reporting of the speed-against-accuracy sweeps: JSON and Markdown (the machine: benchmark_machine.h).
#include "dgtex/accuracy_benchmark.h"
#include "dgtex/stage_timer.h"
#include "dgtex/version.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

namespace dgtex {

double accuracy_clock_ms(AccuracyClock clock) {
  if (clock == AccuracyClock::wall)
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
  return process_cpu_ms();
}

std::string accuracy_clock_name(AccuracyClock clock) { return clock == AccuracyClock::cpu ? "CPU" : "wall"; }

std::vector<std::string> AccuracyChart::series() const {
  std::vector<std::string> out;
  for (const AccuracyPoint& p : points)
    if (std::find(out.begin(), out.end(), p.series) == out.end()) out.push_back(p.series);
  return out;
}

namespace {
// The `extra` keys that count things (sizes, iterations, points): written as integers.
bool is_count_key(const std::string& key) {
  static const char* const counts[] = {"n",        "T",      "free_dofs", "iterations",       "pcg_iterations",
                                       "clusters", "texels", "unknowns",  "quadrature_points", "factorizations"};
  return std::find(std::begin(counts), std::end(counts), key) != std::end(counts);
}
}  // namespace

std::string accuracy_charts_json(const std::vector<AccuracyChart>& charts, const std::string& machine,
                                 const std::string& command) {
  nlohmann::json list = nlohmann::json::array();
  for (const AccuracyChart& chart : charts) {
    nlohmann::json points = nlohmann::json::array();
    for (const AccuracyPoint& p : chart.points) {
      nlohmann::json point = {{"series", p.series}, {"label", p.label}, {"ms", p.ms}, {"error", p.error}};
      for (const auto& [key, value] : p.extra) {
        // Counts are whole numbers in the JSON ("n": 2, not 2.0), for typed readers.
        if (is_count_key(key))
          point[key] = static_cast<std::int64_t>(value);
        else
          point[key] = value;
      }
      points.push_back(point);
    }
    nlohmann::json entry = {{"name", chart.name},
                            {"title", chart.title},
                            {"time_label", chart.time_label},
                            {"error_label", chart.error_label},
                            {"points", points}};
    if (!chart.conclusion.empty()) entry["conclusion"] = chart.conclusion;
    list.push_back(entry);
  }
  return nlohmann::json{{"dgtex_version", version()}, {"machine", machine}, {"command", command}, {"charts", list}}.dump(2) + "\n";
}

std::string accuracy_charts_markdown(const std::vector<AccuracyChart>& charts, const std::string& machine,
                                     const std::string& command) {
  std::ostringstream out;
  out << "Machine: " << machine << "  \nCommand: `" << command << "`\n";
  char number[64];
  for (const AccuracyChart& chart : charts) {
    std::vector<std::string> extra_keys;
    for (const AccuracyPoint& p : chart.points)
      for (const auto& kv : p.extra)
        if (std::find(extra_keys.begin(), extra_keys.end(), kv.first) == extra_keys.end()) extra_keys.push_back(kv.first);
    out << "\n### " << chart.name << ": " << chart.title << "\n\ntime: " << chart.time_label
        << "; error: " << chart.error_label << "\n\n| series | case | ms | error |";
    for (const std::string& k : extra_keys) out << " " << k << " |";
    out << "\n|---|---|---|---|";
    for (std::size_t k = 0; k < extra_keys.size(); ++k) out << "---|";
    out << "\n";
    for (const AccuracyPoint& p : chart.points) {
      out << "| " << p.series << " | " << p.label << " | ";
      std::snprintf(number, sizeof number, "%.3g", p.ms);
      out << number << " | ";
      std::snprintf(number, sizeof number, "%.3g", p.error);
      out << (p.error == 0 ? std::string("0 (reference)") : std::string(number)) << " |";
      for (const std::string& key : extra_keys) {
        const auto it = std::find_if(p.extra.begin(), p.extra.end(), [&](const auto& kv) { return kv.first == key; });
        if (it == p.extra.end()) {
          out << " |";
          continue;
        }
        std::snprintf(number, sizeof number, "%.4g", it->second);
        out << " " << number << " |";
      }
      out << "\n";
    }
    if (!chart.conclusion.empty()) out << "\n" << chart.conclusion << "\n";
  }
  return out.str();
}

}  // namespace dgtex
