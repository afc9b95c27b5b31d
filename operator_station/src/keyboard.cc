#include "rms/operator_station/keyboard.h"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include "rms/base/check.h"
#include "rms/operator_station/bindings.h"

namespace rms::operator_station {

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
  if (c == 127 || c == 8) return wire::kKeyBackspace;
  if (c == '\t') return wire::kKeyTab;
  if (c == '\r' || c == '\n') return wire::kKeyEnter;
  if (c != 27) return c;
  const int b = ReadByte();
  if (b != '[') return 27;
  switch (ReadByte()) {
    case 'A':
      return wire::kKeyUp;
    case 'B':
      return wire::kKeyDown;
    case 'C':
      return wire::kKeyRight;
    case 'D':
      return wire::kKeyLeft;
    case '5':
      return ReadByte() == '~' ? wire::kKeyPageUp : -1;
    case '6':
      return ReadByte() == '~' ? wire::kKeyPageDown : -1;
    default:
      return -1;
  }
}

}  // namespace rms::operator_station
