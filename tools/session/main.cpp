// rms_session: tools over a lab session folder (docs/sessions.md): its
// summary, manifest, CSV export, a new folder, lab files, who is on an
// address, a replay's frames compared, the counter table.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

#include "rms/base/command_line.h"
#include "rms/base/config.h"
#include "rms/base/config_settings.h"
#include "rms/base/counters.h"
#include "rms/base/folder_file.h"
#include "rms/base/text.h"
#include "rms/session/address_probe.h"
#include "rms/session/brief.h"
#include "rms/session/esg_compare.h"
#include "rms/session/export_csv.h"
#include "rms/session/lab_file.h"
#include "rms/session/manifest.h"
#include "rms/session/record.h"
#include "rms/session/session_folder.h"
#include "rms/session/session_summary.h"
#include "rms/wire/malfunction.h"

namespace {

namespace session = rms::session;

// A subcommand and what it does when given; each returns the exit code.
struct Command {
  CLI::App* app;
  std::function<int()> run;
};

// summary: SESSION/summary.json from the log and the stats.
Command Summary(CLI::App& app) {
  struct O {
    std::string dir, out;
    bool brief = false;
  };
  auto o = std::make_shared<O>();
  CLI::App* c =
      app.add_subcommand("summary", "Write SESSION/summary.json from the session's log and stats");
  c->add_option("session", o->dir, "Session folder")->required()->check(CLI::ExistingDirectory);
  c->add_option("--out", o->out, "Output file (default SESSION/summary.json)");
  c->add_flag("--brief", o->brief, "Print a few human-readable lines instead of the JSON");
  return {c, [o] {
            const auto j = session::Summarize(o->dir);
            const std::string out = o->out.empty() ? o->dir + "/summary.json" : o->out;
            rms::WriteWholeFile(
                out, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n",
                rms::LinksForOutput(out, o->dir));
            if (o->brief) {
              std::ostringstream brief;  // names from messages: shown, not obeyed
              session::PrintBrief(j, brief);
              std::cout << rms::TerminalText(brief.str());
            } else
              std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
            // Written, but not to be stood behind: damage inside the log
            // (docs/sessions.md "A damaged log").
            if (const std::int64_t n = j["log"].value("skipped_bytes", std::int64_t{0}); n > 0) {
              std::cerr << "summary: the log is damaged inside (" << n
                        << " bytes that are no event, read past): the summary may be short "
                           "(exit 3)\n";
              return 3;
            }
            if (j["log"].value("events", std::int64_t{0}) == 0 &&
                j["log"].value("unread_bytes", std::int64_t{0}) > 0) {
              std::cerr << "summary: the log holds no event at all, only "
                        << j["log"]["unread_bytes"] << " bytes that are none (exit 3)\n";
              return 3;
            }
            return 0;
          }};
}

// record: SESSION/lcmlog from the processes' journals and the recorder's log.
Command Record(CLI::App& app) {
  struct O {
    std::string dir;
    session::RecordOptions options;
  };
  auto o = std::make_shared<O>();
  CLI::App* c = app.add_subcommand(
      "record",
      "Make SESSION/lcmlog from its processes' journals (journal/) and what the network "
      "delivered (wire.lcmlog); say what each source held and what the network missed "
      "(SESSION/record.json; docs/sessions.md \"The record\")");
  c->add_option("session", o->dir, "Session folder")->required()->check(CLI::ExistingDirectory);
  c->add_flag("--keep-journals", o->options.keep_journals,
              "Leave journal/ as it is once the record is made");
  return {c, [o] {
            std::cout << session::MakeRecord(o->dir, o->options)
                             .dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
                      << "\n";
            return 0;
          }};
}

// manifest: what a session ran, written by scripts/lab at the start.
Command Manifest(CLI::App& app) {
  struct O {
    std::string dir;
    session::ManifestFields f;
  };
  auto o = std::make_shared<O>();
  CLI::App* c =
      app.add_subcommand("manifest", "Write SESSION/manifest.json: config, software, hosts, start");
  session::ManifestFields& f = o->f;
  c->add_option("session", o->dir, "Session folder")->required()->check(CLI::ExistingDirectory);
  c->add_option("--pilot", f.pilot, "autopilot, timeline, by-hand, replay")->required();
  c->add_option("--lcm-url", f.url, "The session's LCM URL")->required();
  c->add_option("--channel-suffix", f.suffix, "The session's channel suffix");
  c->add_option("--session-id", f.session_id, "The session's id (0x and 16 hex digits)");
  c->add_option("--message-auth", f.message_auth,
                "The session's messages carry tags (blake2b-128; its key in run/session.key)");
  c->add_option("--config-sha256", f.config_sha256, "SHA-256 of config.toml");
  c->add_option("--timeline", f.timeline, "The timeline flown, if any");
  c->add_option("--restore", f.restore, "The checkpoint the session started from, if any");
  c->add_option("--host", f.hosts, "PROCESS=HOST, one per process (default: all on this host)");
  c->add_option("--command", f.command, "The command line that started the session");
  c->add_option("--subject", f.subject, "Who flew it (scripts/lab compare groups by it)");
  c->add_option("--note", f.note, "The experimenter's note");
  c->add_option("--kind", f.kind, "live, replay or re-simulation")->capture_default_str();
  c->add_option("--parent", f.parent, "A replay's recorded session");
  c->add_option("--branch-of", f.branch_of,
                "A branch's recorded session (scripts/lab demo --from)");
  c->add_option("--branch-frame", f.branch_frame, "... the last DCP frame of its prefix");
  c->add_option("--branch-time", f.branch_time_s, "... that frame's session time, s");
  c->add_option("--study", f.study.name, "A study's trial (docs/studies.md): the study's name");
  c->add_option("--study-sha256", f.study.file_sha256, "... SHA-256 of its study file");
  c->add_option("--condition", f.study.condition, "... the trial's condition");
  c->add_option("--trial", f.study.trial, "... the trial's place in the subject's order, from 1");
  c->add_option("--trial-kind", f.study.kind, "... practice or measured")
      ->check(CLI::IsMember({"practice", "measured"}));
  c->add_option("--trial-run", f.study.run, "... this trial's run: 1, or more after a lost one");
  c->add_option("--branch-parent-log-sha256", f.branch_parent_log_sha256,
                "... SHA-256 of the recorded session's lcmlog");
  return {c, [o] {
            rms::WriteWholeFile(
                o->dir + "/manifest.json",
                session::MakeManifest(o->dir, o->f)
                        .dump(2, ' ', false, nlohmann::json::error_handler_t::replace) +
                    "\n");
            return 0;
          }};
}

// compare-esg: replayed ESG frames against recorded ones.
Command CompareEsg(CLI::App& app) {
  auto o = std::make_shared<std::pair<std::string, std::string>>();
  CLI::App* c = app.add_subcommand("compare-esg",
                                   "Compare a replay's ESG frames with the recorded session's");
  c->add_option("original", o->first, "The recorded session")
      ->required()
      ->check(CLI::ExistingDirectory);
  c->add_option("replay", o->second, "The replay's session folder")
      ->required()
      ->check(CLI::ExistingDirectory);
  return {c, [o] {
            const auto r = session::CompareEsgFrames(o->first, o->second);
            std::cout << r.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
            return r["identical"] == r["recorded"] && r["missing"] == 0 ? 0 : 1;
          }};
}

// export: every channel to CSV, or every message as a JSON line (the MCAP writer's input).
Command Export(CLI::App& app) {
  struct O {
    std::string dir, out;
    bool jsonl = false;
  };
  auto o = std::make_shared<O>();
  CLI::App* c =
      app.add_subcommand("export", "Every channel of SESSION's log to CSV, decoded, with units");
  c->add_option("session", o->dir, "Session folder")->required()->check(CLI::ExistingDirectory);
  c->add_option("--out", o->out, "Folder for the CSV files (default SESSION/csv)");
  c->add_flag("--jsonl", o->jsonl,
              "Instead: every message as a JSON line on stdout (for the MCAP writer)");
  return {c, [o] {
            if (o->jsonl) {
              std::ios::sync_with_stdio(false);
              long malformed = 0;
              const long n = session::ExportJsonLines(o->dir, std::cout, &malformed);
              std::cout.flush();
              std::cerr << "rms_session export: " << n << " messages";
              if (malformed > 0) std::cerr << " (" << malformed << " malformed, left out)";
              std::cerr << "\n";
              return std::cout ? 0 : 1;
            }
            // Progress only to a person at a terminal (docs/sessions.md "Command lines").
            std::function<void(const std::string&)> progress;
            if (isatty(STDERR_FILENO))
              progress = [](const std::string& line) { std::cerr << line << "\n"; };
            session::ExportRead read;
            const auto files = session::ExportCsv(o->dir, o->out.empty() ? o->dir + "/csv" : o->out,
                                                  progress, &read);
            for (const auto& [f, n] : files)
              std::cout << rms::TerminalText(f) << ": " << n << " rows\n";
            // What could not be read is said, never left to a count of rows.
            if (read.unread_bytes > 0)
              std::cerr << "rms_session export: the log ends in " << read.unread_bytes
                        << " bytes that are no whole event (it was cut short or damaged there): "
                           "exported up to them\n";
            if (read.skipped_bytes > 0)
              std::cerr << "rms_session export: THE LOG IS DAMAGED: " << read.skipped_bytes
                        << " bytes inside it are no event (read past; what they held is not "
                           "exported)\n";
            if (read.events == 0) {
              std::cerr << "rms_session export: " << o->dir
                        << "/lcmlog holds no message of this session: nothing was exported\n";
              return 1;
            }
            return 0;
          }};
}

// folder: a new session folder (the one writer of them; scripts/lab demo and replay).
Command Folder(CLI::App& app) {
  auto dir = std::make_shared<std::string>();
  CLI::App* c =
      app.add_subcommand("folder", "Make a new session folder and print its absolute path");
  c->add_option("dir", *dir, "The folder")->required();
  return {c, [dir] {
            std::cout << session::CreateSessionFolder(*dir) << "\n";
            return 0;
          }};
}

// labfile: a lab's host layout, checked, as JSON for scripts/lab.
Command LabFile(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* c =
      app.add_subcommand("labfile", "Check a lab file (docs/sessions.md) and print it as JSON");
  c->add_option("file", *path, "Lab file")->required()->check(CLI::ExistingFile);
  return {c, [path] {
            std::cout << session::LabFileJson(session::LoadLabFile(*path))
                             .dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
                      << "\n";
            return 0;
          }};
}

// probe: who else is on an address (scripts/lab, before a session starts).
Command Probe(CLI::App& app) {
  auto o = std::make_shared<std::pair<std::string, double>>("", 1.2);
  CLI::App* c = app.add_subcommand("probe",
                                   "Listen on an LCM address and print, as JSON, every rmslab "
                                   "session heard there (docs/security.md)");
  c->add_option("--lcm-url", o->first, "The address")->required();
  c->add_option("--seconds", o->second, "How long to listen")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 60.0));
  return {c, [o] {
            std::cout << session::ProbeAddress(o->first, o->second)
                             .dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
                      << "\n";
            return 0;
          }};
}

// design: a configuration with keys set over it (a study's condition,
// docs/studies.md), checked as every process checks it, written to a file.
Command Design(CLI::App& app) {
  struct O {
    std::string config, out;
    std::vector<std::string> sets;
  };
  auto o = std::make_shared<O>();
  CLI::App* c = app.add_subcommand(
      "design",
      "Write a configuration with KEY=VALUE settings over another, checked (docs/studies.md)");
  c->add_option("--config", o->config, "The configuration the design starts from")->required();
  c->add_option("--set", o->sets, "KEY=VALUE: a key set over it, as rms_resim --set; repeatable");
  c->add_option("--out", o->out, "Where the design's configuration goes")->required();
  return {c, [o] {
            std::vector<rms::ConfigSetting> settings;
            for (const std::string& s : o->sets) settings.push_back(rms::ParseConfigSetting(s));
            const std::string base = rms::ReadRegularFile(
                o->config, "configuration", rms::kMaxConfigBytes, rms::Links::kFollow);
            const std::string text = rms::ApplyConfigSettings(base, o->config, settings);
            rms::ParseConfig(text, o->out);  // refused as every process would refuse it
            rms::WriteWholeFile(o->out, text, rms::Links::kFollow);
            return 0;
          }};
}

// counters: every counter a process reports, as docs/sessions.md lists them.
Command Counters(CLI::App& app) {
  CLI::App* c =
      app.add_subcommand("counters", "Print every process counter with its meaning (markdown)");
  return {c, [] {
            std::cout << rms::CounterTableMarkdown();
            return 0;
          }};
}

// malfunctions: the malfunction table, as docs/sessions.md shows it.
Command Malfunctions(CLI::App& app) {
  CLI::App* c = app.add_subcommand(
      "malfunctions",
      "Print the malfunctions an instructor injects, with their grammar (markdown)");
  return {c, [] {
            std::cout << rms::wire::MalfunctionTableMarkdown();
            return 0;
          }};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rmslab session tools"};
  app.require_subcommand(1);
  const std::vector<Command> commands = {
      Summary(app), Record(app), Manifest(app), CompareEsg(app),   Export(app), Folder(app),
      LabFile(app), Probe(app),  Counters(app), Malfunctions(app), Design(app)};
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    for (const Command& c : commands) {
      if (c.app->parsed()) return c.run();
    }
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "rms_session: " << rms::TerminalText(e.what()) << "\n";
    return 2;
  }
}
