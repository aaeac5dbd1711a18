#pragma once
// Headless rendering of a (cut) shell state through OpenGL (thesis §5.4.3, Figs. 5.8-5.11).
//
// Every element is drawn with one static tessellation of its parameter domain shared by
// all elements (instanced). The vertex stage evaluates base and A_k of the deformed
// position (dgtex/deformed_shell.h) from the DOFs and the enrichment textures and passes
// on only base, the position with the vertex's own H_k and the signs of H_k; the
// geometry stage loops over the element's enrichment slots, finds those whose cut crosses
// the triangle (|H_i - H_j| > cut_threshold and a sign change of H) and duplicates the
// triangle once per combination of their sides, extrapolating the vertices across each
// cut with that side's value (of the nearest texel on that side, a function of the vertex
// alone, so neighbouring copies stay closed); the fragment stage discards the fragments
// of a copy whose texel lies on the other side. At most kMaxEnrichmentsPerElement
// enrichments per element; with the geometry-shader method a tessellation triangle
// crossed by more than kMaxCutsPerTriangle cuts is not drawn (a hole where that many
// cuts meet within one triangle; a finer tessellation separates them).
// ShellRenderer owns its OpenGL objects and shares the EglContext (std::shared_ptr). Its
// constructor, render() and destructor make that context current on the calling thread
// themselves; not thread-safe: one thread at a time per renderer, and renderers sharing a
// context must not render at the same time (EGL allows a context current on one thread
// only: eglMakeCurrent then fails, std::runtime_error). Positions in the mesh's length unit
// (SI: m); images in pixels.
#include <memory>
#include <string>

#include "dgtex/egl_context.h"
#include "dgtex/image.h"
#include "dgtex/shell_state.h"

namespace dgtex {

// Slot bit masks are 32-bit in the shaders; >= kernels::max_enrichments_per_element.
constexpr int kMaxEnrichmentsPerElement = 32;
// Cuts one tessellation triangle may cross (geometry-shader method): 2^k copies.
constexpr int kMaxCutsPerTriangle = 4;

struct RenderSettings {
  int width = 640, height = 480;
  double camera_position[3] = {0, -2, 2};
  double camera_target[3] = {0, 0, 0};
  double camera_up[3] = {0, 0, 1};
  double fov_deg = 40;  // vertical field of view
  // flat: one colour per element (hashed palette) lit by the face normal (Fig. 5.11 left);
  // smooth: one colour, normals averaged at nodes and interpolated (Fig. 5.11 right).
  enum class Shading { flat, smooth } shading = Shading::flat;
  bool wireframe = false;  // overlay the tessellation's triangles in red (Fig. 5.9)
  float background[3] = {1, 1, 1};
  // Fig. 5.10: geometry_shader (duplicate cut triangles, right), drop_triangles (left),
  // kill_pixels (draw cut triangles stretched, discard fragments within
  // kill_radius_texels of a texel on the other side of the cut, middle).
  enum class CutMethod { geometry_shader, drop_triangles, kill_pixels } cut_method = CutMethod::geometry_shader;
  int tessellation = 8;  // subdivisions per element edge
  // Frame the deformed bounding box: keeps the view direction (position - target) and
  // up, moves the target to the box centre and the camera back until it fits.
  bool auto_camera = false;
  float cut_threshold = 0.5f;  // minimal |H_i - H_j| of a cut edge
  int kill_radius_texels = 1;  // kill_pixels only
};

const char* to_string(RenderSettings::Shading shading);
const char* to_string(RenderSettings::CutMethod method);
// Parse "flat"/"smooth", "geometry-shader"/"drop-triangles"/"kill-pixels" (underscores
// accepted); throw std::invalid_argument listing the valid names.
RenderSettings::Shading parse_shading(const std::string& name);
RenderSettings::CutMethod parse_cut_method(const std::string& name);

// The camera a render uses (after auto_camera): column-major 4x4 view-projection matrix
// (OpenGL clip space) and where a world point lands in the image in pixels (x right, y
// down, pixel centres at +0.5). Tests use it to locate geometry.
struct Camera {
  double view_projection[16];
  int width, height;
  void project(const double point[3], double& pixel_x, double& pixel_y) const;
};
Camera make_camera(const ShellState& state, const RenderSettings& settings);

class ShellRenderer {
 public:
  // Creates its own EGL context (throws EglUnavailableError) unless one is given.
  explicit ShellRenderer(std::shared_ptr<EglContext> context = nullptr);
  ~ShellRenderer();
  ShellRenderer(const ShellRenderer&) = delete;
  ShellRenderer& operator=(const ShellRenderer&) = delete;

  // Renders one image. Throws std::invalid_argument for a bad state or settings (e.g.
  // more than kMaxEnrichmentsPerElement enrichments on an element), std::runtime_error
  // for an OpenGL failure.
  Image render(const ShellState& state, const RenderSettings& settings);

  // Wall time of the last render in milliseconds: upload (state validation, buffers,
  // textures), setup (compiling the program and building the tessellation, cached after
  // the first use of a combination of options) and draw (including the read-back, which
  // waits for the GPU).
  double last_upload_ms() const { return last_upload_ms_; }
  double last_setup_ms() const { return last_setup_ms_; }
  double last_draw_ms() const { return last_draw_ms_; }
  // Triangles of the last render: submitted (tessellation triangles x elements) and drawn
  // (what the geometry stage emitted to the rasteriser, GL_PRIMITIVES_GENERATED: cut
  // triangles count once per copy, dropped ones not at all).
  long long last_triangles_submitted() const { return last_triangles_submitted_; }
  long long last_triangles_drawn() const { return last_triangles_drawn_; }

  const EglContext& context() const { return *context_; }

 private:
  struct GlObjects;
  std::shared_ptr<EglContext> context_;
  std::unique_ptr<GlObjects> gl_;
  double last_upload_ms_ = 0, last_setup_ms_ = 0, last_draw_ms_ = 0;
  long long last_triangles_submitted_ = 0, last_triangles_drawn_ = 0;
};

}  // namespace dgtex
