#pragma once
// Flying the arm from the keyboard of a terminal (docs/operator.md has the
// key map). Each key press steps one input; the terminal's auto-repeat makes
// a held key a steady rate. Values are clamped to each channel's range.
#include <string>

#include "rms/input_block.h"

namespace rms::op {

// Keys (after escape-sequence decoding) that are not plain characters.
enum SpecialKey : int { kKeyUp = 256, kKeyDown, kKeyLeft, kKeyRight };

// What one key does. Returns false for keys without a binding. Sets *quit for
// 'x' (Ctrl-C stops the station through SIGINT as usual).
bool ApplyKey(int key, const InputCalibrations& cal, OperatorInputs* in, bool* quit);

std::string KeyboardHelp();

// Raw, non-blocking terminal input on stdin; restores the terminal on
// destruction. Throws rms::InputError when stdin is not a terminal.
class TerminalKeys {
 public:
  TerminalKeys();
  ~TerminalKeys();
  TerminalKeys(const TerminalKeys&) = delete;
  TerminalKeys& operator=(const TerminalKeys&) = delete;
  // Next key or -1 when none is pending.
  int Next();

 private:
  int ReadByte();
  bool restored_ = false;
  struct Saved;
  Saved* saved_;
};

}  // namespace rms::op
