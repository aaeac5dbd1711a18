#include "dgtex/egl_context.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdlib>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

namespace dgtex {
namespace {

const char* egl_error_name(EGLint code) {
  switch (code) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: return "unknown EGL error";
  }
}

// The error of the last EGL call, as text ("" on success). Reading it also clears it.
std::string egl_error() {
  const EGLint code = eglGetError();
  if (code == EGL_SUCCESS) return "";
  std::ostringstream s;
  s << egl_error_name(code) << " (0x" << std::hex << code << ")";
  return s.str();
}

bool has_extension(const char* list, const std::string& name) {
  if (!list) return false;
  std::istringstream words(list);
  std::string word;
  while (words >> word)
    if (word == name) return true;
  return false;
}

// EGL displays are per device and process-wide, and eglTerminate is not reference counted:
// count the live contexts per display so one context's teardown never kills another's.
std::mutex display_mutex;
std::map<EGLDisplay, int> display_users;

void release_display(EGLDisplay display) {
  std::lock_guard<std::mutex> lock(display_mutex);
  if (display_users[display] == 0) {
    eglTerminate(display);
    egl_error();
  }
}

struct Candidate {
  std::string label;  // "EGL device 0 (/dev/dri/card0)"
  EGLenum platform;
  void* native;       // EGLDeviceEXT or EGL_DEFAULT_DISPLAY
};

struct Created {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  int gl_major = 0, gl_minor = 0;
};

// Tries one display; on success the context is current. On failure returns false with
// the reason in why and leaves nothing initialized.
bool try_candidate(const Candidate& c, Created& out, std::string& why) {
  EGLDisplay display = eglGetPlatformDisplayEXT(c.platform, c.native, nullptr);
  std::string err = egl_error();
  if (display == EGL_NO_DISPLAY) {
    why = "eglGetPlatformDisplayEXT failed" + (err.empty() ? "" : ": " + err);
    return false;
  }
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) {
    why = "eglInitialize failed: " + egl_error();
    return false;
  }
  auto fail = [&](const std::string& reason) {
    why = reason;
    release_display(display);
    return false;
  };
  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  if ((err = egl_error()) != "") return fail("eglQueryString failed: " + err);
  if (!has_extension(extensions, "EGL_KHR_surfaceless_context"))
    return fail("no EGL_KHR_surfaceless_context");
  if (!eglBindAPI(EGL_OPENGL_API)) return fail("eglBindAPI(EGL_OPENGL_API) failed: " + egl_error());

  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!has_extension(extensions, "EGL_KHR_no_config_context")) {
    const EGLint attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display, attributes, &config, 1, &count))
      return fail("eglChooseConfig failed: " + egl_error());
    if (count < 1) return fail("no EGLConfig renders OpenGL");
  }
  // OpenGL 4.5 core, else 3.3 core (enough for the geometry-shader renderer).
  const int versions[2][2] = {{4, 5}, {3, 3}};
  std::string context_errors;
  for (const auto& v : versions) {
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, v[0], EGL_CONTEXT_MINOR_VERSION, v[1],
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                 EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, attributes);
    err = egl_error();
    if (context == EGL_NO_CONTEXT) {
      context_errors += (context_errors.empty() ? "" : ", ") + std::to_string(v[0]) + "." +
                        std::to_string(v[1]) + " core: " + (err.empty() ? "failed" : err);
      continue;
    }
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
      err = egl_error();
      eglDestroyContext(display, context);
      egl_error();
      return fail("eglMakeCurrent (surfaceless) failed: " + err);
    }
    {
      std::lock_guard<std::mutex> lock(display_mutex);
      ++display_users[display];
    }
    out.display = display;
    out.context = context;
    out.gl_major = v[0];
    out.gl_minor = v[1];
    return true;
  }
  return fail("eglCreateContext failed (" + context_errors + ")");
}

// The candidates in the order of the header comment; notes records what was skipped.
std::vector<Candidate> list_candidates(std::vector<std::string>& notes) {
  std::vector<Candidate> result;
  const char* forced = std::getenv("DGTEX_EGL_DEVICE");
  const bool surfaceless_only = forced && std::string(forced) == "surfaceless";
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const std::string err = egl_error();
  if (!client) {
    notes.push_back("EGL client extensions unavailable" + (err.empty() ? "" : ": " + err));
    return result;
  }
  if (!has_extension(client, "EGL_EXT_platform_base")) {
    notes.push_back("libEGL offers no EGL_EXT_platform_base (no EGL vendor library loaded; see __EGL_VENDOR_LIBRARY_FILENAMES)");
    return result;
  }
  if (surfaceless_only) {
    notes.push_back("DGTEX_EGL_DEVICE=surfaceless skips EGL_EXT_platform_device");
  } else if (has_extension(client, "EGL_EXT_platform_device") && has_extension(client, "EGL_EXT_device_enumeration")) {
    EGLint count = 0;
    std::vector<EGLDeviceEXT> devices;
    if (!eglQueryDevicesEXT(0, nullptr, &count)) {
      notes.push_back("eglQueryDevicesEXT failed: " + egl_error());
      count = 0;
    } else {
      devices.resize(count);
      if (count > 0 && !eglQueryDevicesEXT(count, devices.data(), &count)) {
        notes.push_back("eglQueryDevicesEXT failed: " + egl_error());
        count = 0;
      }
      devices.resize(count);
    }
    if (devices.empty()) notes.push_back("EGL_EXT_platform_device: no devices");

    std::vector<Candidate> hardware, software, other;
    for (int i = 0; i < static_cast<int>(devices.size()); ++i) {
      const char* device_extensions = eglQueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
      egl_error();
      std::string label = "EGL device " + std::to_string(i);
      if (has_extension(device_extensions, "EGL_EXT_device_drm")) {
        const char* file = eglQueryDeviceStringEXT(devices[i], EGL_DRM_DEVICE_FILE_EXT);
        egl_error();
        hardware.push_back({label + " (" + (file ? file : "drm") + ")", EGL_PLATFORM_DEVICE_EXT, devices[i]});
      } else if (has_extension(device_extensions, "EGL_MESA_device_software")) {
        software.push_back({label + " (software)", EGL_PLATFORM_DEVICE_EXT, devices[i]});
      } else {
        other.push_back({label, EGL_PLATFORM_DEVICE_EXT, devices[i]});
      }
    }
    if (const char* forced = std::getenv("DGTEX_EGL_DEVICE"); forced && *forced && std::string(forced) != "surfaceless") {
      char* end = nullptr;
      const long index = std::strtol(forced, &end, 10);
      if (*end != '\0' || index < 0 || index >= static_cast<long>(devices.size())) {
        throw EglUnavailableError("DGTEX_EGL_DEVICE=" + std::string(forced) +
                                  " is neither 'surfaceless' nor a device index (valid: 0.." +
                                  std::to_string(static_cast<long>(devices.size()) - 1) + ", " +
                                  std::to_string(devices.size()) + " EGL devices found)");
      }
      for (const auto* group : {&hardware, &software, &other})
        for (const auto& c : *group)
          if (c.native == devices[index]) return {c};
    }
    for (const auto* group : {&hardware, &other, &software}) result.insert(result.end(), group->begin(), group->end());
  } else {
    notes.push_back("libEGL lacks EGL_EXT_platform_device");
  }
  if (has_extension(client, "EGL_MESA_platform_surfaceless"))
    result.push_back({"EGL_MESA_platform_surfaceless", EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY});
  else
    notes.push_back("libEGL lacks EGL_MESA_platform_surfaceless");
  return result;
}

}  // namespace

EglContext::EglContext() {
  std::vector<std::string> notes;
  const std::vector<Candidate> candidates = list_candidates(notes);
  Created created;
  std::string chosen;
  for (const auto& c : candidates) {
    std::string why;
    if (try_candidate(c, created, why)) {
      chosen = c.label;
      break;
    }
    notes.push_back(c.label + ": " + why);
  }
  if (created.context == EGL_NO_CONTEXT) {
    std::string message = "no OpenGL 3.3+ core context through EGL (tried: ";
    for (size_t i = 0; i < notes.size(); ++i) message += (i ? "; " : "") + notes[i];
    message += "); install Mesa's EGL and DRI drivers (libegl-mesa0, libgl1-mesa-dri) or a GPU driver";
    throw EglUnavailableError(message);
  }
  display_ = created.display;
  context_ = created.context;
  gl_major_ = created.gl_major;
  gl_minor_ = created.gl_minor;
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  description_ = chosen + ", OpenGL " + std::to_string(gl_major_) + "." + std::to_string(gl_minor_) + " core, " +
                 (renderer ? renderer : "unknown renderer");
}

EglContext::~EglContext() {
  if (display_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_) eglDestroyContext(display_, context_);
    eglGetError();
    {
      std::lock_guard<std::mutex> lock(display_mutex);
      --display_users[display_];
    }
    release_display(display_);
  }
}

void EglContext::make_current() const {
  if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
    throw std::runtime_error("eglMakeCurrent failed: " + egl_error());
}

}  // namespace dgtex
