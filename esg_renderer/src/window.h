#pragma once
// The operator's live view: each frame shown in a desktop window (SDL2, no
// GL in SDL: the frame is blitted). Closing the window stops showing it; the
// renderer carries on.
#include <cstdint>
#include <memory>
#include <string>

namespace rms::esg {

class LiveWindow {
 public:
  // Throws std::runtime_error when there is no display (DISPLAY unset) or
  // SDL cannot open a window.
  LiveWindow(int width, int height, const std::string& title);
  ~LiveWindow();
  // Shows an RGBA frame (rows top down); returns false once the window was closed.
  bool Show(const std::uint8_t* rgba);
  bool open() const { return open_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int width_, height_;
  bool open_ = false;
};

}  // namespace rms::esg
