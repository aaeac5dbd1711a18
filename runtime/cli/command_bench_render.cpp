// dgtex bench render: cut-boundary error (texels) against triangles drawn for per-texel
// tessellation, triangle removal, pixel killing and the geometry-shader method
// (dgtex/render_benchmark.h), with frame times; table, JSON and a gnuplot chart.
// Exit codes: 0 success; 2 bad arguments; 1 no OpenGL context or another failure.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "count_option.h"
#include "gnuplot_chart.h"
#include "dgtex/benchmark_machine.h"
#include "dgtex/render_benchmark.h"
#include "dgtex/version.h"
#include "option_errors.h"
#include "output_paths.h"

namespace dgtex::cli {
namespace {

constexpr double kErrorFloor = 0.05;  // texels; zero errors are drawn here on the log axis

// Error (texels) against triangles drawn, one line per method, the 1-texel target and
// 1/16 of the per-texel triangles as guides. PNG if the path ends in .png, else SVG.
std::string write_chart(const std::string& path, const RenderBenchResult& r) {
  const std::vector<std::string> series = {"per-texel", "geometry-shader", "drop-triangles", "kill-pixels"};
  double per_texel_triangles = 0;
  std::ostringstream data;
  for (const std::string& name : series) {
    data << "# " << name << "\n";
    for (const RenderBenchCase& c : r.cases)
      if (c.method == name) {
        data << c.triangles_drawn << " " << std::max(c.error_texels, kErrorFloor) << " " << c.tessellation << "\n";
        if (name == "per-texel") per_texel_triangles = static_cast<double>(c.triangles_drawn);
      }
    data << "\n\n";
  }
  char texel[32];
  std::snprintf(texel, sizeof texel, "%.2f", r.texel_pixels);
  return draw_gnuplot_chart(path, 1000, 650, data.str(), [&](const std::string& data_file) {
    std::ostringstream script;
    script << "set title 'cut-boundary error against triangles drawn (T = " << r.resolution << ", " << r.width << "x"
           << r.height << ", texel = " << texel << " px" << (r.partial_cut ? "" : ", complete cut only") << ")'\n"
           << "set logscale xy\nset xlabel 'triangles drawn'\nset ylabel 'max boundary error (texels)'\n"
           << "set key outside right\nset grid\n"
           << "set arrow from graph 0, first 1 to graph 1, first 1 nohead dashtype 2 lc rgb 'gray40'\n";
    if (per_texel_triangles > 0)
      script << "set arrow from first " << per_texel_triangles / 16 << ", graph 0 to first "
             << per_texel_triangles / 16 << ", graph 1 nohead dashtype 3 lc rgb 'gray40'\n"
             << "set label '1/16 of per-texel' at first " << per_texel_triangles / 16 << ", graph 0.95 offset 0.5,0\n";
    script << "plot '" << data_file << "' index 0 with points pt 7 ps 2 title 'per-texel tessellation', '" << data_file
           << "' index 1 using 1:2 with linespoints pt 5 title 'geometry shader', '' index 1 using 1:2:(sprintf('%d', $3))"
              " with labels offset 0,1 notitle, '"
           << data_file << "' index 2 with linespoints pt 9 title 'triangle removal', '" << data_file
           << "' index 3 with linespoints pt 13 title 'pixel killing'";
    return script.str();
  });
}

}  // namespace

int bench_render_command(int argc, char** argv) {
  CLI::App app{"Cut-boundary error against triangles drawn for the cut-shell renderer's methods, with frame times",
               "dgtex bench render"};
  RenderBenchOptions options;
  std::string json_path, chart_path;
  app.add_option("--resolution", options.resolution, "texels per element side T (per-texel = tessellation T)")
      ->capture_default_str()->check(whole_number(8, 256));
  app.add_option("--tessellations", options.tessellations, "tessellation levels of the three methods")
      ->delimiter(',')->check(whole_number(1, 256));
  app.add_option("--width", options.width, "image width")->capture_default_str()->check(whole_number(16, 8192));
  app.add_option("--height", options.height, "image height")->capture_default_str()->check(whole_number(16, 8192));
  app.add_option("--repeat", options.repeat, "timed renders per case (medians)")->capture_default_str()
      ->check(whole_number(1, 1000));
  bool complete_only = false;
  app.add_flag("--complete-cut-only", complete_only, "leave out the partial cut (and its tip)");
  app.add_option("--json", json_path, "write the results as JSON")->check(writable_file());
  app.add_option("--chart", chart_path, "write error against triangles (PNG if FILE ends in .png, else SVG)")
      ->check(writable_file());
  try {
    app.parse(argc, argv);
    check_list_items(app, argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_on_option_error(app, e);
  }
  if (!outputs_are_distinct(app, {{"--json", &json_path}, {"--chart", &chart_path}})) return 2;
  options.partial_cut = !complete_only;
  try {
    const std::string machine = describe_machine_and_probe();
    std::printf("machine: %s\n", machine.c_str());
    ShellRenderer renderer;
    const RenderBenchResult r = run_render_benchmark(options, renderer);
    std::printf("dgtex bench render: %d quad8 elements, %s, %d enrichments, T = %d, %d x %d, texel = %.2f px; %s\n",
                r.elements, r.partial_cut ? "complete and partial cut" : "complete cut only", r.enrichments, r.resolution, r.width, r.height, r.texel_pixels, r.device.c_str());
    std::printf("errors in texels: max and mean over mismatched pixels, away from the partial cut's tip (%.0f texels);"
                " max including the tip\n", kRenderBenchTipRadius);
    std::printf("%-16s %5s %10s %10s %8s %8s %9s %10s %9s %9s\n", "method", "tess", "submitted", "drawn", "error",
                "mean", "with tip", "mismatch", "draw ms", "frame ms");
    nlohmann::json cases = nlohmann::json::array();
    for (const RenderBenchCase& c : r.cases) {
      std::printf("%-16s %5d %10lld %10lld %8.2f %8.2f %9.2f %10ld %9.2f %9.2f\n", c.method.c_str(), c.tessellation,
                  c.triangles_submitted, c.triangles_drawn, c.error_texels, c.mean_error_texels,
                  c.error_with_tip_texels, c.mismatched_pixels, c.draw_ms, c.frame_ms);
      cases.push_back({{"method", c.method}, {"tessellation", c.tessellation},
                       {"triangles_submitted", c.triangles_submitted}, {"triangles_drawn", c.triangles_drawn},
                       {"error_texels", c.error_texels}, {"mean_error_texels", c.mean_error_texels},
                       {"mismatched_pixels", c.mismatched_pixels},
                       {"error_with_tip_texels", c.error_with_tip_texels}, {"upload_ms", c.upload_ms},
                       {"draw_ms", c.draw_ms}, {"frame_ms", c.frame_ms}});
    }
    // The target: error <= 1 texel with <= 1/16 of the per-texel triangles.
    const RenderBenchCase& reference = r.cases.front();
    const RenderBenchCase* best = nullptr;
    for (const RenderBenchCase& c : r.cases)
      if (c.method == "geometry-shader" && c.error_texels <= 1.0 &&
          (!best || c.triangles_drawn < best->triangles_drawn))
        best = &c;
    nlohmann::json target = {{"max_error_texels", 1.0}, {"max_triangle_fraction", 1.0 / 16}};
    if (best) {
      const double fraction = double(best->triangles_drawn) / double(std::max(1LL, reference.triangles_drawn));
      std::printf("target (error <= 1 texel with <= 1/16 of per-texel triangles): geometry shader at tessellation %d, "
                  "error %.2f texels with %.4f (1/%.0f) of the triangles: %s\n",
                  best->tessellation, best->error_texels, fraction, 1.0 / fraction, fraction <= 1.0 / 16 ? "met" : "not met");
      target["tessellation"] = best->tessellation;
      target["triangle_fraction"] = fraction;
      target["met"] = fraction <= 1.0 / 16;
    } else {
      std::printf("target: no geometry-shader case reaches an error <= 1 texel: not met\n");
      target["met"] = false;
    }
    if (!json_path.empty()) {
      const nlohmann::json results{{"dgtex_version", version()},
                                   {"machine", machine},
                                   {"resolution", r.resolution},
                                   {"width", r.width},
                                   {"height", r.height},
                                   {"texel_pixels", r.texel_pixels},
                                   {"elements", r.elements},
                                   {"enrichments", r.enrichments},
                                   {"partial_cut", r.partial_cut},
                                   {"device", r.device},
                                   {"tip_radius_texels", kRenderBenchTipRadius},
                                   {"cases", cases},
                                   {"target", target}};
      write_output_file(json_path, results.dump(2) + "\n", "--json");
    }
    if (const std::string failure = chart_path.empty() ? "" : write_chart(chart_path, r); !failure.empty()) {
      std::fprintf(stderr, "dgtex bench render: no chart '%s': %s\n", chart_path.c_str(), failure.c_str());
      return 1;
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "dgtex bench render: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dgtex bench render: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace dgtex::cli
