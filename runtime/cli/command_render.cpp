// dgtex render STATE --out DIR|FILE.png: renders a saved shell state (dgtex/shell_state.h)
// to DIR/frame.png, or to FILE.png, through a headless EGL context.
// Exit codes: 0 success; 2 bad arguments or an unreadable/invalid state file; 1 no
// OpenGL context (one line on stderr: "dgtex render: no OpenGL 3.3+ core context through
// EGL (tried: ...)") or another rendering failure.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "api_argument_checks.h"
#include "commands.h"
#include "count_option.h"
#include "dgtex/kernels/vec3.h"
#include "dgtex/png_io.h"
#include "dgtex/shell_renderer.h"
#include "dgtex/shell_state.h"
#include "option_errors.h"
#include "output_paths.h"

namespace dgtex::cli {

namespace {

// --out names a folder (the image is its frame.png) or, ending in .png and not an existing
// folder, the image itself: `--out spiral.png` writes spiral.png, not spiral.png/frame.png.
std::filesystem::path image_path(const std::string& out) {
  const std::filesystem::path path(out);
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  std::error_code error;
  if (extension == ".png" && !std::filesystem::is_directory(path, error)) return path;
  return path / "frame.png";
}

// The image's folder must exist or be creatable, and an existing image be writable.
CLI::Validator writable_image() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        if (value.empty()) return "an empty path; give a folder or a .png file";
        const std::filesystem::path image = image_path(value);
        std::string file = image.string();
        std::error_code error;
        // A new image: its path as the folders to create (the nearest existing one writable,
        // every name within the file systems' limit).
        return std::filesystem::exists(image, error) ? writable_file()(file) : creatable_folder()(file);
      },
      "DIR|FILE.png");
}

}  // namespace

int render_command(int argc, char** argv) {
  CLI::App app{"Render a saved shell state to OUT/frame.png, or to OUT when it ends in .png (headless, EGL)",
               "dgtex render"};
  std::string state_path, out_dir, shading = "flat", cut_method = "geometry-shader";
  RenderSettings settings;
  std::vector<double> position, target, up, background;
  app.add_option("STATE", state_path,
                 "state file written by dgtex run --save-state (DIR/final.state) or save_state() (dgtex/shell_state.h)")
      ->required();
  app.add_option("--out", out_dir, "output folder (created if missing) for frame.png, or the image's own name, FILE.png")
      ->required()
      ->check(writable_image());
  app.add_option("--width", settings.width, "image width in pixels")->capture_default_str()->check(whole_number(1, 16384));
  app.add_option("--height", settings.height, "image height in pixels")->capture_default_str()->check(whole_number(1, 16384));
  app.add_option("--shading", shading, "flat (one colour per element) or smooth (normals averaged at nodes)")
      ->capture_default_str();
  app.add_flag("--wireframe", settings.wireframe, "overlay the tessellation");
  app.add_option("--cut-method", cut_method, "geometry-shader, drop-triangles or kill-pixels")->capture_default_str();
  app.add_option("--tessellation", settings.tessellation, "subdivisions per element edge")
      ->capture_default_str()->check(whole_number(1, 256));
  app.add_option("--camera-position", position, "camera position x y z (default: frame the shell)")->expected(3);
  app.add_option("--camera-target", target, "point looked at x y z")->expected(3);
  app.add_option("--camera-up", up, "up direction x y z")->expected(3);
  app.add_option("--fov", settings.fov_deg, "vertical field of view in degrees")->capture_default_str();
  app.add_option("--background", background, "background colour r g b in [0, 1]")->expected(3)->check(colour_component());
  try {
    app.parse(argc, argv);
    check_list_items(app, argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::printf("%s", app.help().c_str());
    return 0;
  } catch (const CLI::ParseError& e) {
    return exit_on_option_error(app, e);
  }

  // Refused by option name before the state is read: the library's own checks name its
  // settings' fields (fov_deg, auto_camera), and a NaN colour or a zero up passed them.
  auto refuse = [](const std::string& why) {
    std::fprintf(stderr, "dgtex render: %s (see dgtex render --help)\n", why.c_str());
    return 2;
  };
  auto text = [](const std::vector<double>& v) {
    std::string t;
    for (double x : v) t += (t.empty() ? "" : " ") + detail::short_number(x);
    return t;
  };
  auto norm3 = [](const std::vector<double>& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); };
  try {
    settings.shading = parse_shading(shading);
  } catch (const std::invalid_argument& e) {
    return refuse(std::string("--shading: ") + e.what());
  }
  try {
    settings.cut_method = parse_cut_method(cut_method);
  } catch (const std::invalid_argument& e) {
    return refuse(std::string("--cut-method: ") + e.what());
  }
  if (!(settings.fov_deg > 0 && settings.fov_deg < 180))
    return refuse("--fov: " + detail::short_number(settings.fov_deg) + ": expected more than 0 and less than 180 degrees");
  for (double c : background)
    if (!(c >= 0 && c <= 1)) return refuse("--background: " + text(background) + ": expected three numbers in [0, 1]");
  // Each component, and their lengths at most 1e30: 1e200 passed std::isfinite but its norm
  // overflowed (and the message called it not finite).
  for (const auto& [option, v] : {std::pair{"--camera-position", &position}, {"--camera-target", &target}, {"--camera-up", &up}})
    for (double x : *v)
      if (!(std::abs(x) <= 1e30))
        return refuse(std::string(option) + ": " + text(*v) + ": expected finite numbers of magnitude up to 1e30");
  if (!up.empty() && !(norm3(up) > 0)) return refuse("--camera-up: " + text(up) + ": expected a non-zero direction");
  if (!position.empty()) {
    const double* look = target.empty() ? settings.camera_target : target.data();
    const std::vector<double> view = {look[0] - position[0], look[1] - position[1], look[2] - position[2]};
    if (!(norm3(view) > 0))
      return refuse("--camera-target: " + text({look[0], look[1], look[2]}) +
                    ": the camera's own position; expected a point away from it");
    // A given up along the view is refused; without one the renderer picks a perpendicular
    // (a camera straight above the shell, --camera-position 0 0 5).
    if (!up.empty() && kernels::parallel3(view.data(), up.data()))
      return refuse("--camera-up: " + text(up) + ": parallel to the viewing direction; expected another up");
  }
  if (const std::string image = image_path(out_dir).string();
      !outputs_are_distinct(app, {{"--out", &image}}, {{"the state file", state_path}}))
    return 2;

  ShellState state;
  try {
    // Without an explicit camera, look from the default direction and frame the shell.
    settings.auto_camera = position.empty();
    for (int d = 0; d < 3; ++d) {
      if (!position.empty()) settings.camera_position[d] = position[d];
      if (!target.empty()) settings.camera_target[d] = target[d];
      if (!up.empty()) settings.camera_up[d] = up[d];
      if (!background.empty()) settings.background[d] = static_cast<float>(background[d]);
    }
    state = load_state(state_path);
    // The library draws an empty state as the background alone; from a file that is a
    // damaged count, not an image to write with success.
    if (state.mesh.num_elements() == 0)
      throw std::invalid_argument("state file '" + state_path + "': no elements to draw (dgtex run never writes such a file)");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dgtex render: %s\n", e.what());
    return 2;
  }

  try {
    ShellRenderer renderer;
    const std::filesystem::path frame_path = image_path(out_dir);
    if (frame_path.has_parent_path()) create_output_folder(frame_path.parent_path().string(), "--out");
    const Image image = renderer.render(state, settings);
    const std::string frame = frame_path.string();
    write_png(frame, image);
    std::printf("dgtex render: wrote %s (%d x %d; upload %.1f ms, shader setup %.1f ms, draw %.1f ms; %s)\n",
                frame.c_str(), image.width, image.height, renderer.last_upload_ms(), renderer.last_setup_ms(),
                renderer.last_draw_ms(), renderer.context().description().c_str());
  } catch (const std::invalid_argument& e) {  // the settings are checked above: the state's contents
    std::fprintf(stderr, "dgtex render: state file '%s': %s\n", state_path.c_str(), e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dgtex render: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace dgtex::cli
