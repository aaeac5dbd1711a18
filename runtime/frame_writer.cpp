#include "dgtex/frame_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

#include "dgtex/deformed_shell.h"
#include "dgtex/png_io.h"

namespace dgtex {

namespace {

void box_of(const ShellState& state, double centre[3], double& radius) {
  if (state.mesh.num_nodes() == 0) {
    centre[0] = centre[1] = centre[2] = 0;
    radius = 1;
    return;
  }
  double lo[3], hi[3];
  DeformedShell(state).bounding_box(lo, hi);
  double squared = 0;
  for (int d = 0; d < 3; ++d) {
    centre[d] = 0.5 * (lo[d] + hi[d]);
    squared += 0.25 * (hi[d] - lo[d]) * (hi[d] - lo[d]);
  }
  radius = std::max(std::sqrt(squared), 1e-9);
}

}  // namespace

void resolve_scene_camera(const RenderOptions& options, const ShellState& framing, RenderSettings& s) {
  double centre[3], radius;
  box_of(framing, centre, radius);
  if (options.camera_position && options.camera_target) {
    for (int d = 0; d < 3; ++d) {
      s.camera_position[d] = (*options.camera_position)[d];
      s.camera_target[d] = (*options.camera_target)[d];
    }
    return;
  }
  if (options.camera_position) {
    for (int d = 0; d < 3; ++d) {
      s.camera_position[d] = (*options.camera_position)[d];
      s.camera_target[d] = centre[d];
    }
    // A camera placed at the box centre has no direction: step back along the default.
    if (s.camera_position[0] == centre[0] && s.camera_position[1] == centre[1] && s.camera_position[2] == centre[2])
      for (int d = 0; d < 3; ++d) s.camera_position[d] += radius * kDefaultViewDirection[d];
    return;
  }
  double target[3] = {centre[0], centre[1], centre[2]};
  if (options.camera_target)
    for (int d = 0; d < 3; ++d) target[d] = (*options.camera_target)[d];
  // The whole box fits when the camera is radius / sin(half the narrower field of view)
  // from its centre; a target off the centre moves the camera back by that offset.
  const double half_v = 0.5 * s.fov_deg * M_PI / 180.0;
  const double half_h = std::atan(std::tan(half_v) * double(s.width) / s.height);
  double offset = 0;
  for (int d = 0; d < 3; ++d) offset += (target[d] - centre[d]) * (target[d] - centre[d]);
  const double distance = 1.1 * radius / std::sin(std::min(half_v, half_h)) + std::sqrt(offset);
  const double length = std::sqrt(kDefaultViewDirection[0] * kDefaultViewDirection[0] +
                                  kDefaultViewDirection[1] * kDefaultViewDirection[1] +
                                  kDefaultViewDirection[2] * kDefaultViewDirection[2]);
  for (int d = 0; d < 3; ++d) {
    s.camera_target[d] = target[d];
    s.camera_position[d] = target[d] + distance * kDefaultViewDirection[d] / length;
  }
}

RenderSettings scene_render_settings(const RenderOptions& options, const ShellState& framing) {
  RenderSettings s;
  s.width = options.width;
  s.height = options.height;
  s.fov_deg = options.fov_deg;
  for (int d = 0; d < 3; ++d) {
    s.camera_up[d] = options.camera_up[d];
    s.background[d] = static_cast<float>(options.background[d]);
  }
  s.shading = options.shading == RenderOptions::Shading::smooth ? RenderSettings::Shading::smooth
                                                                : RenderSettings::Shading::flat;
  s.cut_method = RenderSettings::CutMethod::geometry_shader;
  s.auto_camera = false;
  resolve_scene_camera(options, framing, s);
  return s;
}

std::string png_frame_name(int index) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "frame_%05d.png", index);
  return buffer;
}

FrameWriter::FrameWriter(const RenderOptions& options, std::string frames_dir, std::shared_ptr<EglContext> context)
    : options_(options), frames_dir_(std::move(frames_dir)), renderer_(std::make_unique<ShellRenderer>(std::move(context))) {}

FrameWriter::~FrameWriter() = default;

std::string FrameWriter::write(const ShellState& state, int index) {
  // frame_-0001.png was written for -1.
  if (index < 0)
    throw std::invalid_argument("FrameWriter::write: frame index " + std::to_string(index) + " (expected >= 0)");
  ScopedStage whole(timings_, "render");
  if (!camera_fixed_) {
    settings_ = scene_render_settings(options_, state);
    camera_fixed_ = true;
  }
  Image image;
  {
    ScopedStage draw(timings_, "render.draw");
    image = renderer_->render(state, settings_);
  }
  const std::string path = (std::filesystem::path(frames_dir_) / png_frame_name(index)).string();
  {
    ScopedStage png(timings_, "render.png");
    std::filesystem::create_directories(frames_dir_);
    write_png(path, image);
  }
  ++frames_written_;
  return path;
}

}  // namespace dgtex
