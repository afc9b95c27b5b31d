#pragma once
// The OpenGL entry points the ESG uses, as a table of function pointers
// filled by the context's backend (OSMesaGetProcAddress or eglGetProcAddress).
// Nothing links libGL or libOSMesa at build time: both backends are loaded at
// run time, so their gl* symbols never clash in one binary.
#include <GL/gl.h>
#include <GL/glext.h>
#include <string>

namespace rms::esg_renderer {

struct GlApi {
  void (*Viewport)(GLint, GLint, GLsizei, GLsizei) = nullptr;
  void (*ClearColor)(GLfloat, GLfloat, GLfloat, GLfloat) = nullptr;
  void (*Clear)(GLbitfield) = nullptr;
  void (*MatrixMode)(GLenum) = nullptr;
  void (*LoadMatrixd)(const GLdouble*) = nullptr;
  void (*Enable)(GLenum) = nullptr;
  void (*Disable)(GLenum) = nullptr;
  void (*CullFace)(GLenum) = nullptr;
  void (*FrontFace)(GLenum) = nullptr;
  void (*ShadeModel)(GLenum) = nullptr;
  void (*DepthFunc)(GLenum) = nullptr;
  void (*DepthMask)(GLboolean) = nullptr;
  void (*EnableClientState)(GLenum) = nullptr;
  void (*VertexPointer)(GLint, GLenum, GLsizei, const void*) = nullptr;
  void (*ColorPointer)(GLint, GLenum, GLsizei, const void*) = nullptr;
  void (*DrawArrays)(GLenum, GLint, GLsizei) = nullptr;
  void (*Finish)() = nullptr;
  void (*ReadPixels)(GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, void*) = nullptr;
  void (*PixelStorei)(GLenum, GLint) = nullptr;
  const GLubyte* (*GetString)(GLenum) = nullptr;
  GLenum (*GetError)() = nullptr;
  // Framebuffer objects (the EGL backend renders into one).
  void (*GenFramebuffers)(GLsizei, GLuint*) = nullptr;
  void (*BindFramebuffer)(GLenum, GLuint) = nullptr;
  void (*GenRenderbuffers)(GLsizei, GLuint*) = nullptr;
  void (*BindRenderbuffer)(GLenum, GLuint) = nullptr;
  void (*RenderbufferStorage)(GLenum, GLenum, GLsizei, GLsizei) = nullptr;
  void (*FramebufferRenderbuffer)(GLenum, GLenum, GLenum, GLuint) = nullptr;
  GLenum (*CheckFramebufferStatus)(GLenum) = nullptr;

  // Fills every pointer with `get(name)`; returns the first name it could
  // not find, or "" when all were found (framebuffer functions only when
  // `need_fbo`).
  template <class Getter>
  std::string Load(Getter get, bool need_fbo);
};

template <class Getter>
std::string GlApi::Load(Getter get, bool need_fbo) {
#define RMS_GL_LOAD(field, name)                        \
  field = reinterpret_cast<decltype(field)>(get(name)); \
  if (!(field)) return name;
  RMS_GL_LOAD(Viewport, "glViewport")
  RMS_GL_LOAD(ClearColor, "glClearColor")
  RMS_GL_LOAD(Clear, "glClear")
  RMS_GL_LOAD(MatrixMode, "glMatrixMode")
  RMS_GL_LOAD(LoadMatrixd, "glLoadMatrixd")
  RMS_GL_LOAD(Enable, "glEnable")
  RMS_GL_LOAD(Disable, "glDisable")
  RMS_GL_LOAD(CullFace, "glCullFace")
  RMS_GL_LOAD(FrontFace, "glFrontFace")
  RMS_GL_LOAD(ShadeModel, "glShadeModel")
  RMS_GL_LOAD(DepthFunc, "glDepthFunc")
  RMS_GL_LOAD(DepthMask, "glDepthMask")
  RMS_GL_LOAD(EnableClientState, "glEnableClientState")
  RMS_GL_LOAD(VertexPointer, "glVertexPointer")
  RMS_GL_LOAD(ColorPointer, "glColorPointer")
  RMS_GL_LOAD(DrawArrays, "glDrawArrays")
  RMS_GL_LOAD(Finish, "glFinish")
  RMS_GL_LOAD(ReadPixels, "glReadPixels")
  RMS_GL_LOAD(PixelStorei, "glPixelStorei")
  RMS_GL_LOAD(GetString, "glGetString")
  RMS_GL_LOAD(GetError, "glGetError")
  if (need_fbo) {
    RMS_GL_LOAD(GenFramebuffers, "glGenFramebuffers")
    RMS_GL_LOAD(BindFramebuffer, "glBindFramebuffer")
    RMS_GL_LOAD(GenRenderbuffers, "glGenRenderbuffers")
    RMS_GL_LOAD(BindRenderbuffer, "glBindRenderbuffer")
    RMS_GL_LOAD(RenderbufferStorage, "glRenderbufferStorage")
    RMS_GL_LOAD(FramebufferRenderbuffer, "glFramebufferRenderbuffer")
    RMS_GL_LOAD(CheckFramebufferStatus, "glCheckFramebufferStatus")
  }
#undef RMS_GL_LOAD
  return "";
}

}  // namespace rms::esg_renderer
