#include "rms/instructor_station/instructor_lesson.h"

#include <algorithm>

#include "rms/base/text.h"
#include "rms/session_control_t.hpp"

namespace rms::instructor_station {

void InstructorLesson::Set(lesson::Lesson lesson, const std::string& source) {
  std::lock_guard<std::mutex> lock(mu_);
  fired_at_s_.assign(lesson.events().size(), -1.0);
  lesson_ = std::move(lesson);
  source_ = source;
}

std::vector<LessonCommand> InstructorLesson::Due(const dcp_telemetry_t* telemetry,
                                                 double frame_rate_hz, std::int64_t now_us) {
  std::vector<LessonCommand> out;
  std::lock_guard<std::mutex> lock(mu_);
  // A timed freeze's RUN (docs/lessons.md: for_s is wall time).
  const auto due_run = std::remove_if(run_at_us_.begin(), run_at_us_.end(),
                                      [&](std::int64_t at) { return at <= now_us; });
  for (auto it = due_run; it != run_at_us_.end(); ++it)
    out.push_back({session_control_t::RUN, "", ""});
  run_at_us_.erase(due_run, run_at_us_.end());
  if (!lesson_ || !telemetry) return out;
  // Session time as the operator station counts it: the frames published,
  // up to and with the one this telemetry answers.
  const double t_s = static_cast<double>(telemetry->input_frame + 1) / frame_rate_hz;
  for (const std::size_t i : lesson_->Due(t_s, telemetry)) {
    const lesson::LessonEvent& e = lesson_->events()[i];
    fired_at_s_[i] = t_s;
    out.push_back(
        {e.command, e.name,
         Sprintf("lesson: event %zu (%s), at %.3f s of session time", i + 1, e.text.c_str(), t_s)});
    if (e.command == session_control_t::FREEZE && e.for_s > 0)
      run_at_us_.push_back(now_us + static_cast<std::int64_t>(e.for_s * 1e6));
  }
  return out;
}

nlohmann::json InstructorLesson::Json() const {
  std::lock_guard<std::mutex> lock(mu_);
  nlohmann::json j = {{"loaded", lesson_.has_value()}, {"source", source_}};
  j["events"] = nlohmann::json::array();
  if (!lesson_) return j;
  for (std::size_t i = 0; i < lesson_->events().size(); ++i) {
    const bool fired = fired_at_s_[i] >= 0;
    j["events"].push_back({{"text", lesson_->events()[i].text},
                           {"fired", fired},
                           {"fired_at_s", fired ? nlohmann::json(fired_at_s_[i]) : nullptr}});
  }
  return j;
}

}  // namespace rms::instructor_station
