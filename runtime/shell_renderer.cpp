#include "dgtex/shell_renderer.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "dgtex/deformed_shell.h"
#include "dgtex/kernels/enriched_basis.h"
#include "dgtex/kernels/vec3.h"
#include "api_argument_checks.h"
#include "dgtex_embedded_shaders.h"

namespace dgtex {

static_assert(kMaxEnrichmentsPerElement >= kernels::max_enrichments_per_element,
              "the renderer must draw every element the shell model allows");

const char* to_string(RenderSettings::Shading shading) {
  return shading == RenderSettings::Shading::flat ? "flat" : "smooth";
}

const char* to_string(RenderSettings::CutMethod method) {
  switch (method) {
    case RenderSettings::CutMethod::geometry_shader: return "geometry-shader";
    case RenderSettings::CutMethod::drop_triangles: return "drop-triangles";
    case RenderSettings::CutMethod::kill_pixels: return "kill-pixels";
  }
  return "?";
}

namespace {

std::string dashed(std::string s) {
  std::replace(s.begin(), s.end(), '_', '-');
  return s;
}

// ---- camera ----------------------------------------------------------------------

using Vec3 = std::array<double, 3>;
Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::hypot(a[0], a[1], a[2]); }  // no underflow of tiny vectors
Vec3 normalized(const Vec3& a) {
  const double n = norm(a);
  return {a[0] / n, a[1] / n, a[2] / n};
}

struct ResolvedCamera {
  Vec3 eye, target, up;
  double near_plane, far_plane;
};

// The shaders draw in 32-bit floats: a state whose coordinates pass their range (a damaged
// or hand-made state file with positions of 1e39) drew a blank image with success.
constexpr double kLargestDrawnCoordinate = 1e30;

ResolvedCamera resolve_camera(const DeformedShell& shell, const RenderSettings& s) {
  double lo[3], hi[3];
  shell.bounding_box(lo, hi);
  for (int d = 0; d < 3; ++d)
    for (double x : {lo[d], hi[d]})
      if (!(std::abs(x) <= kLargestDrawnCoordinate))
        throw std::invalid_argument("the deformed shell reaches coordinate " + detail::short_number(x) +
                                    ", beyond what the renderer's 32-bit floats draw (magnitudes up to 1e30)");
  const Vec3 center = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
  const double radius = std::max(0.5 * norm(sub(Vec3{hi[0], hi[1], hi[2]}, Vec3{lo[0], lo[1], lo[2]})), 1e-9);
  ResolvedCamera c;
  c.eye = {s.camera_position[0], s.camera_position[1], s.camera_position[2]};
  c.target = {s.camera_target[0], s.camera_target[1], s.camera_target[2]};
  c.up = normalized({s.camera_up[0], s.camera_up[1], s.camera_up[2]});  // a tiny up's cross products underflowed
  Vec3 direction = sub(c.eye, c.target);
  if (norm(direction) == 0) direction = {0, -1, 1};
  direction = normalized(direction);
  if (kernels::parallel3(direction.data(), c.up.data())) {
    // Up parallel to the view direction: pick any perpendicular axis.
    c.up = std::abs(direction[2]) < 0.9 ? Vec3{0, 0, 1} : Vec3{0, 1, 0};
  }
  if (s.auto_camera) {
    const double half_v = 0.5 * s.fov_deg * M_PI / 180.0;
    const double half_h = std::atan(std::tan(half_v) * double(s.width) / s.height);
    const double distance = 1.05 * radius / std::sin(std::min(half_v, half_h));
    c.target = center;
    c.eye = {center[0] + distance * direction[0], center[1] + distance * direction[1], center[2] + distance * direction[2]};
  }
  const double distance = norm(sub(c.eye, center));
  c.far_plane = 1.1 * (distance + radius);
  c.near_plane = std::max(0.9 * (distance - radius), 1e-3 * c.far_plane);
  return c;
}

// Column-major product of two column-major 4x4 matrices.
void multiply(const double a[16], const double b[16], double out[16]) {
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) {
      double sum = 0;
      for (int k = 0; k < 4; ++k) sum += a[k * 4 + row] * b[col * 4 + k];
      out[col * 4 + row] = sum;
    }
}

void validate_settings(const RenderSettings& s) {
  if (s.width < 1 || s.height < 1 || s.width > 16384 || s.height > 16384)
    throw std::invalid_argument("render size " + std::to_string(s.width) + " x " + std::to_string(s.height) +
                                " (valid: 1..16384 each)");
  if (!(s.fov_deg > 0 && s.fov_deg < 180))
    throw std::invalid_argument("fov_deg = " + std::to_string(s.fov_deg) + " (valid: between 0 and 180)");
  if (s.tessellation < 1 || s.tessellation > 256)
    throw std::invalid_argument("tessellation = " + std::to_string(s.tessellation) + " (valid: 1..256)");
  if (!(s.cut_threshold >= 0))
    throw std::invalid_argument("cut_threshold = " + std::to_string(s.cut_threshold) + " (valid: >= 0)");
  if (s.kill_radius_texels < 0 || s.kill_radius_texels > 16)
    throw std::invalid_argument("kill_radius_texels = " + std::to_string(s.kill_radius_texels) + " (valid: 0..16)");
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(s.camera_position[d]) || !std::isfinite(s.camera_target[d]) || !std::isfinite(s.camera_up[d]))
      throw std::invalid_argument("camera position, target and up must be finite");
  if (norm(Vec3{s.camera_up[0], s.camera_up[1], s.camera_up[2]}) == 0)
    throw std::invalid_argument("camera up is the zero vector (expected a direction)");
  for (int c = 0; c < 3; ++c)
    if (!(s.background[c] >= 0 && s.background[c] <= 1))
      throw std::invalid_argument("background[" + std::to_string(c) + "] = " + std::to_string(s.background[c]) +
                                  " (valid: 0..1)");
  if (s.shading != RenderSettings::Shading::flat && s.shading != RenderSettings::Shading::smooth)
    throw std::invalid_argument("shading " + std::to_string(static_cast<int>(s.shading)) + " (valid: flat, smooth)");
  using Cut = RenderSettings::CutMethod;
  if (s.cut_method != Cut::geometry_shader && s.cut_method != Cut::drop_triangles && s.cut_method != Cut::kill_pixels)
    throw std::invalid_argument("cut_method " + std::to_string(static_cast<int>(s.cut_method)) +
                                " (valid: geometry_shader, drop_triangles, kill_pixels)");
  if (!s.auto_camera && norm(sub(Vec3{s.camera_position[0], s.camera_position[1], s.camera_position[2]},
                                 Vec3{s.camera_target[0], s.camera_target[1], s.camera_target[2]})) == 0)
    throw std::invalid_argument("camera position equals camera target (or set auto_camera)");
}

Camera camera_for(const DeformedShell& shell, const RenderSettings& s, ResolvedCamera* resolved_out = nullptr) {
  validate_settings(s);
  const ResolvedCamera c = resolve_camera(shell, s);
  if (resolved_out) *resolved_out = c;
  const Vec3 f = normalized(sub(c.target, c.eye));
  const Vec3 r = normalized(cross(f, c.up));
  const Vec3 u = cross(r, f);
  const double view[16] = {r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0,
                           -dot(r, c.eye), -dot(u, c.eye), dot(f, c.eye), 1};
  const double t = 1.0 / std::tan(0.5 * s.fov_deg * M_PI / 180.0);
  const double aspect = double(s.width) / s.height;
  const double n = c.near_plane, fa = c.far_plane;
  const double projection[16] = {t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, -(fa + n) / (fa - n), -1,
                                 0, 0, -2 * fa * n / (fa - n), 0};
  Camera camera;
  multiply(projection, view, camera.view_projection);
  camera.width = s.width;
  camera.height = s.height;
  return camera;
}

// ---- OpenGL helpers ------------------------------------------------------------------

void check_gl(const char* where) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    char code[16];
    std::snprintf(code, sizeof(code), "0x%04x", error);
    throw std::runtime_error(std::string("OpenGL error ") + code + " during " + where);
  }
}

GLuint compile_shader(GLenum stage, const std::string& source, const char* name) {
  const GLuint shader = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(std::max(length, 1), '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    throw std::runtime_error(std::string("compiling shader ") + name + " failed: " + log.c_str());
  }
  return shader;
}

// A buffer texture (samplerBuffer): a GL buffer viewed as a 1-D texel array.
struct BufferTexture {
  GLuint buffer = 0, texture = 0;
  void upload(GLenum format, const void* data, size_t bytes, size_t element_bytes) {
    if (!buffer) {
      glGenBuffers(1, &buffer);
      glGenTextures(1, &texture);
    }
    // An empty buffer texture is not allowed everywhere: keep at least one element.
    std::vector<unsigned char> padding;
    if (bytes == 0) {
      padding.assign(element_bytes, 0);
      data = padding.data();
      bytes = element_bytes;
    }
    glBindBuffer(GL_TEXTURE_BUFFER, buffer);
    glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(bytes), data, GL_STREAM_DRAW);
    glBindTexture(GL_TEXTURE_BUFFER, texture);
    glTexBuffer(GL_TEXTURE_BUFFER, format, buffer);
    glBindBuffer(GL_TEXTURE_BUFFER, 0);
  }
  void release() {
    if (texture) glDeleteTextures(1, &texture);
    if (buffer) glDeleteBuffers(1, &buffer);
    texture = buffer = 0;
  }
};

struct Tessellation {
  GLuint vao = 0, vertices = 0, indices = 0;
  GLsizei index_count = 0;
};

}  // namespace

RenderSettings::Shading parse_shading(const std::string& name) {
  const std::string n = dashed(name);
  if (n == "flat") return RenderSettings::Shading::flat;
  if (n == "smooth") return RenderSettings::Shading::smooth;
  throw std::invalid_argument("shading '" + name + "' (valid: flat, smooth)");
}

RenderSettings::CutMethod parse_cut_method(const std::string& name) {
  const std::string n = dashed(name);
  if (n == "geometry-shader") return RenderSettings::CutMethod::geometry_shader;
  if (n == "drop-triangles") return RenderSettings::CutMethod::drop_triangles;
  if (n == "kill-pixels") return RenderSettings::CutMethod::kill_pixels;
  throw std::invalid_argument("cut method '" + name + "' (valid: geometry-shader, drop-triangles, kill-pixels)");
}

void Camera::project(const double p[3], double& pixel_x, double& pixel_y) const {
  const double* m = view_projection;
  double clip[4];
  for (int row = 0; row < 4; ++row) clip[row] = m[row] * p[0] + m[4 + row] * p[1] + m[8 + row] * p[2] + m[12 + row];
  pixel_x = 0.5 * (clip[0] / clip[3] + 1.0) * width;
  pixel_y = 0.5 * (1.0 - clip[1] / clip[3]) * height;
}

Camera make_camera(const ShellState& state, const RenderSettings& settings) {
  const DeformedShell shell(state);
  return camera_for(shell, settings);
}

// ---- renderer ----------------------------------------------------------------------

struct ShellRenderer::GlObjects {
  std::map<std::string, GLuint> programs;  // by preamble (the #defines)
  std::map<std::pair<int, int>, Tessellation> tessellations;  // by (element type, subdivisions)
  BufferTexture instance_elements, rest_positions, displacements, element_nodes, node_normals;
  BufferTexture element_slots, slot_tiles, slot_node_values, slot_dofs;
  GLuint atlas = 0;
  GLuint primitives_query = 0;  // GL_PRIMITIVES_GENERATED of a render
  GLuint framebuffer = 0, color = 0, depth = 0;
  int framebuffer_width = 0, framebuffer_height = 0;
  GLint max_texture_size = 0, max_array_layers = 0, max_buffer_texels = 0;

  GLuint program(const std::string& preamble) {
    auto it = programs.find(preamble);
    if (it != programs.end()) return it->second;
    // Compiler messages name lines as SOURCE:LINE with source 1 = shell_common.glsl,
    // 2 = the stage's own file.
    const std::string common = preamble + "#line 1 1\n" + embedded_shaders::shell_common_glsl + "\n#line 1 2\n";
    const GLuint vs = compile_shader(GL_VERTEX_SHADER, common + embedded_shaders::shell_vert, "shell.vert");
    const GLuint gs = compile_shader(GL_GEOMETRY_SHADER, common + embedded_shaders::shell_geom, "shell.geom");
    const GLuint fs = compile_shader(GL_FRAGMENT_SHADER, common + embedded_shaders::shell_frag, "shell.frag");
    const GLuint p = glCreateProgram();
    for (GLuint s : {vs, gs, fs}) glAttachShader(p, s);
    glLinkProgram(p);
    for (GLuint s : {vs, gs, fs}) glDeleteShader(s);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
      GLint length = 0;
      glGetProgramiv(p, GL_INFO_LOG_LENGTH, &length);
      std::string log(std::max(length, 1), '\0');
      glGetProgramInfoLog(p, length, nullptr, log.data());
      glDeleteProgram(p);
      throw std::runtime_error("linking the shell shader program failed: " + std::string(log.c_str()));
    }
    check_gl("shader compilation");
    programs[preamble] = p;
    return p;
  }

  // The static tessellation of one element's parameter domain (attribute 0: xi).
  const Tessellation& tessellation(ElementType type, int n) {
    const auto key = std::make_pair(static_cast<int>(type), n);
    auto it = tessellations.find(key);
    if (it != tessellations.end()) return it->second;
    std::vector<float> xi;
    std::vector<GLuint> indices;
    if (type == ElementType::quad8) {
      for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
          xi.push_back(-1.0f + 2.0f * i / n);
          xi.push_back(-1.0f + 2.0f * j / n);
        }
      auto id = [n](int i, int j) { return GLuint(j * (n + 1) + i); };
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          for (GLuint v : {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)})
            indices.push_back(v);
    } else {
      std::vector<GLuint> row_start(n + 2, 0);
      for (int j = 0; j <= n; ++j) {
        row_start[j + 1] = row_start[j] + (n + 1 - j);
        for (int i = 0; i + j <= n; ++i) {
          xi.push_back(float(i) / n);
          xi.push_back(float(j) / n);
        }
      }
      auto id = [&](int i, int j) { return row_start[j] + i; };
      for (int j = 0; j < n; ++j)
        for (int i = 0; i + j < n; ++i) {
          for (GLuint v : {id(i, j), id(i + 1, j), id(i, j + 1)}) indices.push_back(v);
          if (i + j < n - 1)
            for (GLuint v : {id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)}) indices.push_back(v);
        }
    }
    Tessellation t;
    glGenVertexArrays(1, &t.vao);
    glBindVertexArray(t.vao);
    glGenBuffers(1, &t.vertices);
    glBindBuffer(GL_ARRAY_BUFFER, t.vertices);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(xi.size() * sizeof(float)), xi.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    glGenBuffers(1, &t.indices);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, t.indices);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(GLuint)), indices.data(),
                 GL_STATIC_DRAW);
    glBindVertexArray(0);
    t.index_count = static_cast<GLsizei>(indices.size());
    check_gl("tessellation upload");
    return tessellations[key] = t;
  }

  void ensure_framebuffer(int width, int height) {
    if (framebuffer && framebuffer_width == width && framebuffer_height == height) return;
    if (!framebuffer) {
      glGenFramebuffers(1, &framebuffer);
      glGenRenderbuffers(1, &color);
      glGenRenderbuffers(1, &depth);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("framebuffer of " + std::to_string(width) + " x " + std::to_string(height) +
                               " pixels is incomplete (status " + std::to_string(status) + ")");
    framebuffer_width = width;
    framebuffer_height = height;
    check_gl("framebuffer setup");
  }

  void release() {
    for (auto& [key, p] : programs) glDeleteProgram(p);
    for (auto& [key, t] : tessellations) {
      glDeleteVertexArrays(1, &t.vao);
      glDeleteBuffers(1, &t.vertices);
      glDeleteBuffers(1, &t.indices);
    }
    for (BufferTexture* b : {&instance_elements, &rest_positions, &displacements, &element_nodes, &node_normals, &element_slots,
                             &slot_tiles, &slot_node_values, &slot_dofs})
      b->release();
    if (atlas) glDeleteTextures(1, &atlas);
    if (primitives_query) glDeleteQueries(1, &primitives_query);
    if (framebuffer) glDeleteFramebuffers(1, &framebuffer);
    if (color) glDeleteRenderbuffers(1, &color);
    if (depth) glDeleteRenderbuffers(1, &depth);
  }
};

ShellRenderer::ShellRenderer(std::shared_ptr<EglContext> context)
    : context_(context ? std::move(context) : std::make_shared<EglContext>()), gl_(std::make_unique<GlObjects>()) {
  context_->make_current();
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &gl_->max_texture_size);
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &gl_->max_array_layers);
  glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &gl_->max_buffer_texels);
  check_gl("querying limits");
}

ShellRenderer::~ShellRenderer() {
  try {
    context_->make_current();
    gl_->release();
  } catch (...) {
    // Destructors must not throw; the context's own teardown frees what is left.
  }
}

Image ShellRenderer::render(const ShellState& state, const RenderSettings& settings) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const DeformedShell shell(state);  // validates the state
  if (shell.max_enrichments_per_element() > kMaxEnrichmentsPerElement)
    throw std::invalid_argument("an element has " + std::to_string(shell.max_enrichments_per_element()) +
                                " enrichments; the renderer supports at most " +
                                std::to_string(kMaxEnrichmentsPerElement) + " per element");
  ResolvedCamera resolved;
  const Camera camera = camera_for(shell, settings, &resolved);
  context_->make_current();
  GlObjects& gl = *gl_;
  const Mesh& mesh = state.mesh;
  const int npe = mesh.nodes_per_element();
  const int elements = mesh.num_elements();
  const int slots_per_element = shell.max_enrichments_per_element();
  const bool smooth = settings.shading == RenderSettings::Shading::smooth;

  const size_t largest_buffer = std::max({mesh.elements.size(), static_cast<size_t>(mesh.num_nodes()),
                                           static_cast<size_t>(elements) * slots_per_element,
                                           state.enrichments.size() * npe});
  if (largest_buffer > static_cast<size_t>(gl.max_buffer_texels))
    throw std::invalid_argument("mesh too large for this OpenGL implementation's buffer textures (" +
                                std::to_string(largest_buffer) + " > GL_MAX_TEXTURE_BUFFER_SIZE " +
                                std::to_string(gl.max_buffer_texels) + ")");

  // Node data (RGBA32F: RGB32F buffer textures need GL 4.0).
  auto to_rgba = [](const std::vector<double>& xyz, size_t count) {
    std::vector<float> rgba(4 * count, 0.0f);
    for (size_t i = 0; i < count && 3 * i + 2 < xyz.size(); ++i)
      for (int d = 0; d < 3; ++d) rgba[4 * i + d] = static_cast<float>(xyz[3 * i + d]);
    return rgba;
  };
  const size_t nodes = mesh.num_nodes();
  const auto rest = to_rgba(mesh.positions, nodes);
  const auto displacement = to_rgba(state.displacement, nodes);
  gl.rest_positions.upload(GL_RGBA32F, rest.data(), rest.size() * sizeof(float), 16);
  gl.displacements.upload(GL_RGBA32F, displacement.data(), displacement.size() * sizeof(float), 16);
  gl.element_nodes.upload(GL_R32I, mesh.elements.data(), mesh.elements.size() * sizeof(int), 4);
  if (smooth) {
    const auto normals = to_rgba(shell.averaged_node_normals(), nodes);
    gl.node_normals.upload(GL_RGBA32F, normals.data(), normals.size() * sizeof(float), 16);
  }

  // Enrichment slots and the texture atlas: one tile of the largest resolution per slot,
  // packed in rows of a 2-D array texture.
  const int slot_count = static_cast<int>(state.enrichments.size());
  if (slots_per_element > 0) {
    std::vector<int> element_slots(static_cast<size_t>(elements) * slots_per_element, -1);
    for (int e = 0; e < elements; ++e) {
      const auto& list = shell.enrichments_of(e);
      for (size_t k = 0; k < list.size(); ++k) element_slots[static_cast<size_t>(e) * slots_per_element + k] = list[k];
    }
    int tile = 1;
    for (const auto& en : state.enrichments) tile = std::max(tile, en.resolution);
    if (tile > gl.max_texture_size)
      throw std::invalid_argument("enrichment resolution " + std::to_string(tile) + " exceeds GL_MAX_TEXTURE_SIZE " +
                                  std::to_string(gl.max_texture_size));
    const int tiles_per_row = std::max(1, std::min(gl.max_texture_size / tile,
                                                   static_cast<int>(std::ceil(std::sqrt(double(slot_count))))));
    const int rows = std::max(1, std::min(gl.max_texture_size / tile, (slot_count + tiles_per_row - 1) / tiles_per_row));
    const int per_layer = tiles_per_row * rows;
    const int layers = (slot_count + per_layer - 1) / per_layer;
    if (layers > gl.max_array_layers)
      throw std::invalid_argument(std::to_string(slot_count) + " enrichment textures of " + std::to_string(tile) +
                                  "^2 texels exceed the texture array limits of this OpenGL implementation");
    std::vector<int> tiles(4 * static_cast<size_t>(slot_count));
    std::vector<float> node_values(static_cast<size_t>(slot_count) * npe);
    std::vector<float> dofs(4 * static_cast<size_t>(slot_count) * npe, 0.0f);
    if (!gl.atlas) glGenTextures(1, &gl.atlas);
    glBindTexture(GL_TEXTURE_2D_ARRAY, gl.atlas);
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_R32F, tiles_per_row * tile, rows * tile, layers, 0, GL_RED, GL_FLOAT,
                 nullptr);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAX_LEVEL, 0);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    for (int s = 0; s < slot_count; ++s) {
      const ElementEnrichment& en = state.enrichments[s];
      const int layer = s / per_layer, in_layer = s % per_layer;
      const int x0 = (in_layer % tiles_per_row) * tile, y0 = (in_layer / tiles_per_row) * tile;
      tiles[4 * s + 0] = layer;
      tiles[4 * s + 1] = x0;
      tiles[4 * s + 2] = y0;
      tiles[4 * s + 3] = en.resolution;
      glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, x0, y0, layer, en.resolution, en.resolution, 1, GL_RED, GL_FLOAT,
                      en.values.data());
      for (int a = 0; a < npe; ++a) {
        node_values[static_cast<size_t>(s) * npe + a] = en.node_values[a];
        for (int d = 0; d < 3; ++d) dofs[4 * (static_cast<size_t>(s) * npe + a) + d] = static_cast<float>(en.dofs[3 * a + d]);
      }
    }
    gl.element_slots.upload(GL_R32I, element_slots.data(), element_slots.size() * sizeof(int), 4);
    gl.slot_tiles.upload(GL_RGBA32I, tiles.data(), tiles.size() * sizeof(int), 16);
    gl.slot_node_values.upload(GL_R32F, node_values.data(), node_values.size() * sizeof(float), 4);
    gl.slot_dofs.upload(GL_RGBA32F, dofs.data(), dofs.size() * sizeof(float), 16);
  }
  check_gl("uploading the state");
  const auto uploaded = Clock::now();

  // Two instanced draws: elements without enrichment through a program compiled without
  // enrichment slots (cheaper vertex and geometry stages), then the enriched elements.
  // u_instance_elements maps each draw's instances to elements.
  std::vector<int> instance_elements;
  instance_elements.reserve(elements);
  for (int pass = 0; pass < 2; ++pass)
    for (int e = 0; e < elements; ++e)
      if (shell.enrichments_of(e).empty() == (pass == 0)) instance_elements.push_back(e);
  int plain_elements = 0;
  while (plain_elements < elements && shell.enrichments_of(instance_elements[plain_elements]).empty()) ++plain_elements;
  gl.instance_elements.upload(GL_R32I, instance_elements.data(), instance_elements.size() * sizeof(int), 4);

  // The programs for this combination of options.
  auto preamble = [&](int slots) {
    const int cuts_per_triangle =
        settings.cut_method == RenderSettings::CutMethod::geometry_shader ? std::min(slots, kMaxCutsPerTriangle) : 0;
    std::string text = "#version 330 core\n";
    text += "#define NODES_PER_ELEMENT " + std::to_string(npe) + "\n";
    text += "#define ELEMENT_QUAD8 " + std::string(mesh.type == ElementType::quad8 ? "1" : "0") + "\n";
    text += "#define MAX_ENRICHMENTS " + std::to_string(slots) + "\n";
    text += "#define MAX_CUTS_PER_TRIANGLE " + std::to_string(cuts_per_triangle) + "\n";
    text += "#define CUT_METHOD " + std::to_string(static_cast<int>(settings.cut_method)) + "\n";
    text += "#define SMOOTH_SHADING " + std::string(smooth ? "1" : "0") + "\n";
    text += "#define WIREFRAME " + std::string(settings.wireframe ? "1" : "0") + "\n";
    text += "#define GEOMETRY_MAX_VERTICES " + std::to_string(3 << cuts_per_triangle) + "\n";
    return text;
  };
  const auto compile_start = Clock::now();
  const GLuint plain_program = plain_elements > 0 ? gl.program(preamble(0)) : 0;
  const GLuint enriched_program = plain_elements < elements ? gl.program(preamble(slots_per_element)) : 0;
  const Tessellation& tess = gl.tessellation(mesh.type, settings.tessellation);
  const auto drawing = Clock::now();

  gl.ensure_framebuffer(settings.width, settings.height);
  glBindFramebuffer(GL_FRAMEBUFFER, gl.framebuffer);
  glViewport(0, 0, settings.width, settings.height);
  glDisable(GL_MULTISAMPLE);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glClearColor(settings.background[0], settings.background[1], settings.background[2], 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  float view_projection[16];
  for (int i = 0; i < 16; ++i) view_projection[i] = static_cast<float>(camera.view_projection[i]);
  auto draw = [&](GLuint program, int first_instance, int count) {
    if (count == 0) return;
    glUseProgram(program);
    int unit = 0;
    auto bind = [&](const char* name, GLenum target, GLuint texture) {
      const GLint location = glGetUniformLocation(program, name);
      if (location < 0) return;  // unused by this combination of options
      glActiveTexture(GL_TEXTURE0 + unit);
      glBindTexture(target, texture);
      glUniform1i(location, unit);
      ++unit;
    };
    bind("u_instance_elements", GL_TEXTURE_BUFFER, gl.instance_elements.texture);
    bind("u_rest_positions", GL_TEXTURE_BUFFER, gl.rest_positions.texture);
    bind("u_displacements", GL_TEXTURE_BUFFER, gl.displacements.texture);
    bind("u_element_nodes", GL_TEXTURE_BUFFER, gl.element_nodes.texture);
    if (smooth) bind("u_node_normals", GL_TEXTURE_BUFFER, gl.node_normals.texture);
    if (slots_per_element > 0) {
      bind("u_element_slots", GL_TEXTURE_BUFFER, gl.element_slots.texture);
      bind("u_slot_tiles", GL_TEXTURE_BUFFER, gl.slot_tiles.texture);
      bind("u_slot_node_values", GL_TEXTURE_BUFFER, gl.slot_node_values.texture);
      bind("u_slot_dofs", GL_TEXTURE_BUFFER, gl.slot_dofs.texture);
      bind("u_atlas", GL_TEXTURE_2D_ARRAY, gl.atlas);
    }
    glUniform1i(glGetUniformLocation(program, "u_first_instance"), first_instance);
    glUniformMatrix4fv(glGetUniformLocation(program, "u_view_projection"), 1, GL_FALSE, view_projection);
    glUniform1f(glGetUniformLocation(program, "u_cut_threshold"), settings.cut_threshold);
    glUniform1i(glGetUniformLocation(program, "u_kill_radius"), settings.kill_radius_texels);
    glUniform1i(glGetUniformLocation(program, "u_tessellation"), settings.tessellation);
    glUniform3f(glGetUniformLocation(program, "u_camera_position"), float(resolved.eye[0]), float(resolved.eye[1]),
                float(resolved.eye[2]));
    glUniform3f(glGetUniformLocation(program, "u_surface_color"), 0.72f, 0.78f, 0.88f);
    check_gl("setting uniforms");
    glBindVertexArray(tess.vao);
    glDrawElementsInstanced(GL_TRIANGLES, tess.index_count, GL_UNSIGNED_INT, nullptr, count);
    glBindVertexArray(0);
    check_gl("drawing");
  };
  if (!gl.primitives_query) glGenQueries(1, &gl.primitives_query);
  glBeginQuery(GL_PRIMITIVES_GENERATED, gl.primitives_query);
  draw(plain_program, 0, plain_elements);
  draw(enriched_program, plain_elements, elements - plain_elements);
  glEndQuery(GL_PRIMITIVES_GENERATED);

  Image image(settings.width, settings.height);
  std::vector<std::uint8_t> bottom_up(image.rgba.size());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, settings.width, settings.height, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
  check_gl("reading back the image");
  GLuint primitives = 0;  // the read-back has waited for the draws: no stall here
  glGetQueryObjectuiv(gl.primitives_query, GL_QUERY_RESULT, &primitives);
  check_gl("reading the primitive count");
  last_triangles_drawn_ = primitives;
  last_triangles_submitted_ = static_cast<long long>(tess.index_count / 3) * elements;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  const size_t row = 4 * static_cast<size_t>(settings.width);
  for (int y = 0; y < settings.height; ++y)
    std::copy_n(bottom_up.data() + (settings.height - 1 - y) * row, row, image.rgba.data() + y * row);
  const auto done = Clock::now();
  last_upload_ms_ = std::chrono::duration<double, std::milli>(uploaded - start).count();
  last_setup_ms_ = std::chrono::duration<double, std::milli>(drawing - compile_start).count();
  last_draw_ms_ = std::chrono::duration<double, std::milli>(done - drawing).count();
  return image;
}

}  // namespace dgtex
