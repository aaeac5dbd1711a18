#pragma once
// A headless OpenGL context through EGL: no display server, no window. Rendering goes
// into framebuffer objects of the caller.
//
// Creation order (the first that yields an OpenGL 4.5 core context, else 3.3 core, wins):
//   1. EGL_EXT_platform_device: if the environment variable DGTEX_EGL_DEVICE=INDEX is set,
//      only that device; otherwise hardware devices (EGL_EXT_device_drm) first, then
//      other devices, then Mesa's software device (EGL_MESA_device_software, llvmpipe).
//   2. EGL_MESA_platform_surfaceless (DGTEX_EGL_DEVICE=surfaceless tries only this).
// If none works, the constructor throws EglUnavailableError whose message is one line
// listing every attempt and why it failed.
//
// The context is made current on the constructing thread; call make_current() before
// using it from another thread (one thread at a time; it throws std::runtime_error when
// EGL refuses, e.g. while the context is current on another thread).
// EglContext owns the EGL display connection and context (released by the destructor;
// not copyable); share it between renderers through std::shared_ptr.
#include <stdexcept>
#include <string>

namespace dgtex {

class EglUnavailableError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class EglContext {
 public:
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  void make_current() const;

  int gl_major() const { return gl_major_; }
  int gl_minor() const { return gl_minor_; }
  // e.g. "EGL device 1 (software), OpenGL 4.5 core, llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string& description() const { return description_; }

 private:
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  int gl_major_ = 0;
  int gl_minor_ = 0;
  std::string description_;
};

}  // namespace dgtex
