#pragma once
// A scripted operator that sees only what a person sees and does only what
// a person at a terminal can do (docs/operator.md "A scripted operator"): it
// reads the operator station's status screen, waits a reaction time after
// each look before it acts, and types the terminal's keys -- manual
// augmented control, coarse and vernier increments, stop, the frame key,
// the finger -- to acquire the payload, lift it out of the bay and dock it,
// counting every key it presses.
//
// It flies a terminal (OperatorTerminal): a real one, where
// `scripts/lab demo --by-hand` runs (the integration tests, through tmux),
// or the station without a network (OfflineStation, offline_station.h), as
// a virtual subject of a closed-loop sweep (docs/studies.md "Designs judged
// by flying them").
#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace rms::sim {

// The status screen, read as a person reads it (operator_station's
// status_screen.cc writes it).
struct Screen {
  bool valid = false;  // the station's screen is up
  double t_s = 0.0;    // session time
  int mode = 0;        // 1..3 (0: no telemetry shown)
  bool acquired = false, docked = false, held = false;
  std::string frame;     // "end effector", "orbiter", "payload"
  std::string scale;     // "COARSE", "VERNIER", "FINE"
  bool vernier = false;  // not coarse (vernier or fine: the same rates)
  // Per axis x, y, z, roll, pitch, yaw: the commanded rate (signed, ft/s
  // or deg/s) and what is still to go of the increment in flight.
  std::array<double, 6> rate{}, to_go{};
  bool guidance = false;
  // The guidance offsets, signed in each axis's "+" key direction: x
  // forward, y right, z down, roll right, pitch up, yaw right.
  std::array<double, 6> offset{};
  std::array<bool, 6> condition{};
  std::array<double, 6> margin{};  // > 0: holds by
  double close_gap = -1;           // Mode 1: where the closing finger would stop
  bool close_ok = false;           // ... below D3Y
  bool would_acquire = false;      // "CLOSING THE FINGER NOW ACQUIRES"
  double angle = 0;                // the guidance's whole turn, deg
  // What flies by itself: each axis nulled ("(to 0)"), the square-up, the unwind.
  std::array<bool, 6> nulling{};
  bool squaring = false, unwinding = false, stowing = false;
  bool near_limit = false;      // "WRIST NEAR ITS LIMIT"
  double turn_clearance = 1e9;  // Mode 3: above the sill line over the turn, ft
  bool clearance_warning = false;
  bool automatic() const {
    bool any = squaring || unwinding || stowing;
    for (bool n : nulling) any = any || n;
    return any;
  }
  double bay_clearance = -1e9;  // Mode 2/3: > 0 clear of the bay
  double dock_distance = 0, dock_angle = 0;
};
Screen ParseScreen(const std::string& text);

struct FlightReport {
  bool acquired = false, docked = false;
  double acquired_t_s = -1, docked_t_s = -1;        // session time
  int key_actions = 0;                              // keys pressed in all
  int key_actions_acquire = 0;                      // up to acquisition
  double dock_distance_ft = 0, dock_angle_deg = 0;  // as the screen showed them when docked
  std::string failure;                              // why it stopped short, if it did
  std::vector<std::string> transcript;              // what it saw and did, line by line
};

// What the scripted operator reads and types on.
class OperatorTerminal {
 public:
  virtual ~OperatorTerminal() = default;
  // The terminal's text: the station's status screen once it is up.
  virtual std::string Capture() = 0;
  // Types keys, by tmux's send-keys names: one character ("w", "Q"),
  // "Space", "Enter".
  virtual void Send(const std::vector<std::string>& keys) = 0;
  // Lets `s` seconds pass: the wall clock's at a live terminal, session
  // time at an offline station.
  virtual void Wait(double s) = 0;
  // A live window's keyboard (docs/operator.md "The live window's keys"):
  // Send puts keys down, and they stay held until Release.
  virtual bool HoldsKeys() const { return false; }
  virtual void Release(const std::vector<std::string>& keys) { (void)keys; }
};

// A person's dispersions (docs/studies.md "Designs judged by flying
// them"): the reaction time after each look; how long the subject holds a
// timed tap against the time it takes (tap_gain: 1 exact, above 1 over);
// and, with a seed other than 0, each reaction drawn from a normal law of
// `reaction_sd_s` about reaction_s (at least 0.05 s).
struct ScriptedOperatorOptions {
  double reaction_s = 0.3;
  double tap_gain = 1.0;
  double reaction_sd_s = 0.0;
  std::uint64_t seed = 0;
};

class ScriptedOperator {
 public:
  // The terminal shows operator_station --keyboard (or `scripts/lab demo
  // --by-hand`) with the default bindings.
  ScriptedOperator(OperatorTerminal* terminal, const ScriptedOperatorOptions& options);
  // Flies from the initial state: acquires, and unless acquire_only, lifts
  // the payload out of the bay and docks it. Gives up at `limit_s` of
  // session time.
  FlightReport Fly(bool acquire_only, double limit_s);
  // After a flight that docked: presses reset (a new attempt: Mode 1, the
  // payload back in the bay, the arm where it docked), opens the finger and
  // flies again from there; the report is the new attempt's, those two
  // presses counted.
  FlightReport FlyAgainAfterReset(double limit_s);
  // What it has seen and done so far (a flight cut short keeps it).
  const FlightReport& report() const { return report_; }

 private:
  struct Goal {
    int axis;      // 0..5: x, y, z, roll, pitch, yaw
    double error;  // how far to go, in the axis's "+" direction (ft or deg)
    double tol;    // close enough
  };
  Screen Look();
  double Reaction();
  // Presses `keys` a reaction time after the last look; with pulse_s > 0,
  // presses `then` that long after (a tap and its stop: one motion of the
  // hand, not a second reaction).
  // At a window (OperatorTerminal::HoldsKeys) a motion key is held for
  // pulse_s, or until let go (hold: Drive lets go of it), or as long as a
  // terminal's increment would fly; `then` is not needed there.
  void Press(const std::vector<std::string>& keys, const std::string& why, double pulse_s = 0,
             const std::vector<std::string>& then = {}, bool hold = false);
  // Moves each goal's axis toward its target this cycle (presses what it
  // takes); true when every goal is within its tolerance and still.
  bool Drive(const Screen& s, const std::vector<Goal>& goals, const std::string& why);
  void Note(const std::string& line);
  bool Acquire(double limit_s);
  bool Extract(double limit_s);
  bool Dock(double limit_s);
  bool WaitForFrame(const std::string& frame, double limit_s);
  // Presses `keys` (null keys, the square-up) and watches until nothing
  // flies by itself; unwinds and squares up again if the wrist nears its
  // limit on the way, and stows the arm if it comes back there after an
  // unwind. False when the limit comes first.
  bool FlyAutomatic(const std::vector<std::string>& keys, const std::string& why, double limit_s);
  // Presses the scale key until the screen shows `scale`.
  bool SetScale(const std::string& scale, double limit_s);
  int unwinds_ = 0;
  bool stowed_ = false;
  // A window's keys: the motion keys held now.
  std::vector<std::string> held_;
  void ReleaseHeld(const std::vector<std::string>& keys);

  OperatorTerminal* terminal_;
  ScriptedOperatorOptions options_;
  std::mt19937_64 rng_;
  Screen last_;
  FlightReport report_;
};

}  // namespace rms::sim
