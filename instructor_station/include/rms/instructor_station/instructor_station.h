#pragma once
// instructor_station: the instructor's station in a browser
// (docs/instructor.md): joins the session over LCM, serves a web page with
// live views of any camera station, the session's status and events, and
// its controls (freeze, run, step, reset, checkpoint, restore, sent as
// RMS_CONTROL commands so the log records them), and a lesson's scripted
// events (instructor_lesson.h).
#include <string>

#include "rms/base/config.h"
#include "rms/transport/lcm_interface.h"

namespace rms::instructor_station {

struct InstructorOptions {
  std::string bind = "127.0.0.1";  // --bind ADDRESS: where the page is served
  int port = 8080;                 // --port N (0: any free port)
  std::string token;     // --token T (or RMSLAB_INSTRUCTOR_TOKEN; default random): every request
  std::string url_file;  // --url-file FILE: the page's URL written there once serving
  std::string checkpoint_dir;     // --checkpoint-dir DIR: the session's checkpoints (listed)
  int view_width = 512;           // --view-width: the views' size, pixels
  int view_height = 384;          // --view-height
  double view_rate_hz = 15.0;     // --view-rate: each view drawn at most this often
  std::string lesson_path;        // --lesson FILE: a lesson fired from the start (docs/lessons.md)
  std::string lesson_state_path;  // --lesson-state FILE: kept there; a restart carries on from it
  std::string session_dir;  // --session-dir DIR: its log read at start (a restart recovers its
                            // history; a debrief shows the whole session)
  std::string marks_path;   // --marks-file FILE: the instructor's marks (JSON lines), kept there
  bool debrief = false;     // --debrief: a recorded session, nothing live (needs --session-dir)
};

// --token's default: RMSLAB_INSTRUCTOR_TOKEN (how the launcher passes it,
// so it is not on the command line for every user of the host to read).
void TakeTokenFromEnvironment(InstructorOptions* options);
// Checks the options (throws InputError naming the option and the reason).
void CheckOptions(const InstructorOptions& options);

int RunInstructorStation(const LabConfig& config, transport::LcmInterface& lcm,
                         const InstructorOptions& options, const std::string& stats_path,
                         const std::string& ready_path);

}  // namespace rms::instructor_station
