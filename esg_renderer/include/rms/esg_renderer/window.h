#pragma once
// The operator's live view: each frame shown in a desktop window (SDL2, no
// GL in SDL: the frame is blitted), and the window's keyboard -- which keys
// are held, which went down -- for the operator station (RMS_WINDOW_KEYS:
// hold to move, release to stop; docs/operator.md "Devices"). Closing the
// window stops showing it; the renderer carries on.
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace rms::esg_renderer {

// What the keyboard did since the last Poll.
struct WindowKeys {
  std::vector<int> held;     // keys held now (rms/key_codes.h), each once
  std::vector<int> pressed;  // went down since the last poll, in order
  bool focused = true;       // the window has the keyboard
  bool changed = false;      // anything above changed
};

class LiveWindow {
 public:
  // Throws std::runtime_error when there is no display (DISPLAY unset) or
  // SDL cannot open a window.
  LiveWindow(int width, int height, const std::string& title);
  ~LiveWindow();
  // Shows an RGBA frame (rows top down); returns false once the window was closed.
  bool Show(const std::uint8_t* rgba);
  // Handles the window's events (closing, keys, focus) without drawing.
  WindowKeys Poll();
  bool open() const { return open_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int width_, height_;
  bool open_ = false;
  std::map<int, int> held_;  // SDL scancode -> key code, as pressed
  std::vector<int> pressed_;
  bool focused_ = true, changed_ = false;
};

// A key as the window saw it: SDL's keycode and modifiers to a key code
// (rms/key_codes.h), -1 for keys with none.
int KeyCodeFromSdl(int sdl_keycode, int sdl_modifiers);

}  // namespace rms::esg_renderer
