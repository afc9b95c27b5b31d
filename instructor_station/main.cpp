// instructor_station: the instructor's station in a browser. Joins the
// session over LCM and serves a page of live views, status, events and
// controls. A thin main over instructor_station/src; see docs/instructor.md.
#include <CLI/CLI.hpp>

#include "rms/instructor_station/instructor_station.h"
#include "rms/transport/process.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab instructor_station: a web page to watch any camera station live, see the "
      "session's status and events, freeze, run, step, checkpoint, restore or reset it, and "
      "inject and repair malfunctions (docs/instructor.md)."};
  rms::transport::CommonOptions common;
  rms::instructor_station::InstructorOptions o;
  app.add_option("--bind", o.bind, "Address to serve the page on (beyond loopback: --token)")
      ->capture_default_str();
  app.add_option("--port", o.port, "Port (0: any free one)")->capture_default_str();
  app.add_option("--token", o.token,
                 "The page's token (16..128 of [A-Za-z0-9_-]; default: RMSLAB_INSTRUCTOR_TOKEN, "
                 "else a random one, in the URL file)");
  app.add_option("--url-file", o.url_file, "Write the page's URL (with its token) to this file");
  app.add_option("--checkpoint-dir", o.checkpoint_dir, "The session's checkpoints folder");
  app.add_option("--view-width", o.view_width, "The views' width, pixels")->capture_default_str();
  app.add_option("--view-height", o.view_height, "The views' height, pixels")
      ->capture_default_str();
  app.add_option("--view-rate", o.view_rate_hz, "Each view drawn at most this often, Hz")
      ->capture_default_str();
  app.add_option("--lesson", o.lesson_path,
                 "A lesson (docs/lessons.md) whose events this station fires as the session "
                 "reaches them (the page can load one too)");
  app.add_option("--lesson-state", o.lesson_state_path,
                 "Keep the lesson in force and what it fired here; a restarted station carries on "
                 "from it");
  app.add_option("--session-dir", o.session_dir,
                 "The session's folder: its log so far is read at start (a restarted station "
                 "recovers its history)");
  app.add_option("--marks-file", o.marks_path,
                 "The instructor's marks and notes, kept here (JSON lines; the launcher's "
                 "SESSION/instructor_marks.jsonl)");
  app.add_flag("--debrief", o.debrief,
               "A debrief of the recorded session in --session-dir: scrub through it, place marks; "
               "nothing is sent");
  return rms::transport::ProcessMain(
      app, argc, argv, "instructor_station", &common,
      [&](const rms::LabConfig& config, rms::transport::LcmInterface& lcm) {
        rms::instructor_station::TakeTokenFromEnvironment(&o);
        return rms::instructor_station::RunInstructorStation(config, lcm, o, common.stats_path,
                                                             common.ready_path);
      },
      [&](const rms::LabConfig&) {
        rms::instructor_station::TakeTokenFromEnvironment(&o);
        rms::instructor_station::CheckOptions(o);
      });
}
