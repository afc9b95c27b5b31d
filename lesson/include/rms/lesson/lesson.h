#pragma once
// A lesson: scripted events of a session (docs/lessons.md) -- malfunctions,
// camera losses, input delays, repairs and freezes -- each fired once, at a
// session time, on entering a mode, or when a condition on the DCP's
// telemetry first holds. operator_station (--lesson FILE) fires them: each
// is sent on RMS_CONTROL as the session's own command, so the DCP honours
// it, the log records it and a re-simulation takes it word for word.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rms/dcp_telemetry_t.hpp"

namespace rms::lesson {

// A quantity of the DCP's telemetry a condition may test (docs/lessons.md
// "Conditions"): its name, and the mode in which it means something.
enum class LessonQuantity { kDockDistanceFt, kDockAngleDeg, kCollisions };
enum class LessonComparison { kLess, kLessOrEqual, kGreater, kGreaterOrEqual };

struct LessonEvent {
  // The trigger: exactly one of at_s, on_mode, when.
  std::optional<double> at_s;  // session time
  int on_mode = 0;             // 1..3: the first frame the DCP is in that mode (after the start)
  struct Condition {
    LessonQuantity quantity;
    LessonComparison comparison;
    double value;
  };
  std::optional<Condition> when;
  std::string when_text;  // as written, for the log
  // The action: a session control command and its name (the malfunction's
  // or repair's canonical text; empty for a freeze).
  std::int8_t command = 0;  // session_control_t::MALFUNCTION, REPAIR or FREEZE
  std::string name;
  double for_s = 0;  // a freeze: run again after this many seconds (wall time; 0: stays frozen)
  std::string text;  // "at 20 s: malfunction joint 2 stuck", for the log
};

class Lesson {
 public:
  // Throws rms::InputError naming the file and the key.
  static Lesson Load(const std::string& path);
  static Lesson Parse(std::string_view toml_text, const std::string& source);
  const std::vector<LessonEvent>& events() const { return events_; }
  // The events due at session time t_s with this telemetry (null: none yet),
  // each once: their indices, marked fired.
  std::vector<std::size_t> Due(double t_s, const dcp_telemetry_t* telemetry);
  std::size_t fired() const;
  bool was_fired(std::size_t i) const { return fired_[i]; }
  // Event i counted as fired (a station restarted that had fired it): it
  // is never due again.
  void MarkFired(std::size_t i) { fired_.at(i) = true; }

 private:
  std::vector<LessonEvent> events_;
  std::vector<bool> fired_;
  int last_mode_ = 0;
};

}  // namespace rms::lesson
