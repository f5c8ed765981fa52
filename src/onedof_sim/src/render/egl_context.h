// An OpenGL 3.3 core context on Mesa's surfaceless EGL platform: no display, no window, no X
// server; drawing goes to framebuffer objects. Where the machine has no GPU (CI, containers),
// Mesa renders on the CPU (llvmpipe).
#pragma once

#include <memory>
#include <string>

namespace onedof_sim {
namespace render {

class EglContext {
 public:
  // Null and *error saying which step failed (and EGL's error code) when there is none to have.
  static std::unique_ptr<EglContext> create(std::string* error);
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;
  // Makes the context current on the calling thread; false if EGL refuses.
  bool makeCurrent();

 private:
  EglContext() = default;
  void* display_ = nullptr;
  void* context_ = nullptr;
};

}  // namespace render
}  // namespace onedof_sim
