// rms_monitor: live decoded traffic of a session, per channel, with rates
// (docs/sessions.md "Monitor"); lcm-spy does not run on Java 17.
//   rms_monitor [--lcm-url URL] [--channel-suffix S]        redraws twice a second
//   rms_monitor --for SECONDS                                one plain snapshot, then exit
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>

#include "rms/base/command_line.h"
#include "rms/monitor/monitor.h"
#include "rms/sender_t.hpp"
#include "rms/session/manifest.h"
#include "rms/transport/lcm_interface.h"
#include "rms/transport/process.h"

int main(int argc, char** argv) {
  CLI::App app{"rmslab rms_monitor: live decoded traffic of a session, per channel, with rates"};
  rms::transport::LcmOptions lcm_options;
  double for_s = 0.0;
  app.add_option("--lcm-url", lcm_options.url, "LCM URL of the session")->capture_default_str();
  app.add_option("--channel-suffix", lcm_options.channel_suffix, "The session's channel suffix");
  std::string session_dir;
  app.add_option("--session", session_dir,
                 "The session's folder: its URL, suffix, id and key come from it, and only its "
                 "own messages, their tags checked, are shown")
      ->check(CLI::ExistingDirectory);
  app.add_option("--for", for_s,
                 "Listen this many seconds, print one snapshot and exit (0: live, until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  rms::transport::InstallStopHandlers();
  try {
    std::optional<rms::session::SessionInfo> info;
    if (!session_dir.empty()) {
      info = rms::session::ReadSessionInfo(session_dir);
      lcm_options.url = info->lcm_url;
      lcm_options.channel_suffix = info->channel_suffix;
    }
    rms::transport::UdpLcm lcm(lcm_options);
    if (info) {
      lcm.SetSender(
          {info->session_id, rms::sender_t::PROCESS_TOOL, static_cast<std::int32_t>(getpid())});
      if (const auto key = rms::session::ReadSessionKey(session_dir)) lcm.SetKey(*key);
    }
    rms::monitor::Monitor monitor(&lcm, lcm_options);
    std::fputs(monitor.Run(for_s).c_str(), stdout);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_monitor: %s\n", e.what());
    return 2;
  }
}
