#pragma once
// Raw, non-blocking key input from the terminal on stdin, escape sequences
// for the arrow keys decoded (bindings.h SpecialKey). What each key does is
// in config/bindings.toml [keyboard] (docs/operator.md).
namespace rms::operator_station {

class TerminalKeys {
 public:
  // Throws rms::InputError when stdin is not a terminal.
  TerminalKeys();
  // Restores the terminal.
  ~TerminalKeys();
  TerminalKeys(const TerminalKeys&) = delete;
  TerminalKeys& operator=(const TerminalKeys&) = delete;
  // Next key or -1 when none is pending.
  int Next();

 private:
  int ReadByte();
  struct Saved;
  Saved* saved_;
};

}  // namespace rms::operator_station
