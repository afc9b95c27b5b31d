#include "rms/esg_renderer/gl_context.h"

#include <dlfcn.h>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>
#include <cstring>
#include <stdexcept>

#include "rms/base/check.h"

namespace rms::esg_renderer {

GlBackend ParseGlBackend(const std::string& name) {
  if (name == "osmesa") return GlBackend::kOsMesa;
  if (name == "egl") return GlBackend::kEgl;
  throw InputError("unknown GL backend '" + name + "' (osmesa or egl)");
}

namespace {

void CheckSize(int w, int h) {
  if (w < 16 || h < 16 || w > 8192 || h > 8192) {
    throw std::runtime_error("image size " + std::to_string(w) + "x" + std::to_string(h) +
                             " must be between 16 and 8192 pixels a side");
  }
}

void* OpenFirst(std::initializer_list<const char*> names, std::string* tried) {
  for (const char* n : names) {
    if (void* h = dlopen(n, RTLD_NOW | RTLD_LOCAL)) return h;
    *tried += std::string(tried->empty() ? "" : ", ") + n;
  }
  return nullptr;
}

std::string Describe(const GlApi& gl, const char* backend) {
  const char* r = reinterpret_cast<const char*>(gl.GetString(GL_RENDERER));
  const char* v = reinterpret_cast<const char*>(gl.GetString(GL_VERSION));
  return std::string(backend) + ": " + (r ? r : "?") + ", GL " + (v ? v : "?");
}

// ---------------------------------------------------------------- OSMesa

class OsMesaContext final : public GlContext {
 public:
  OsMesaContext(int w, int h) : w_(w), h_(h), buffer_(static_cast<std::size_t>(w) * h * 4) {
    std::string tried;
    lib_ = OpenFirst({"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}, &tried);
    if (!lib_)
      throw std::runtime_error("cannot load OSMesa (" + tried +
                               "): install libosmesa6, or use --gl egl");
    create_ = reinterpret_cast<decltype(create_)>(dlsym(lib_, "OSMesaCreateContextExt"));
    make_current_ = reinterpret_cast<decltype(make_current_)>(dlsym(lib_, "OSMesaMakeCurrent"));
    destroy_ = reinterpret_cast<decltype(destroy_)>(dlsym(lib_, "OSMesaDestroyContext"));
    pixel_store_ = reinterpret_cast<decltype(pixel_store_)>(dlsym(lib_, "OSMesaPixelStore"));
    get_proc_ = reinterpret_cast<decltype(get_proc_)>(dlsym(lib_, "OSMesaGetProcAddress"));
    if (!create_ || !make_current_ || !destroy_ || !pixel_store_ || !get_proc_) {
      throw std::runtime_error("OSMesa library lacks its entry points");
    }
    // A 32-bit depth buffer where the driver has one (the reference mode's
    // precision at contact lines), else 24.
    ctx_ = create_(OSMESA_RGBA, 32, 0, 0, nullptr);
    if (!ctx_) ctx_ = create_(OSMESA_RGBA, 24, 0, 0, nullptr);
    if (!ctx_) throw std::runtime_error("OSMesaCreateContextExt failed");
    if (!make_current_(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, w_, h_)) {
      throw std::runtime_error("OSMesaMakeCurrent failed for " + std::to_string(w) + "x" +
                               std::to_string(h));
    }
    pixel_store_(OSMESA_Y_UP, 0);  // row 0 is the top of the image
    const std::string missing =
        gl_.Load([&](const char* n) { return reinterpret_cast<void*>(get_proc_(n)); }, false);
    if (!missing.empty()) throw std::runtime_error("OSMesa has no " + missing);
  }
  ~OsMesaContext() override {
    if (ctx_) destroy_(ctx_);
    // The library stays loaded: llvmpipe's threads may outlive the context.
  }
  int width() const override { return w_; }
  int height() const override { return h_; }
  const GlApi& gl() const override { return gl_; }
  void MakeCurrent() override {
    make_current_(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, w_, h_);
    pixel_store_(OSMESA_Y_UP, 0);
  }
  std::uint8_t* FinishAndGetPixels() override {
    gl_.Finish();
    return buffer_.data();
  }
  std::string description() const override { return Describe(gl_, "OSMesa"); }

 private:
  int w_, h_;
  std::vector<std::uint8_t> buffer_;
  void* lib_ = nullptr;
  OSMesaContext (*create_)(GLenum, GLint, GLint, GLint, OSMesaContext) = nullptr;
  GLboolean (*make_current_)(OSMesaContext, void*, GLenum, GLsizei, GLsizei) = nullptr;
  void (*destroy_)(OSMesaContext) = nullptr;
  void (*pixel_store_)(GLint, GLint) = nullptr;
  OSMESAproc (*get_proc_)(const char*) = nullptr;
  OSMesaContext ctx_ = nullptr;
  GlApi gl_;
};

// ---------------------------------------------------------------- EGL

class EglContext final : public GlContext {
 public:
  EglContext(int w, int h)
      : w_(w), h_(h), raw_(static_cast<std::size_t>(w) * h * 4), buffer_(raw_.size()) {
    std::string tried;
    lib_ = OpenFirst({"libEGL.so.1", "libEGL.so"}, &tried);
    if (!lib_) throw std::runtime_error("cannot load EGL (" + tried + "): install libegl1");
    auto sym = [&](const char* n) { return dlsym(lib_, n); };
    auto get_proc = reinterpret_cast<void* (*)(const char*)>(sym("eglGetProcAddress"));
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(get_proc("eglGetPlatformDisplayEXT"));
    auto initialize = reinterpret_cast<PFNEGLINITIALIZEPROC>(sym("eglInitialize"));
    auto bind_api = reinterpret_cast<PFNEGLBINDAPIPROC>(sym("eglBindAPI"));
    auto choose = reinterpret_cast<PFNEGLCHOOSECONFIGPROC>(sym("eglChooseConfig"));
    auto create = reinterpret_cast<PFNEGLCREATECONTEXTPROC>(sym("eglCreateContext"));
    auto make_current = reinterpret_cast<PFNEGLMAKECURRENTPROC>(sym("eglMakeCurrent"));
    if (!get_proc || !get_platform_display || !initialize || !bind_api || !choose || !create ||
        !make_current) {
      throw std::runtime_error("EGL lacks EGL_EXT_platform_base or its core entry points");
    }
    display_ = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (display_ == EGL_NO_DISPLAY || !initialize(display_, &major, &minor)) {
      throw std::runtime_error(
          "EGL surfaceless display (EGL_MESA_platform_surfaceless) is not available");
    }
    if (!bind_api(EGL_OPENGL_API)) throw std::runtime_error("EGL cannot bind the OpenGL API");
    const EGLint attrs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                            EGL_NONE};
    EGLConfig config = nullptr;
    EGLint n = 0;
    choose(display_, attrs, &config, 1, &n);
    // A compatibility-profile context (fixed-function pipeline).
    const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 2, EGL_CONTEXT_MINOR_VERSION, 1,
                                EGL_NONE};
    ctx_ = create(display_, n > 0 ? config : nullptr, EGL_NO_CONTEXT, ctx_attrs);
    if (ctx_ == EGL_NO_CONTEXT) throw std::runtime_error("eglCreateContext failed");
    make_current_ = make_current;
    if (!make_current(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx_)) {
      throw std::runtime_error(
          "eglMakeCurrent without a surface failed (EGL_KHR_surfaceless_context)");
    }
    const std::string missing = gl_.Load([&](const char* name) { return get_proc(name); }, true);
    if (!missing.empty()) throw std::runtime_error("EGL's OpenGL has no " + missing);
    GLuint color = 0, depth = 0;
    gl_.GenFramebuffers(1, &fbo_);
    gl_.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
    gl_.GenRenderbuffers(1, &color);
    gl_.BindRenderbuffer(GL_RENDERBUFFER, color);
    gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    gl_.GenRenderbuffers(1, &depth);
    gl_.BindRenderbuffer(GL_RENDERBUFFER, depth);
    gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, w, h);
    gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    if (gl_.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error("EGL framebuffer object is incomplete");
    }
  }
  int width() const override { return w_; }
  int height() const override { return h_; }
  const GlApi& gl() const override { return gl_; }
  void MakeCurrent() override {
    make_current_(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx_);
    gl_.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
  }
  std::uint8_t* FinishAndGetPixels() override {
    gl_.Finish();
    gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl_.ReadPixels(0, 0, w_, h_, GL_RGBA, GL_UNSIGNED_BYTE, raw_.data());
    const std::size_t row = static_cast<std::size_t>(w_) * 4;
    for (int y = 0; y < h_; ++y) {  // GL's rows run bottom to top
      std::memcpy(buffer_.data() + y * row, raw_.data() + (h_ - 1 - y) * row, row);
    }
    return buffer_.data();
  }
  std::string description() const override { return Describe(gl_, "EGL surfaceless"); }

 private:
  int w_, h_;
  std::vector<std::uint8_t> raw_, buffer_;
  void* lib_ = nullptr;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext ctx_ = EGL_NO_CONTEXT;
  PFNEGLMAKECURRENTPROC make_current_ = nullptr;
  GLuint fbo_ = 0;
  GlApi gl_;
};

}  // namespace

std::unique_ptr<GlContext> CreateGlContext(GlBackend backend, int width, int height) {
  CheckSize(width, height);
  if (backend == GlBackend::kEgl) return std::make_unique<EglContext>(width, height);
  return std::make_unique<OsMesaContext>(width, height);
}

}  // namespace rms::esg_renderer
