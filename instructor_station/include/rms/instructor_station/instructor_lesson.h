#pragma once
// The instructor's lesson (docs/lessons.md "From the instructor's
// station"): a lesson file -- the same format the operator station reads
// -- loaded at start (instructor_station --lesson FILE) or from the page
// (POST /api/lesson), its events fired as the session's telemetry reaches
// them, each sent on RMS_CONTROL as the instructor's command (so the DCP
// takes it, the log records it and a re-simulation takes it word for
// word). Loaded from the web server's threads, fired from the LCM thread:
// every method locks.
#include <cstdint>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rms/dcp_telemetry_t.hpp"
#include "rms/lesson/lesson.h"

namespace rms::instructor_station {

// A command the lesson sends (session_control_t's command and name).
struct LessonCommand {
  std::int8_t command = 0;
  std::string name;
  std::string said;  // for the events list and the log ("" for a timed RUN)
};

class InstructorLesson {
 public:
  // Replaces the lesson (what the old one had not fired is dropped; a
  // timed freeze's RUN still due is kept). `source`: where it came from,
  // for the page ("lesson.toml", "the page: my_lesson.toml").
  void Set(lesson::Lesson lesson, const std::string& source);
  // The commands due: each event whose trigger first holds at this
  // telemetry (session time: the operator frame it answers, over the frame
  // rate), and the RUN of a timed freeze whose wall time (now_us) came.
  std::vector<LessonCommand> Due(const dcp_telemetry_t* telemetry, double frame_rate_hz,
                                 std::int64_t now_us);
  // {"loaded", "source", "events": [{"text", "fired", "fired_at_s"}]}.
  nlohmann::json Json() const;

 private:
  mutable std::mutex mu_;
  std::optional<lesson::Lesson> lesson_;
  std::string source_;
  std::vector<double> fired_at_s_;       // -1: not yet
  std::vector<std::int64_t> run_at_us_;  // timed freezes' RUNs still due
};

}  // namespace rms::instructor_station
