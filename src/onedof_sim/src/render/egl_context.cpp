#include "egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <sstream>

namespace onedof_sim {
namespace render {
namespace {

std::string eglFailure(const char* step) {
  std::ostringstream text;
  text << step << " failed (EGL error 0x" << std::hex << eglGetError() << ")";
  return text.str();
}

bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  const size_t length = std::strlen(name);
  for (const char* at = std::strstr(list, name); at; at = std::strstr(at + 1, name))
    if ((at == list || at[-1] == ' ') && (at[length] == ' ' || at[length] == '\0')) return true;
  return false;
}

}  // namespace

std::unique_ptr<EglContext> EglContext::create(std::string* error) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(client, "EGL_MESA_platform_surfaceless")) {
    *error = "EGL has no surfaceless platform (EGL_MESA_platform_surfaceless: Mesa's EGL, "
             "Debian's libegl-mesa0, is not installed)";
    return nullptr;
  }
  auto get_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_display) {
    *error = "EGL has no eglGetPlatformDisplayEXT";
    return nullptr;
  }
  EGLDisplay display = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0, minor = 0;
  if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor)) {
    *error = eglFailure("eglInitialize on the surfaceless platform");
    return nullptr;
  }
  std::unique_ptr<EglContext> out(new EglContext);
  out->display_ = display;
  if (!hasExtension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
    *error = "EGL cannot make a context current without a surface (EGL_KHR_surfaceless_context)";
    return nullptr;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    *error = eglFailure("eglBindAPI(EGL_OPENGL_API)");
    return nullptr;
  }
  const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                      EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint configs = 0;
  if (!eglChooseConfig(display, config_attributes, &config, 1, &configs) || configs < 1) {
    *error = eglFailure("eglChooseConfig (an OpenGL config)");
    return nullptr;
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                       EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
  if (context == EGL_NO_CONTEXT) {
    *error = eglFailure("eglCreateContext (OpenGL 3.3 core)");
    return nullptr;
  }
  out->context_ = context;
  if (!out->makeCurrent()) {
    *error = eglFailure("eglMakeCurrent without a surface");
    return nullptr;
  }
  return out;
}

EglContext::~EglContext() {
  if (!display_) return;
  if (context_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
  }
  // The display is not terminated: EGL displays are shared by the process, and another
  // renderer may be using it.
}

bool EglContext::makeCurrent() {
  return eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) == EGL_TRUE;
}

}  // namespace render
}  // namespace onedof_sim
