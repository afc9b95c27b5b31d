#pragma once
// The GL context behind one small interface, two backends:
//  - OSMesa (default): Mesa's off-screen software renderer, headless;
//  - EGL surfaceless (EGL_PLATFORM_SURFACELESS_MESA) rendering into a
//    framebuffer object: OSMesa has been removed from recent Mesa releases,
//    and this backend works there.
// Both give a compatibility-profile context (the fixed-function pipeline)
// and RGBA frames with rows top to bottom.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rms/esg_renderer/gl_api.h"

namespace rms::esg_renderer {

enum class GlBackend { kOsMesa, kEgl };
// "osmesa" / "egl"; throws rms::InputError for another name.
GlBackend ParseGlBackend(const std::string& name);

class GlContext {
 public:
  virtual ~GlContext() = default;
  virtual int width() const = 0;
  virtual int height() const = 0;
  virtual const GlApi& gl() const = 0;
  // Makes this context current on the calling thread (several may coexist).
  virtual void MakeCurrent() = 0;
  // Finishes rendering and returns the frame: RGBA, rows top to bottom,
  // valid until the next frame is drawn.
  virtual std::uint8_t* FinishAndGetPixels() = 0;
  virtual std::string description() const = 0;
};

// Creates the context and makes it current. Throws std::runtime_error with
// the reason when the backend cannot be loaded or set up.
std::unique_ptr<GlContext> CreateGlContext(GlBackend backend, int width, int height);

}  // namespace rms::esg_renderer
