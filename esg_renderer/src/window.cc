#include "rms/esg_renderer/window.h"

#include <SDL2/SDL.h>
#include <stdexcept>

#include "rms/wire/key_codes.h"

namespace rms::esg_renderer {

struct LiveWindow::Impl {
  SDL_Window* window = nullptr;
};

int KeyCodeFromSdl(int sym, int mod) {
  switch (sym) {
    case SDLK_UP:
      return wire::kKeyUp;
    case SDLK_DOWN:
      return wire::kKeyDown;
    case SDLK_LEFT:
      return wire::kKeyLeft;
    case SDLK_RIGHT:
      return wire::kKeyRight;
    case SDLK_PAGEUP:
      return wire::kKeyPageUp;
    case SDLK_PAGEDOWN:
      return wire::kKeyPageDown;
    case SDLK_BACKSPACE:
      return wire::kKeyBackspace;
    case SDLK_TAB:
      return wire::kKeyTab;
    case SDLK_RETURN:
    case SDLK_KP_ENTER:
      return wire::kKeyEnter;
    case SDLK_KP_PLUS:
      return '+';
    case SDLK_KP_MINUS:
      return '-';
    default:
      break;
  }
  if (sym >= 'a' && sym <= 'z') return (mod & KMOD_SHIFT) ? sym - 'a' + 'A' : sym;
  if (sym == '=' && (mod & KMOD_SHIFT))
    return '+';  // the US layout's shifted keys that bindings name
  if (sym == '-' && (mod & KMOD_SHIFT)) return '_';
  if (sym >= ' ' && sym < 127) return sym;
  return -1;
}

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
  impl_->window = SDL_CreateWindow(title.c_str(), SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED,
                                   width, height, 0);
  if (!impl_->window) throw std::runtime_error(std::string("SDL_CreateWindow: ") + SDL_GetError());
  open_ = true;
}

LiveWindow::~LiveWindow() {
  if (impl_->window) SDL_DestroyWindow(impl_->window);
  SDL_QuitSubSystem(SDL_INIT_VIDEO);
}

WindowKeys LiveWindow::Poll() {
  SDL_Event e;
  while (open_ && SDL_PollEvent(&e)) {
    if (e.type == SDL_QUIT ||
        (e.type == SDL_WINDOWEVENT && e.window.event == SDL_WINDOWEVENT_CLOSE)) {
      open_ = false;
      SDL_DestroyWindow(impl_->window);
      impl_->window = nullptr;
      held_.clear();
      changed_ = true;
    } else if (e.type == SDL_WINDOWEVENT && e.window.event == SDL_WINDOWEVENT_FOCUS_LOST) {
      // No key-up will come for keys held when the focus went: let go.
      focused_ = false;
      held_.clear();
      changed_ = true;
    } else if (e.type == SDL_WINDOWEVENT && e.window.event == SDL_WINDOWEVENT_FOCUS_GAINED) {
      focused_ = true;
      changed_ = true;
    } else if (e.type == SDL_KEYDOWN && !e.key.repeat) {
      const int code = KeyCodeFromSdl(e.key.keysym.sym, e.key.keysym.mod);
      if (code < 0) continue;
      held_[e.key.keysym.scancode] = code;  // released by scancode: shift may change first
      pressed_.push_back(code);
      focused_ = true;
      changed_ = true;
    } else if (e.type == SDL_KEYUP) {
      if (held_.erase(e.key.keysym.scancode)) changed_ = true;
    }
  }
  WindowKeys k;
  std::set<int> held;
  for (const auto& [scancode, code] : held_) held.insert(code);
  k.held.assign(held.begin(), held.end());
  k.pressed.swap(pressed_);
  k.focused = focused_;
  k.changed = changed_;
  changed_ = false;
  return k;
}

bool LiveWindow::Show(const std::uint8_t* rgba) {
  if (!open_) return false;
  SDL_Surface* frame = SDL_CreateRGBSurfaceWithFormatFrom(
      const_cast<std::uint8_t*>(rgba), width_, height_, 32, width_ * 4, SDL_PIXELFORMAT_RGBA32);
  SDL_Surface* target = SDL_GetWindowSurface(impl_->window);
  if (frame && target) {
    SDL_SetSurfaceBlendMode(frame, SDL_BLENDMODE_NONE);  // copy, do not blend on alpha
    SDL_BlitSurface(frame, nullptr, target, nullptr);
    SDL_UpdateWindowSurface(impl_->window);
  }
  if (frame) SDL_FreeSurface(frame);
  return true;
}

}  // namespace rms::esg_renderer
