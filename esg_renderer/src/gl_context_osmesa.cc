#include <GL/osmesa.h>

#include <stdexcept>
#include <vector>

#include "gl_context.h"

namespace rms::esg {

namespace {

class OsMesaContext final : public GlContext {
 public:
  OsMesaContext(int w, int h) : w_(w), h_(h), buffer_(static_cast<std::size_t>(w) * h * 4) {
    ctx_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
    if (ctx_ == nullptr) throw std::runtime_error("OSMesaCreateContextExt failed");
    if (!OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, w_, h_)) {
      OSMesaDestroyContext(ctx_);
      throw std::runtime_error("OSMesaMakeCurrent failed for " + std::to_string(w) + "x" +
                               std::to_string(h));
    }
    OSMesaPixelStore(OSMESA_Y_UP, 0);  // row 0 is the top of the image
  }
  ~OsMesaContext() override { OSMesaDestroyContext(ctx_); }
  int width() const override { return w_; }
  int height() const override { return h_; }
  const std::uint8_t* FinishAndGetPixels() override {
    glFinish();
    return buffer_.data();
  }
  std::string description() const override {
    const char* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const char* v = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    return std::string("OSMesa: ") + (r ? r : "?") + ", GL " + (v ? v : "?");
  }

 private:
  int w_, h_;
  std::vector<std::uint8_t> buffer_;
  OSMesaContext ctx_ = nullptr;
};

}  // namespace

std::unique_ptr<GlContext> CreateOsMesaContext(int width, int height) {
  if (width < 16 || height < 16 || width > 8192 || height > 8192) {
    throw std::runtime_error("image size " + std::to_string(width) + "x" + std::to_string(height) +
                             " must be between 16 and 8192 pixels a side");
  }
  return std::make_unique<OsMesaContext>(width, height);
}

}  // namespace rms::esg
