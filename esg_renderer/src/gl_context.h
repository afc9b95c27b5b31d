#pragma once
// The GL context behind one small interface. OSMesa (software, headless) is
// the default backend; OSMesa has been removed from recent Mesa releases, so
// a second backend (EGL surfaceless) belongs behind this same interface.
#include <cstdint>
#include <memory>
#include <string>

namespace rms::esg {

class GlContext {
 public:
  virtual ~GlContext() = default;
  virtual int width() const = 0;
  virtual int height() const = 0;
  // Finishes rendering and returns the frame: RGBA, 8 bits a channel, rows
  // top to bottom, valid until the next frame is drawn.
  virtual const std::uint8_t* FinishAndGetPixels() = 0;
  virtual std::string description() const = 0;
};

// Creates and makes current a legacy (fixed-function) GL context rendering
// into a width x height RGBA buffer with a 24-bit depth buffer. Throws
// std::runtime_error with the reason when it cannot.
std::unique_ptr<GlContext> CreateOsMesaContext(int width, int height);

}  // namespace rms::esg
