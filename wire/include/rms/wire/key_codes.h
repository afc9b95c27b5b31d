#pragma once
// Key codes: how a key is named in config/bindings.toml and numbered on the
// wire (RMS_WINDOW_KEYS) -- printable characters as themselves, the special
// keys from 256. The live window (esg_renderer) and a terminal (the operator
// station) both decode their keys into these. docs/operator.md "Key codes".
#include <string>
#include <string_view>

namespace rms::wire {

enum SpecialKey : int {
  kKeyUp = 256,
  kKeyDown,
  kKeyLeft,
  kKeyRight,
  kKeyPageUp,
  kKeyPageDown,
  kKeyBackspace,
  kKeyTab,
  kKeyEnter
};
inline constexpr int kMaxKeyCode = kKeyEnter;

// "q", "Q", "1", "[", "space", "up", "down", "left", "right", "pageup",
// "pagedown", "backspace", "tab", "enter", "plus", "minus": the key code,
// or -1 for a name that is no key.
int KeyCode(std::string_view name);
// The inverse: "w", "space", "pageup", ...
std::string KeyName(int code);

}  // namespace rms::wire
