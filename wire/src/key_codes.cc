#include "rms/wire/key_codes.h"

namespace rms::wire {

namespace {
struct KeyNameCode {
  std::string_view name;
  int code;
};
constexpr KeyNameCode kKeyNames[] = {
    {"space", ' '},
    {"plus", '+'},
    {"minus", '-'},
    {"up", kKeyUp},
    {"down", kKeyDown},
    {"left", kKeyLeft},
    {"right", kKeyRight},
    {"pageup", kKeyPageUp},
    {"pagedown", kKeyPageDown},
    {"backspace", kKeyBackspace},
    {"tab", kKeyTab},
    {"enter", kKeyEnter},
};
}  // namespace

int KeyCode(std::string_view n) {
  for (const KeyNameCode& k : kKeyNames) {
    if (n == k.name) return k.code;
  }
  if (n.size() == 1 && n[0] > ' ' && n[0] < 127) return static_cast<unsigned char>(n[0]);
  return -1;
}

std::string KeyName(int code) {
  for (const KeyNameCode& k : kKeyNames) {
    if (code == k.code) return std::string(k.name);
  }
  if (code > ' ' && code < 127) return std::string(1, static_cast<char>(code));
  return "key" + std::to_string(code);
}

}  // namespace rms::wire
