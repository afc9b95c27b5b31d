// rms_control: commands to a running session on RMS_CONTROL
// (docs/sessions.md "Freeze, run, step, checkpoint"; docs/security.md "The
// control channel"):
//   rms_control --session DIR freeze | run | step [N] | checkpoint NAME | restore NAME|FILE [--run]
// Every command carries the session's id (from DIR/manifest.json, or
// --session-id): the session's processes take no other. A checkpoint is a
// name in the session's checkpoints folder, never a path; restore of a file
// from elsewhere copies it into that folder first. restore freezes the
// session first (so no frame is in flight), restores the DCP's state and the
// operator station's inputs, and leaves the session frozen unless --run.
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <chrono>
#include <map>
#include <functional>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "rms/channels.h"
#include "rms/check.h"
#include "rms/checkpoint.h"
#include "rms/lcm_interface.h"
#include "rms/message_io.h"
#include "rms/sender_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/session_control_t.hpp"
#include "session_summary.h"

namespace fs = std::filesystem;

namespace {

// "before_dock" -> "before_dock.json"; then checked as a name.
std::string CheckpointName(std::string name) {
  if (name.find('/') != std::string::npos) {
    throw rms::InputError("'" + name + "' is a path: give a checkpoint's name (it is saved in the session's "
                          "checkpoints folder)");
  }
  if (name.size() < 5 || name.compare(name.size() - 5, 5, ".json") != 0) name += ".json";
  rms::CheckpointFolder::ValidateName(name);
  return name;
}

// The name to restore: one in the session's folder, or a file from
// elsewhere copied in under a new name.
std::string RestoreName(const std::string& what, const std::string& folder) {
  if (what.find('/') == std::string::npos && !fs::exists(what)) return CheckpointName(what);
  if (!fs::is_regular_file(what)) throw rms::InputError("no checkpoint '" + what + "' (a name, or a file)");
  if (folder.empty()) {
    throw rms::InputError("restoring the file '" + what + "' needs --session DIR: it is copied into the session's "
                          "checkpoints folder first");
  }
  (void)rms::ReadCheckpoint(what);  // a real checkpoint, or a clear error now
  std::string stem = fs::path(what).stem().string();
  for (char& c : stem) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') c = '_';
  }
  stem = "restore-" + stem.substr(0, 40);
  std::string name = stem + ".json";
  for (int i = 2; fs::exists(fs::path(folder) / name); ++i) name = stem + "-" + std::to_string(i) + ".json";
  rms::CheckpointFolder::ValidateName(name);
  fs::copy_file(what, fs::path(folder) / name);
  std::printf("copied %s into the session as %s\n", what.c_str(), (fs::path(folder) / name).c_str());
  return name;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rmslab rms_control: freeze, run, step, checkpoint or restore a running session (RMS_CONTROL)"};
  rms::LcmOptions lcm_options;
  std::string session_dir, session_id;
  app.add_option("--session", session_dir,
                 "The session's folder: its LCM URL, channel suffix, id and checkpoints folder come from it")
      ->check(CLI::ExistingDirectory);
  app.add_option("--lcm-url", lcm_options.url, "LCM URL of the session (without --session)")->capture_default_str();
  app.add_option("--channel-suffix", lcm_options.channel_suffix, "The session's channel suffix (without --session)");
  app.add_option("--session-id", session_id, "The session's id, from its manifest.json (without --session)");
  app.require_subcommand(1);
  int steps = 1;
  std::string what;
  bool then_run = false;
  auto* freeze = app.add_subcommand("freeze", "Freeze the session: every process holds its frame");
  auto* run = app.add_subcommand("run", "Run a frozen session again");
  auto* step = app.add_subcommand("step", "While frozen: N more frames (default 1)");
  step->add_option("n", steps, "Frames")->check(CLI::Range(1, 100000));
  auto* checkpoint = app.add_subcommand("checkpoint", "dynamics_proc saves its state as NAME in the session's checkpoints folder");
  checkpoint->add_option("name", what, "Checkpoint name (letters, digits, _ - .; .json is added)")->required();
  auto* restore = app.add_subcommand(
      "restore", "Freeze, then restore the DCP's state (and the operator's inputs) from a checkpoint NAME, or a FILE");
  restore->add_option("checkpoint", what, "A checkpoint's name in the session, or a checkpoint file")->required();
  restore->add_flag("--run", then_run, "Run again after restoring");
  CLI11_PARSE(app, argc, argv);
  try {
    std::string folder;
    std::int64_t id = session_id.empty() ? 0 : rms::ParseSessionId(session_id, "--session-id");
    if (!session_dir.empty()) {
      const rms::session::SessionInfo s = rms::session::ReadSessionInfo(session_dir);
      if (s.lcm_url.empty()) throw rms::InputError(session_dir + " ran on no network (a re-simulation): nothing to control");
      lcm_options.url = s.lcm_url;
      lcm_options.channel_suffix = s.channel_suffix;
      id = s.session_id;
      folder = (fs::path(session_dir) / "checkpoints").string();
    }
    std::string name;
    if (checkpoint->parsed()) {
      name = CheckpointName(what);
      if (!folder.empty() && fs::exists(fs::path(folder) / name)) {
        std::fprintf(stderr, "rms_control: checkpoint %s exists already in %s: give another name\n", name.c_str(),
                     folder.c_str());
        return 1;
      }
    }
    if (restore->parsed()) name = RestoreName(what, folder);
    rms::UdpLcm lcm(lcm_options);
    lcm.SetSender({id, rms::sender_t::PROCESS_CONTROL, static_cast<std::int32_t>(getpid())});
    std::int64_t sequence = 0;
    auto send = [&](std::int8_t command, const std::string& n = "") {
      rms::session_control_t m;
      m.send_time_us = lcm.NowUs();
      m.sequence = sequence++;
      m.command = command;
      m.name = n;
      if (!rms::PublishMessage(lcm, rms::channels::kControl, m)) throw std::runtime_error("cannot publish");
    };
    auto pause = [] { std::this_thread::sleep_for(std::chrono::milliseconds(300)); };
    // The DCP's own counts, from its status reports (once a second): what a
    // restore did, confirmed rather than assumed.
    std::map<std::string, std::int64_t> dcp_counts;
    int dcp_reports = 0;
    lcm.Subscribe(rms::channels::kStatus, [&](const void* d, int n, std::int64_t) {
      rms::process_status_t st;
      if (rms::SafeDecode(d, n, 1 << 20, &st) != rms::DecodeError::kNone || st.process != "dynamics_proc") return;
      for (int i = 0; i < st.num_counters; ++i) dcp_counts[st.counter_names[i]] = st.counter_values[i];
      ++dcp_reports;
    });
    auto listen_until = [&](double seconds, const std::function<bool()>& done) {
      const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
      while (std::chrono::steady_clock::now() < end && !done()) lcm.HandleSubscriptions(50);
      return done();
    };
    auto count = [&](const char* k) { return dcp_counts.count(k) ? dcp_counts[k] : 0; };
    if (freeze->parsed()) send(rms::session_control_t::FREEZE);
    if (run->parsed()) send(rms::session_control_t::RUN);
    if (step->parsed()) {
      for (int i = 0; i < steps; ++i) send(rms::session_control_t::STEP);
    }
    std::int64_t cp_refused0 = 0;
    if (checkpoint->parsed()) {
      listen_until(1.5, [&] { return dcp_reports > 0; });
      cp_refused0 = count("control.refused") + count("control.rate_limited");
      send(rms::session_control_t::CHECKPOINT, name);
    }
    std::int64_t restores0 = 0, refused0 = 0, limited0 = 0;
    if (restore->parsed()) {
      listen_until(1.5, [&] { return dcp_reports > 0; });
      restores0 = count("control.restores");
      refused0 = count("control.refused");
      limited0 = count("control.rate_limited");
      send(rms::session_control_t::FREEZE);
      pause();  // the last frames through the pipeline
      send(rms::session_control_t::RESTORE, name);
      if (then_run) {
        pause();
        send(rms::session_control_t::RUN);
      }
    }
    std::printf("sent to %s%s, session %s\n", lcm_options.url.c_str(),
                lcm_options.channel_suffix.empty() ? "" : (" (suffix " + lcm_options.channel_suffix + ")").c_str(),
                id ? rms::FormatSessionId(id).c_str() : "none (only processes of no session take it)");
    if (checkpoint->parsed() && !folder.empty()) {
      // Confirm it: the DCP writes the file within a frame or two.
      const fs::path p = fs::path(folder) / name;
      const int seen = dcp_reports;
      listen_until(3.0, [&] {
        return fs::exists(p) ||
               (dcp_reports > seen && count("control.refused") + count("control.rate_limited") > cp_refused0);
      });
      if (!fs::exists(p) && count("control.refused") + count("control.rate_limited") > cp_refused0) {
        std::fprintf(stderr, "rms_control: dynamics_proc refused checkpoint %s (see the session's logs/dynamics_proc.log)\n",
                     name.c_str());
        return 1;
      }
      if (!fs::exists(p)) {
        std::fprintf(stderr, "rms_control: %s did not appear within 3 s (see the session's logs/dynamics_proc.log)\n",
                     p.c_str());
        return 1;
      }
      std::printf("saved %s\n", p.c_str());
    }
    if (restore->parsed() && dcp_reports > 0) {
      const int seen = dcp_reports;
      listen_until(3.0, [&] {
        return dcp_reports > seen && (count("control.restores") > restores0 || count("control.refused") > refused0 ||
                                      count("control.rate_limited") > limited0);
      });
      if (count("control.restores") > restores0) {
        std::printf("restored from %s (dynamics_proc confirms)%s\n", name.c_str(), then_run ? "" : "; frozen: run resumes");
        return 0;
      }
      std::fprintf(stderr, "rms_control: dynamics_proc did not restore %s (%s; see the session's logs/dynamics_proc.log)\n",
                   name.c_str(),
                   count("control.rate_limited") > limited0 ? "too many checkpoint commands a second: try again"
                   : count("control.refused") > refused0    ? "refused"
                                                            : "no word from it within 3 s");
      return 1;
    }
    if (restore->parsed()) std::printf("restore sent (not confirmed: no status report from dynamics_proc heard)\n");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_control: %s\n", e.what());
    return 2;
  }
}
