#include "window.h"

#include <SDL2/SDL.h>

#include <stdexcept>

namespace rms::esg {

struct LiveWindow::Impl {
  SDL_Window* window = nullptr;
};

LiveWindow::LiveWindow(int width, int height, const std::string& title)
    : impl_(std::make_unique<Impl>()), width_(width), height_(height) {
  // The window surface must not be backed by GL: SDL would load GLX into a
  // process whose GL is OSMesa's (or EGL's), and GLX's swrast then crashes
  // on the first update. A plain X11 image (XShm / XPutImage) is all a
  // blit needs.
  SDL_SetHint(SDL_HINT_FRAMEBUFFER_ACCELERATION, "0");
  if (SDL_InitSubSystem(SDL_INIT_VIDEO) != 0) {
    throw std::runtime_error(std::string("cannot open a window: ") + SDL_GetError());
  }
  impl_->window = SDL_CreateWindow(title.c_str(), SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, width, height, 0);
  if (!impl_->window) throw std::runtime_error(std::string("SDL_CreateWindow: ") + SDL_GetError());
  open_ = true;
}

LiveWindow::~LiveWindow() {
  if (impl_->window) SDL_DestroyWindow(impl_->window);
  SDL_QuitSubSystem(SDL_INIT_VIDEO);
}

bool LiveWindow::Show(const std::uint8_t* rgba) {
  if (!open_) return false;
  SDL_Event e;
  while (SDL_PollEvent(&e)) {
    if (e.type == SDL_QUIT || (e.type == SDL_WINDOWEVENT && e.window.event == SDL_WINDOWEVENT_CLOSE)) {
      open_ = false;
      SDL_DestroyWindow(impl_->window);
      impl_->window = nullptr;
      return false;
    }
  }
  SDL_Surface* frame = SDL_CreateRGBSurfaceWithFormatFrom(const_cast<std::uint8_t*>(rgba), width_, height_, 32,
                                                          width_ * 4, SDL_PIXELFORMAT_RGBA32);
  SDL_Surface* target = SDL_GetWindowSurface(impl_->window);
  if (frame && target) {
    SDL_SetSurfaceBlendMode(frame, SDL_BLENDMODE_NONE);  // copy, do not blend on alpha
    SDL_BlitSurface(frame, nullptr, target, nullptr);
    SDL_UpdateWindowSurface(impl_->window);
  }
  if (frame) SDL_FreeSurface(frame);
  return true;
}

}  // namespace rms::esg
