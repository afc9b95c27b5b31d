#include "keyboard.h"

#include <algorithm>
#include <termios.h>
#include <unistd.h>
#include <fcntl.h>

#include "rms/check.h"

namespace rms::op {

namespace {
void Step(OperatorInputs* in, const InputCalibrations& cal, int idx, double delta) {
  in->value[idx] = std::clamp(in->value[idx] + delta, cal[idx].min, cal[idx].max);
}
}  // namespace

bool ApplyKey(int key, const InputCalibrations& cal, OperatorInputs* in, bool* quit) {
  constexpr double kJointDeg = 2.0, kPanDeg = 3.0, kHeightFt = 0.25, kLever = 0.05;
  switch (key) {
    case 'q': Step(in, cal, kShoulderYaw, +kJointDeg); return true;
    case 'a': Step(in, cal, kShoulderYaw, -kJointDeg); return true;
    case 'w': Step(in, cal, kShoulderPitch, +kJointDeg); return true;
    case 's': Step(in, cal, kShoulderPitch, -kJointDeg); return true;
    case 'e': Step(in, cal, kElbowPitch, +kJointDeg); return true;
    case 'd': Step(in, cal, kElbowPitch, -kJointDeg); return true;
    case 'r': Step(in, cal, kWristPitch, +kJointDeg); return true;
    case 'f': Step(in, cal, kWristPitch, -kJointDeg); return true;
    case 't': Step(in, cal, kWristYaw, +kJointDeg); return true;
    case 'g': Step(in, cal, kWristYaw, -kJointDeg); return true;
    case 'y': Step(in, cal, kWristRoll, +kJointDeg); return true;
    case 'h': Step(in, cal, kWristRoll, -kJointDeg); return true;
    case 'u': Step(in, cal, kFinger, +kLever); return true;   // close
    case 'j': Step(in, cal, kFinger, -kLever); return true;   // open
    case 'i': Step(in, cal, kShoulderHeight, +kHeightFt); return true;
    case 'k': Step(in, cal, kShoulderHeight, -kHeightFt); return true;
    case kKeyLeft: Step(in, cal, kCameraPan, -kPanDeg); return true;
    case kKeyRight: Step(in, cal, kCameraPan, +kPanDeg); return true;
    case kKeyUp: Step(in, cal, kCameraTilt, +kPanDeg); return true;
    case kKeyDown: Step(in, cal, kCameraTilt, -kPanDeg); return true;
    case '+': case '=': Step(in, cal, kCameraZoom, +kLever); return true;
    case '-': case '_': Step(in, cal, kCameraZoom, -kLever); return true;
    case 'o': in->overlay = !in->overlay; return true;
    case ' ': in->reset = true; return true;
    case 'x': *quit = true; return true;
    default:
      if (key >= '1' && key <= '8') {
        in->camera_station = key - '0';
        return true;
      }
      return false;
  }
}

std::string KeyboardHelp() {
  return "keys: q/a shoulder yaw  w/s shoulder pitch  e/d elbow pitch  r/f wrist pitch  "
         "t/g wrist yaw  y/h wrist roll  u/j finger close/open  i/k shoulder height  "
         "1-8 camera  arrows pan/tilt  +/- zoom  o overlay  space reset  x quit";
}

struct TerminalKeys::Saved {
  termios tio;
  int flags;
};

TerminalKeys::TerminalKeys() : saved_(new Saved) {
  if (!isatty(STDIN_FILENO)) {
    delete saved_;
    throw InputError("--keyboard needs a terminal on standard input");
  }
  tcgetattr(STDIN_FILENO, &saved_->tio);
  saved_->flags = fcntl(STDIN_FILENO, F_GETFL);
  termios raw = saved_->tio;
  raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);  // keep ISIG: Ctrl-C still stops
  raw.c_cc[VMIN] = 0;
  raw.c_cc[VTIME] = 0;
  tcsetattr(STDIN_FILENO, TCSANOW, &raw);
  fcntl(STDIN_FILENO, F_SETFL, saved_->flags | O_NONBLOCK);
}

TerminalKeys::~TerminalKeys() {
  tcsetattr(STDIN_FILENO, TCSANOW, &saved_->tio);
  fcntl(STDIN_FILENO, F_SETFL, saved_->flags);
  delete saved_;
}

int TerminalKeys::ReadByte() {
  unsigned char c = 0;
  return read(STDIN_FILENO, &c, 1) == 1 ? c : -1;
}

int TerminalKeys::Next() {
  const int c = ReadByte();
  if (c != 27) return c;
  const int b = ReadByte();
  if (b != '[') return 27;
  switch (ReadByte()) {
    case 'A': return kKeyUp;
    case 'B': return kKeyDown;
    case 'C': return kKeyRight;
    case 'D': return kKeyLeft;
    default: return -1;
  }
}

}  // namespace rms::op
