#include "rms/instructor_station/instructor_lesson.h"

#include <algorithm>
#include <filesystem>
#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/base/folder_file.h"
#include "rms/base/text.h"
#include "rms/session_control_t.hpp"

namespace rms::instructor_station {

InstructorLesson::InstructorLesson(std::string state_path) : state_path_(std::move(state_path)) {}

bool InstructorLesson::Restore() {
  if (state_path_.empty() || !std::filesystem::exists(state_path_)) return false;
  const std::string what = "the instructor's lesson state " + state_path_;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(ReadRegularFile(state_path_, what, 64 << 20, Links::kRefuse));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(what + ": not JSON (" + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("text") || !j["text"].is_string() ||
      !j.value("fired_at_s", nlohmann::json()).is_array())
    throw InputError(what + ": not a lesson state");
  lesson::Lesson l = lesson::Lesson::Parse(j["text"].get<std::string>(), j.value("source", ""));
  std::vector<double> fired_at(l.events().size(), -1.0);
  const auto& fired = j["fired_at_s"];
  for (std::size_t i = 0; i < fired.size() && i < fired_at.size(); ++i) {
    if (!fired[i].is_number()) continue;
    fired_at[i] = fired[i].get<double>();
    l.MarkFired(i);
  }
  std::vector<std::int64_t> ids(fired_at.size(), -1);
  const nlohmann::json saved_ids = j.value("command_ids", nlohmann::json::array());
  for (std::size_t i = 0; saved_ids.is_array() && i < saved_ids.size() && i < ids.size(); ++i) {
    if (saved_ids[i].is_number_integer()) ids[i] = saved_ids[i].get<std::int64_t>();
  }
  std::lock_guard<std::mutex> lock(mu_);
  fired_at_s_ = std::move(fired_at);
  command_id_ = std::move(ids);
  text_ = j["text"].get<std::string>();
  source_ = j.value("source", "");
  loaded_ = j.value("loaded", nlohmann::json::array());
  lesson_ = std::move(l);
  return true;
}

void InstructorLesson::Load(std::string_view toml, const std::string& source, double session_s) {
  lesson::Lesson l = lesson::Lesson::Parse(toml, source);  // InputError: nothing changes
  std::lock_guard<std::mutex> lock(mu_);
  fired_at_s_.assign(l.events().size(), -1.0);
  command_id_.assign(l.events().size(), -1);
  lesson_ = std::move(l);
  source_ = source;
  text_ = std::string(toml);
  loaded_.push_back({{"session_s", session_s}, {"source", source}, {"text", text_}});
  Save();
}

void InstructorLesson::CancelTimedRuns() {
  std::lock_guard<std::mutex> lock(mu_);
  run_at_us_.clear();
}

void InstructorLesson::Save() {
  if (state_path_.empty() || !lesson_) return;
  nlohmann::json fired = nlohmann::json::array();
  for (const double t : fired_at_s_) fired.push_back(t >= 0 ? nlohmann::json(t) : nullptr);
  const nlohmann::json j = {{"source", source_},
                            {"text", text_},
                            {"fired_at_s", fired},
                            {"command_ids", command_id_},
                            {"loaded", loaded_}};
  try {
    WriteWholeFile(state_path_, j.dump(1) + "\n");
  } catch (
      const std::exception& e) {  // (a full disk: the lesson goes on; a restart would not know)
    spdlog::error("lesson: cannot keep its state in {}: {}", state_path_, e.what());
  }
}

std::vector<LessonCommand> InstructorLesson::Due(const dcp_telemetry_t* telemetry,
                                                 double frame_rate_hz, std::int64_t now_us) {
  std::vector<LessonCommand> out;
  std::lock_guard<std::mutex> lock(mu_);
  // A timed freeze's RUN (docs/lessons.md: for_s is wall time).
  const auto due_run = std::remove_if(run_at_us_.begin(), run_at_us_.end(),
                                      [&](std::int64_t at) { return at <= now_us; });
  for (auto it = due_run; it != run_at_us_.end(); ++it)
    out.push_back({session_control_t::RUN, "", "", -1});
  run_at_us_.erase(due_run, run_at_us_.end());
  if (!lesson_ || !telemetry) return out;
  // Session time as the operator station counts it: the frames published,
  // up to and with the one this telemetry answers.
  const double t_s = static_cast<double>(telemetry->input_frame + 1) / frame_rate_hz;
  bool fired = false;
  for (const std::size_t i : lesson_->Due(t_s, telemetry)) {
    const lesson::LessonEvent& e = lesson_->events()[i];
    fired_at_s_[i] = t_s;
    fired = true;
    out.push_back({e.command, e.name,
                   Sprintf("lesson %s: event %zu (%s), at %.3f s of session time", source_.c_str(),
                           i + 1, e.text.c_str(), t_s),
                   static_cast<int>(i)});
    if (e.command == session_control_t::FREEZE && e.for_s > 0)
      run_at_us_.push_back(now_us + static_cast<std::int64_t>(e.for_s * 1e6));
  }
  if (fired) Save();
  return out;
}

void InstructorLesson::NoteCommandId(int event, std::int64_t id) {
  std::lock_guard<std::mutex> lock(mu_);
  if (event < 0 || static_cast<std::size_t>(event) >= command_id_.size()) return;
  command_id_[static_cast<std::size_t>(event)] = id;
  Save();
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
                           {"fired_at_s", fired ? nlohmann::json(fired_at_s_[i]) : nullptr},
                           {"command_id", command_id_[i] >= 0 ? nlohmann::json(command_id_[i])
                                                              : nlohmann::json(nullptr)}});
  }
  return j;
}

}  // namespace rms::instructor_station
