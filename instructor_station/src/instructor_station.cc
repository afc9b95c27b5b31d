#include "rms/instructor_station/instructor_station.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/base/folder_file.h"
#include "rms/base/text.h"
#include "rms/instructor_station/instructor_lesson.h"
#include "rms/instructor_station/session_watch.h"
#include "rms/instructor_station/station_views.h"
#include "rms/instructor_station/web_server.h"
#include "rms/lesson/lesson.h"
#include "rms/session_control_t.hpp"
#include "rms/transport/process.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_io.h"

namespace rms::instructor_station {

namespace {

// 128 bits from the system's entropy, as hex: the session's web token.
std::string NewToken() {
  std::random_device rd;
  std::string t;
  for (int i = 0; i < 4; ++i) t += Sprintf("%08x", rd());
  return t;
}

// Mode 0600 from its creation, and whole or not there: written to a
// temporary file and renamed (a reader never sees it empty or half written).
void WriteUrlFile(const std::string& path, const std::string& url) {
  const std::string tmp = path + ".tmp";
  std::filesystem::remove(tmp);
  const int fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) throw InputError("cannot write " + tmp + ": " + std::strerror(errno));
  const std::string text = url + "\n";
  const bool ok = write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  close(fd);
  if (!ok) throw InputError("cannot write " + tmp + ": " + std::strerror(errno));
  std::filesystem::rename(tmp, path);
}

bool Loopback(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "::1";
}

// docs/lessons.md "From the instructor's station": what is due, queued
// for RMS_CONTROL with the page's own commands, said in the events list and
// the log.
void FireLesson(InstructorLesson* lesson, SessionWatch& watch, double frame_rate_hz,
                std::int64_t now_us, ControlQueue* controls, Counters* counters) {
  const std::optional<dcp_telemetry_t> t = watch.LatestTelemetry();
  for (const LessonCommand& c : lesson->Due(t ? &*t : nullptr, frame_rate_hz, now_us)) {
    const std::int64_t id = controls->Push({c.command, c.name});
    if (c.said.empty()) continue;  // a timed freeze's RUN
    lesson->NoteCommandId(c.event, id);
    spdlog::warn("{}", c.said);
    watch.NoteLocal("lesson", c.said);
    counters->Add(Counter::kLessonEvents);
  }
}

// The debrief's scrubbing: one past view asked for, drawn a wait, from the
// frames kept (the camera drive run up over the 3 s before it).
void DrawPastView(const SessionWatch& watch, StationViews& views) {
  const auto asked = views.PendingPast();
  if (!asked) return;
  const SessionWatch::PastFrames past = watch.HistoryAt(asked->second, 90);
  views.DrawPast(asked->first, asked->second, past.frames, past.lost_stations);
}

}  // namespace

void TakeTokenFromEnvironment(InstructorOptions* o) {
  if (!o->token.empty()) return;
  if (const char* t = std::getenv("RMSLAB_INSTRUCTOR_TOKEN"); t && *t) o->token = t;
}

void CheckOptions(const InstructorOptions& o) {
  if (o.port < 0 || o.port > 65535)
    throw InputError("--port " + std::to_string(o.port) + ": 0..65535");
  if (o.view_width < 16 || o.view_height < 16 || o.view_width > 4096 || o.view_height > 4096 ||
      o.view_width % 2 || o.view_height % 2) {
    throw InputError("--view-width/--view-height " + std::to_string(o.view_width) + "x" +
                     std::to_string(o.view_height) + ": even sizes, 16..4096");
  }
  if (!(o.view_rate_hz >= 0.5 && o.view_rate_hz <= 120))
    throw InputError("--view-rate: 0.5..120 views a second");
  if (!o.token.empty() && (o.token.size() < 16 || o.token.size() > 128))
    throw InputError("--token: 16..128 characters");
  for (char c : o.token) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_')
      throw InputError("--token: letters, digits, - and _ only");
  }
  if (!o.lesson_path.empty()) (void)lesson::Lesson::Load(o.lesson_path);  // refused at start
  if (o.debrief && o.session_dir.empty())
    throw InputError("--debrief: give the recorded session with --session-dir DIR");
  if (!Loopback(o.bind) && o.token.empty()) {
    // Refused rather than made up: whoever opens it beyond this host needs
    // to be given the token (docs/security.md "The instructor's page").
    throw InputError("--bind " + o.bind +
                     " serves beyond this host: give --token (or RMSLAB_INSTRUCTOR_TOKEN)");
  }
}

int RunInstructorStation(const LabConfig& config, transport::LcmInterface& lcm,
                         const InstructorOptions& given, const std::string& stats_path,
                         const std::string& ready_path) {
  InstructorOptions options = given;
  CheckOptions(options);
  if (options.token.empty()) options.token = NewToken();
  Counters counters;
  SessionWatch watch(config, &lcm, &counters, !options.debrief);
  if (!options.marks_path.empty()) watch.SetMarksFile(options.marks_path);
  // docs/instructor.md "A restarted station", "Debrief": the session's log
  // so far, through the same handlers as live traffic (which waits
  // meanwhile in the socket: what both hold counts once).
  if (!options.session_dir.empty()) {
    try {
      const std::int64_t n = watch.ReadLog(options.session_dir);
      spdlog::info("read {} messages of the session's log{}", n,
                   watch.restarted() ? ": a restart, its history recovered" : "");
    } catch (const InputError& e) {
      if (options.debrief) throw;
      spdlog::warn("the session's log not read ({}): the history begins now", e.what());
    }
  }
  StationViews views(config, options.view_width, options.view_height, options.view_rate_hz,
                     &counters);
  ControlQueue controls;
  controls.set_next_id(watch.NextCommandId());  // ids go on through restarts
  // docs/lessons.md "From the instructor's station": a station restarted
  // after a crash carries on with the lesson in force, fired events fired.
  InstructorLesson lesson(options.lesson_state_path);
  bool restored = false;
  try {
    restored = lesson.Restore();
  } catch (const InputError& e) {
    if (!options.debrief) throw;
    spdlog::warn("{}: the debrief shows no lesson", e.what());
  }
  if (restored) {
    spdlog::warn("lesson: {} {}",
                 options.debrief ? "as the session ran it, from" : "carried on from",
                 options.lesson_state_path);
  } else if (!options.lesson_path.empty()) {
    lesson.Load(ReadRegularFile(options.lesson_path, "lesson", kMaxConfigBytes, Links::kFollow),
                options.lesson_path, 0.0);
    spdlog::info("lesson {}: fired from this station", options.lesson_path);
  }
  WebServer server(config, options, &watch, &views, &controls, &lesson, &counters);
  const int port = server.Start();
  std::string host = options.bind == "0.0.0.0" || options.bind == "::" ? "localhost" : options.bind;
  if (host.find(':') != std::string::npos) host = "[" + host + "]";  // IPv6
  const std::string page = "http://" + host + ":" + std::to_string(port) + "/";
  // The token goes only to the URL file, readable by this user alone (not
  // to the log, nor the command line: the launcher passes it in the
  // environment).
  if (!options.url_file.empty()) WriteUrlFile(options.url_file, page + "?token=" + options.token);
  spdlog::info("instructor's page: {} (its token: {})", page,
               options.url_file.empty() ? "given with --token" : "in " + options.url_file);
  if (!ready_path.empty()) transport::WriteReadyFile(ready_path);
  transport::RunNodeLoop(
      lcm, "instructor_station", counters, {},
      [&] {
        const auto d = watch.LatestDcpFrame();
        return d ? d->frame : std::int64_t{-1};
      },
      [&] {
        if (auto d = watch.LatestDcpFrame()) views.Update(*d, watch.LostStations());
        DrawPastView(watch, views);
        if (!options.debrief)
          FireLesson(&lesson, watch, config.session.frame_rate_hz, lcm.NowUs(), &controls,
                     &counters);
        for (const ControlRequest& r : controls.Drain(transport::WallTimeUs())) {
          session_control_t m;
          m.send_time_us = lcm.NowUs();
          m.sequence = r.id;
          m.command = r.command;
          m.name = r.name;
          watch.NoteCommand(r.id, r.command, r.name);
          counters.Add(transport::PublishMessage(lcm, wire::channels::kControl, m)
                           ? Counter::kPublished
                           : Counter::kPublishFailed);
        }
        counters.Set(Counter::kHttpRequests, server.requests());
        counters.Set(Counter::kHttpRefused, server.refused());
        counters.Set(Counter::kControlSent, server.sent());
      },
      stats_path, 10);
  server.Stop();
  return 0;
}

}  // namespace rms::instructor_station
