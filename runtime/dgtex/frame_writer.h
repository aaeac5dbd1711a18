#pragma once
// The images of `dgtex run`: turns a scene's render block (RenderOptions, dgtex/scene.h)
// into renderer settings, keeps one EGL context and renderer for the whole run and writes
// DIR/frame_NNNNN.png, NNNNN the step number (static runs: 00000).
//
// The camera is fixed once, on the first frame, so an animation does not jump: a missing
// camera position or target is filled in by framing that first state's bounding box
// (see resolve_scene_camera).
// FrameWriter owns its renderer (and shares the EGL context by std::shared_ptr); not
// thread-safe, use it from one thread. Scene positions in m, image sizes in pixels.
#include <memory>
#include <string>

#include "dgtex/egl_context.h"
#include "dgtex/scene.h"
#include "dgtex/shell_renderer.h"
#include "dgtex/shell_state.h"
#include "dgtex/stage_timer.h"

namespace dgtex {

// View direction (from the target towards the camera) used when the render block gives
// neither camera.position nor camera.target: from -y, above (+z) and a little from +x.
constexpr double kDefaultViewDirection[3] = {0.5, -1.0, 0.8};

// Settings for the scene's size, fov, up, shading and background; geometry_shader cut
// method; camera from resolve_scene_camera(options, framing).
RenderSettings scene_render_settings(const RenderOptions& options, const ShellState& framing);

// Fills settings.camera_position/target from options:
//  - both given: used as they are;
//  - only position: target = centre of framing's deformed bounding box;
//  - only target: the camera looks at it from kDefaultViewDirection, far enough back that
//    the bounding box fits the field of view;
//  - neither: as above, looking at the box centre.
void resolve_scene_camera(const RenderOptions& options, const ShellState& framing, RenderSettings& settings);

// "frame_00042.png".
std::string png_frame_name(int index);

class FrameWriter {
 public:
  // Opens the EGL context now, so a run without one can fail before it writes anything
  // (throws EglUnavailableError with the one-line message of EglContext). Writes nothing;
  // `frames_dir` is created by write() if missing.
  FrameWriter(const RenderOptions& options, std::string frames_dir, std::shared_ptr<EglContext> context = nullptr);
  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // Renders `state` and writes frames_dir/png_frame_name(index); returns the file's path.
  // The first call fixes the camera. Errors: std::invalid_argument (bad state, a negative
  // index), std::runtime_error (OpenGL or file failure).
  std::string write(const ShellState& state, int index);

  // Stage "render": one call per frame (render + PNG); "render.draw" (GPU draw and
  // read-back), "render.png" (encoding and writing the file).
  const StageTimings& timings() const { return timings_; }
  int frames_written() const { return frames_written_; }
  const RenderSettings& settings() const { return settings_; }  // camera resolved after the first write
  const EglContext& context() const { return renderer_->context(); }

 private:
  RenderOptions options_;
  std::string frames_dir_;
  std::unique_ptr<ShellRenderer> renderer_;
  RenderSettings settings_;
  bool camera_fixed_ = false;
  int frames_written_ = 0;
  StageTimings timings_;
};

}  // namespace dgtex
