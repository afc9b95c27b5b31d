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
#include <string_view>
#include <vector>

#include "rms/dcp_telemetry_t.hpp"
#include "rms/lesson/lesson.h"

namespace rms::instructor_station {

// A command the lesson sends (session_control_t's command and name).
struct LessonCommand {
  std::int8_t command = 0;
  std::string name;
  std::string said;  // for the events list and the log ("" for a timed RUN)
  int event = -1;    // the lesson's event it fires (-1: a timed freeze's RUN)
};

class InstructorLesson {
 public:
  // The state file (--lesson-state; the launcher's
  // run/instructor_lesson.json): the lesson in force -- its text, source
  // and which events fired -- and every lesson loaded, written whole after
  // each change, so a station restarted after a crash carries on with the
  // same lesson and fires none of its events again. "" : none kept.
  explicit InstructorLesson(std::string state_path = "");
  // Restores the state file's lesson, if there is one: true when it did.
  // Throws rms::InputError when it cannot be read as one.
  bool Restore();
  // Replaces the lesson with the one `toml` holds (what the old one had not
  // fired is dropped; a timed freeze's RUN still due is kept). `source`:
  // where it came from, for the page. Throws rms::InputError naming the
  // source and the key; the lesson in force is then unchanged.
  void Load(std::string_view toml, const std::string& source, double session_s);
  // A freeze or a run the instructor sent by hand: the timed freeze's RUN
  // still due is dropped (the session is the instructor's to run again).
  void CancelTimedRuns();
  // The commands due: each event whose trigger first holds at this
  // telemetry (session time: the operator frame it answers, over the frame
  // rate), and the RUN of a timed freeze whose wall time (now_us) came.
  std::vector<LessonCommand> Due(const dcp_telemetry_t* telemetry, double frame_rate_hz,
                                 std::int64_t now_us);
  // The page's id of the command event `event` fired (ControlQueue), so
  // the page shows what became of it (done or refused, never "sent").
  void NoteCommandId(int event, std::int64_t id);
  // {"loaded", "source", "events": [{"text", "fired", "fired_at_s",
  // "command_id" (null before it fired)}]}.
  nlohmann::json Json() const;

 private:
  void Save();  // mu_ held

  mutable std::mutex mu_;
  std::string state_path_;
  std::optional<lesson::Lesson> lesson_;
  std::string source_, text_;
  nlohmann::json loaded_ = nlohmann::json::array();  // every lesson loaded: when, source, text
  std::vector<double> fired_at_s_;                   // -1: not yet
  std::vector<std::int64_t> command_id_;             // -1: none (yet)
  std::vector<std::int64_t> run_at_us_;              // timed freezes' RUNs still due
};

}  // namespace rms::instructor_station
