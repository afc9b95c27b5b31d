// rms_control: commands to a running session on RMS_CONTROL
// (docs/sessions.md "Freeze, run, step, checkpoint"; docs/security.md "The
// control channel"):
//   rms_control --session DIR freeze | run | step [N] | reset | checkpoint NAME
//               | restore NAME|FILE [--run]
//               | malfunction WHAT... | repair WHAT...
// Every command carries the session's id (from DIR/manifest.json, or
// --session-id): the session's processes take no other. A checkpoint is a
// name in the session's checkpoints folder, never a path; restore of a file
// from elsewhere copies it into that folder first. restore freezes the
// session (so no frame is in flight), restores the DCP's state and the
// operator station's inputs, and leaves the session frozen unless --run.
// Each command is confirmed by the answer of the process that acts on it
// (RMS_CONTROL_ANSWER), or its refusal said with the reason.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <thread>

#include "rms/base/check.h"
#include "rms/base/command_line.h"
#include "rms/control_answer_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/sender_t.hpp"
#include "rms/session/manifest.h"
#include "rms/session_control_t.hpp"
#include "rms/transport/journal.h"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/malfunction.h"
#include "rms/wire/message_auth.h"
#include "rms/wire/message_io.h"

namespace fs = std::filesystem;

namespace {

// "before_dock" -> "before_dock.json"; then checked as a name.
std::string CheckpointName(std::string name) {
  if (name.find('/') != std::string::npos) {
    throw rms::InputError("'" + name +
                          "' is a path: give a checkpoint's name (it is saved in the session's "
                          "checkpoints folder)");
  }
  if (name.size() < 5 || name.compare(name.size() - 5, 5, ".json") != 0) name += ".json";
  rms::wire::CheckpointFolder::ValidateName(name);
  return name;
}

// The name to restore: one in the session's folder, or a file from
// elsewhere copied in under a new name.
std::string RestoreName(const std::string& what, const std::string& folder) {
  if (what.find('/') == std::string::npos && !fs::exists(what)) return CheckpointName(what);
  if (!fs::is_regular_file(what))
    throw rms::InputError("no checkpoint '" + what + "' (a name, or a file)");
  if (folder.empty()) {
    throw rms::InputError("restoring the file '" + what +
                          "' needs --session DIR: it is copied into the session's "
                          "checkpoints folder first");
  }
  (void)rms::wire::ReadCheckpoint(what);  // a real checkpoint, or a clear error now
  std::string stem = fs::path(what).stem().string();
  for (char& c : stem) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') c = '_';
  }
  stem = "restore-" + stem.substr(0, 40);
  std::string name = stem + ".json";
  for (int i = 2; fs::exists(fs::path(folder) / name); ++i)
    name = stem + "-" + std::to_string(i) + ".json";
  rms::wire::CheckpointFolder::ValidateName(name);
  fs::copy_file(what, fs::path(folder) / name);
  std::printf("copied %s into the session as %s\n", what.c_str(),
              (fs::path(folder) / name).c_str());
  return name;
}

}  // namespace

namespace {

// The session's control channel as this tool uses it: commands out, and
// the answers of the processes that act on them in (RMS_CONTROL_ANSWER,
// docs/protocol.md), so what a command did is confirmed, or its refusal
// said with the reason, rather than assumed. Status reports say whether
// anyone is there to answer.
class ControlLink {
 public:
  struct Heard {
    std::int8_t outcome = 0;  // control_answer_t::DONE or REFUSED
    std::string text;
  };

  ControlLink(const rms::transport::LcmOptions& options, std::int64_t session_id,
              const std::optional<rms::wire::SessionKey>& key)
      : lcm_(options), pid_(static_cast<std::int32_t>(getpid())) {
    lcm_.SetSender({session_id, rms::sender_t::PROCESS_CONTROL, pid_});
    if (key) lcm_.SetKey(*key);
    lcm_.Subscribe(rms::wire::channels::kStatus, [this](const void* d, int n, std::int64_t) {
      rms::process_status_t st;
      if (rms::wire::SafeDecode(d, n, &st) != rms::wire::DecodeError::kNone) return;
      ++reports_[st.process];
    });
    lcm_.Subscribe(rms::wire::channels::kControlAnswer, [this](const void* d, int n, std::int64_t) {
      rms::control_answer_t a;
      if (rms::wire::SafeDecode(d, n, &a) != rms::wire::DecodeError::kNone) return;
      if (a.command_process != rms::sender_t::PROCESS_CONTROL || a.command_pid != pid_) return;
      answers_[{a.command_sequence, rms::wire::ProcessCodeName(a.sender.process)}] = {a.outcome,
                                                                                      a.text};
    });
  }
  // Journals what it sends in the session's journal/ (rms/transport/journal.h);
  // one it cannot make is said, and the command still goes.
  void JournalIn(const std::string& dir) {
    try {
      lcm_.SetJournal(rms::transport::Journal::CreateIn(dir, "rms_control"));
    } catch (const rms::InputError& e) {
      std::fprintf(stderr,
                   "rms_control: no journal (%s): the command reaches the record only if "
                   "the session's recorder hears it\n",
                   e.what());
    }
  }
  // Sends a command; its sequence (with this tool's pid, its id).
  std::int64_t Send(std::int8_t command, const std::string& name = "") {
    rms::session_control_t m;
    m.send_time_us = lcm_.NowUs();
    m.sequence = sequence_++;
    m.command = command;
    m.name = name;
    if (!rms::transport::PublishMessage(lcm_, rms::wire::channels::kControl, m))
      throw std::runtime_error("cannot publish");
    return m.sequence;
  }
  // Handles messages until done() or `seconds` pass; done()'s last answer.
  bool ListenUntil(double seconds, const std::function<bool()>& done) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end && !done()) lcm_.HandleSubscriptions(50);
    return done();
  }
  // Waits (up to 2.5 s: they report once a second) for a first status
  // report of `process`; false if none came (nobody there to answer).
  bool WaitForProcess(const std::string& process) {
    return ListenUntil(2.5, [&] { return reports_.count(process) > 0; });
  }
  // `process`'s answer to command `sequence`, waiting up to `seconds`.
  std::optional<Heard> Answer(std::int64_t sequence, const std::string& process, double seconds) {
    ListenUntil(seconds, [&] { return answers_.count({sequence, process}) > 0; });
    const auto it = answers_.find({sequence, process});
    if (it == answers_.end()) return std::nullopt;
    return it->second;
  }

 private:
  rms::transport::UdpLcm lcm_;
  std::int32_t pid_;
  std::int64_t sequence_ = 0;
  std::map<std::string, int> reports_;
  std::map<std::pair<std::int64_t, std::string>, Heard> answers_;
};

void SayWhereSent(const rms::transport::LcmOptions& options, std::int64_t id);

// Nobody answered: said, and a failure (docs/sessions.md "Command lines").
int NobodyThere(const rms::transport::LcmOptions& options, std::int64_t id, const char* process) {
  std::fprintf(
      stderr,
      "rms_control: no %s of session %s is running on %s%s (no status report heard in 2.5 s): "
      "nothing "
      "was sent\n",
      process, id ? rms::wire::FormatSessionId(id).c_str() : "(none)", options.url.c_str(),
      options.channel_suffix.empty() ? "" : (" with suffix " + options.channel_suffix).c_str());
  return 1;
}

// A command's answer from `process`, said: 0 done, 1 refused or none
// within 3 s.
int Said(ControlLink& link, std::int64_t sequence, const char* process, const char* what) {
  const std::optional<ControlLink::Heard> h = link.Answer(sequence, process, 3.0);
  if (!h) {
    std::fprintf(stderr,
                 "rms_control: %s: no answer from %s within 3 s (see its log in the "
                 "session's logs/)\n",
                 what, process);
    return 1;
  }
  if (h->outcome != rms::control_answer_t::DONE) {
    std::fprintf(stderr, "rms_control: %s refused by %s: %s\n", what, process, h->text.c_str());
    return 1;
  }
  std::printf("%s: %s (%s)\n", what, h->text.c_str(), process);
  return 0;
}

// FREEZE, RUN, STEP, RESET: answered by the operator station (it is the
// session's clock, and presses the reset button).
int Clock(ControlLink& link, std::int8_t command, int steps,
          const rms::transport::LcmOptions& options, std::int64_t id) {
  if (!link.WaitForProcess("operator_station")) return NobodyThere(options, id, "operator station");
  // One command, a step's count in its name (docs/protocol.md "RMS_CONTROL").
  const std::int64_t q = link.Send(command, steps > 1 ? std::to_string(steps) : "");
  SayWhereSent(options, id);
  return Said(link, q, "operator_station", rms::wire::ControlCommandName(command));
}

void SayWhereSent(const rms::transport::LcmOptions& options, std::int64_t id) {
  std::printf(
      "sent to %s%s, session %s\n", options.url.c_str(),
      options.channel_suffix.empty() ? "" : (" (suffix " + options.channel_suffix + ")").c_str(),
      id ? rms::wire::FormatSessionId(id).c_str() : "none (only processes of no session take it)");
}

// CHECKPOINT: answered by the DCP.
int Checkpoint(ControlLink& link, const std::string& name, const std::string& folder,
               const rms::transport::LcmOptions& options, std::int64_t id) {
  if (!link.WaitForProcess("dynamics_proc")) return NobodyThere(options, id, "dynamics_proc");
  const std::int64_t q = link.Send(rms::session_control_t::CHECKPOINT, name);
  SayWhereSent(options, id);
  const int rc = Said(link, q, "dynamics_proc", "checkpoint");
  if (rc == 0 && !folder.empty()) std::printf("saved %s\n", (fs::path(folder) / name).c_str());
  return rc;
}

// RESTORE (which freezes the session), and RUN with --run: answered by the
// DCP (its state) and the operator station (its inputs, and the freeze).
int Restore(ControlLink& link, const std::string& name, bool then_run,
            const rms::transport::LcmOptions& options, std::int64_t id) {
  if (!link.WaitForProcess("dynamics_proc")) return NobodyThere(options, id, "dynamics_proc");
  // Frozen first, and the last frames through the pipeline, so the DCP
  // restores with no frame in flight (docs/sessions.md).
  if (Said(link, link.Send(rms::session_control_t::FREEZE), "operator_station", "freeze") != 0)
    return 1;
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const std::int64_t q = link.Send(rms::session_control_t::RESTORE, name);
  SayWhereSent(options, id);
  int rc = Said(link, q, "dynamics_proc", "restore");
  rc = std::max(rc, Said(link, q, "operator_station", "restore"));
  if (rc == 0 && then_run)
    rc = Said(link, link.Send(rms::session_control_t::RUN), "operator_station", "run");
  return rc;
}

// MALFUNCTION and REPAIR (docs/sessions.md "Malfunctions"): answered by the DCP.
int Malfunction(ControlLink& link, std::int8_t command, const std::string& text,
                const rms::transport::LcmOptions& options, std::int64_t id) {
  if (!link.WaitForProcess("dynamics_proc")) return NobodyThere(options, id, "dynamics_proc");
  const std::int64_t q = link.Send(command, text);
  SayWhereSent(options, id);
  return Said(link, q, "dynamics_proc", rms::wire::ControlCommandName(command));
}

// The words after the subcommand, as one text.
std::string Joined(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : " ") + w;
  return out;
}

// The session a command goes to: its id, checkpoints folder and key, from
// its folder or from the options (the LCM URL and suffix set in *lcm).
struct Target {
  std::int64_t id = 0;
  std::string checkpoints;  // empty without --session
  std::optional<rms::wire::SessionKey> key;
};
Target ResolveTarget(const std::string& session_dir, const std::string& session_id,
                     const std::string& key_file, rms::transport::LcmOptions* lcm) {
  Target t;
  t.id = session_id.empty() ? 0 : rms::transport::ParseSessionId(session_id, "--session-id");
  if (!session_dir.empty()) {
    const rms::session::SessionInfo s = rms::session::ReadSessionInfo(session_dir);
    if (s.lcm_url.empty())
      throw rms::InputError(session_dir +
                            " ran on no network (a re-simulation): nothing to control");
    lcm->url = s.lcm_url;
    lcm->channel_suffix = s.channel_suffix;
    t.id = s.session_id;
    t.checkpoints = (fs::path(session_dir) / "checkpoints").string();
  }
  // The session's messages carry tags: its processes drop a command
  // without the key's (docs/security.md "Authenticated messages").
  t.key = !session_dir.empty() ? rms::session::ReadSessionKey(session_dir)
          : !key_file.empty()  ? std::optional(rms::wire::ReadSessionKeyFile(key_file))
                               : rms::wire::SessionKeyFromEnv();
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_control: freeze, run, step, checkpoint, restore, inject a malfunction in or "
      "repair a running session (RMS_CONTROL)"};
  rms::transport::LcmOptions lcm_options;
  std::string session_dir, session_id;
  app.add_option("--session", session_dir,
                 "The session's folder: its LCM URL, channel suffix, id and checkpoints folder "
                 "come from it")
      ->check(CLI::ExistingDirectory);
  app.add_option("--lcm-url", lcm_options.url, "LCM URL of the session (without --session)")
      ->capture_default_str();
  app.add_option("--channel-suffix", lcm_options.channel_suffix,
                 "The session's channel suffix (without --session)");
  app.add_option("--session-id", session_id,
                 "The session's id, from its manifest.json (without --session)");
  std::string key_file;
  app.add_option("--key-file", key_file,
                 "The session's key file, SESSION/run/session.key (without --session; default: "
                 "RMSLAB_SESSION_KEY_FILE)");
  app.require_subcommand(1);
  int steps = 1;
  std::string what;
  bool then_run = false;
  auto* freeze = app.add_subcommand("freeze", "Freeze the session: every process holds its frame");
  auto* run = app.add_subcommand("run", "Run a frozen session again");
  auto* reset = app.add_subcommand(
      "reset", "Press the reset button for one frame: back to Mode 1, a new attempt");
  auto* step = app.add_subcommand("step", "While frozen: N more frames (default 1)");
  step->add_option("n", steps, "Frames")
      ->check(CLI::Range(1, static_cast<int>(rms::session_control_t::MAX_STEPS)));
  auto* checkpoint = app.add_subcommand(
      "checkpoint", "dynamics_proc saves its state as NAME in the session's checkpoints folder");
  checkpoint->add_option("name", what, "Checkpoint name (letters, digits, _ - .; .json is added)")
      ->required();
  auto* restore = app.add_subcommand("restore",
                                     "Freeze, then restore the DCP's state (and the operator's "
                                     "inputs) from a checkpoint NAME, or a FILE");
  restore
      ->add_option("checkpoint", what, "A checkpoint's name in the session, or a checkpoint file")
      ->required();
  restore->add_flag("--run", then_run, "Run again after restoring");
  std::vector<std::string> words;
  // (The grammars are made from the malfunction table, rms/wire/malfunction.h.)
  auto* malfunction =
      app.add_subcommand("malfunction", "Inject a malfunction: " + rms::wire::MalfunctionGrammar() +
                                            " (docs/sessions.md \"Malfunctions\")");
  malfunction->add_option("what", words, "The malfunction, e.g. joint 2 stuck")->required();
  auto* repair =
      app.add_subcommand("repair", "Repair a malfunction: " + rms::wire::RepairGrammar());
  repair->add_option("what", words, "What to repair, e.g. joint 2")->required();
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    const Target target = ResolveTarget(session_dir, session_id, key_file, &lcm_options);
    const std::string& folder = target.checkpoints;
    const std::int64_t id = target.id;
    std::string name;
    if (checkpoint->parsed()) {
      name = CheckpointName(what);
      if (!folder.empty() && fs::exists(fs::path(folder) / name)) {
        std::fprintf(stderr, "rms_control: checkpoint %s exists already in %s: give another name\n",
                     name.c_str(), folder.c_str());
        return 1;
      }
    }
    if (restore->parsed()) name = RestoreName(what, folder);
    // A malfunction's text is checked here first: a clear error, nothing sent.
    if (malfunction->parsed())
      name = rms::wire::MalfunctionText(rms::wire::ParseMalfunction(Joined(words)));
    if (repair->parsed()) name = rms::wire::RepairText(rms::wire::ParseRepair(Joined(words)));
    ControlLink link(lcm_options, id, target.key);
    // A running session's record has the command from this tool's own
    // journal too (docs/sessions.md "The record").
    if (!session_dir.empty() && fs::is_directory(fs::path(session_dir) / "journal"))
      link.JournalIn((fs::path(session_dir) / "journal").string());
    if (malfunction->parsed())
      return Malfunction(link, rms::session_control_t::MALFUNCTION, name, lcm_options, id);
    if (repair->parsed())
      return Malfunction(link, rms::session_control_t::REPAIR, name, lcm_options, id);
    if (checkpoint->parsed()) return Checkpoint(link, name, folder, lcm_options, id);
    if (restore->parsed()) return Restore(link, name, then_run, lcm_options, id);
    if (freeze->parsed()) return Clock(link, rms::session_control_t::FREEZE, 1, lcm_options, id);
    if (run->parsed()) return Clock(link, rms::session_control_t::RUN, 1, lcm_options, id);
    if (reset->parsed()) return Clock(link, rms::session_control_t::RESET, 1, lcm_options, id);
    return Clock(link, rms::session_control_t::STEP, steps, lcm_options, id);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_control: %s\n", e.what());
    return 2;
  }
}
