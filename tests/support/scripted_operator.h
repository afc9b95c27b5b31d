#pragma once
// The scripted operator (rms/sim/scripted_operator.h) at a real terminal:
// tmux, where `scripts/lab demo --by-hand` (or operator_station
// --keyboard) runs; it waits in real time.
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "rms/sim/scripted_operator.h"

#include "tmux.h"

namespace rms::testing {

using sim::FlightReport;
using sim::ParseScreen;
using sim::Screen;

class TmuxTerminal : public sim::OperatorTerminal {
 public:
  explicit TmuxTerminal(Tmux* tmux) : tmux_(tmux) {}
  std::string Capture() override { return tmux_->Capture(); }
  void Send(const std::vector<std::string>& keys) override { tmux_->Send(keys); }
  void Wait(double s) override {
    if (s > 0) std::this_thread::sleep_for(std::chrono::duration<double>(s));
  }

 private:
  Tmux* tmux_;
};

class ScriptedOperator {
 public:
  explicit ScriptedOperator(Tmux* tmux, double reaction_s = 0.3)
      : terminal_(tmux), op_(&terminal_, sim::ScriptedOperatorOptions{reaction_s}) {}
  // sim::ScriptedOperator::Fly.
  FlightReport Fly(bool acquire_only, double limit_s) { return op_.Fly(acquire_only, limit_s); }

 private:
  TmuxTerminal terminal_;
  sim::ScriptedOperator op_;
};

}  // namespace rms::testing
