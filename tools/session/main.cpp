// rms_session: tools over a lab session folder (docs/sessions.md).
//   rms_session summary SESSION   writes SESSION/summary.json
#include <CLI/CLI.hpp>
#include "rms/base/command_line.h"
#include <fstream>
#include <functional>
#include <unistd.h>
#include <iostream>
#include <map>

#include "rms/base/text.h"
#include "rms/session/export_csv.h"
#include "rms/session/lab_file.h"
#include "rms/session/session_folder.h"
#include "rms/session/session_summary.h"

int main(int argc, char** argv) {
  CLI::App app{"rmslab session tools"};
  app.require_subcommand(1);
  std::string dir;
  std::string out;
  CLI::App* summary = app.add_subcommand("summary", "Write SESSION/summary.json from the session's log and stats");
  summary->add_option("session", dir, "Session folder")->required()->check(CLI::ExistingDirectory);
  summary->add_option("--out", out, "Output file (default SESSION/summary.json)");
  bool brief = false;
  summary->add_flag("--brief", brief, "Print a few human-readable lines instead of the JSON");

  // manifest: what a session ran, written by scripts/lab at the start.
  CLI::App* manifest = app.add_subcommand("manifest", "Write SESSION/manifest.json: config, software, hosts, start");
  std::string m_dir;
  rms::session::ManifestFields mf;
  manifest->add_option("session", m_dir, "Session folder")->required()->check(CLI::ExistingDirectory);
  manifest->add_option("--pilot", mf.pilot, "autopilot, timeline, by-hand, replay")->required();
  manifest->add_option("--lcm-url", mf.url, "The session's LCM URL")->required();
  manifest->add_option("--channel-suffix", mf.suffix, "The session's channel suffix");
  manifest->add_option("--session-id", mf.session_id, "The session's id (0x and 16 hex digits)");
  manifest->add_option("--config-sha256", mf.config_sha256, "SHA-256 of config.toml");
  manifest->add_option("--timeline", mf.timeline, "The timeline flown, if any");
  manifest->add_option("--restore", mf.restore, "The checkpoint the session started from, if any");
  manifest->add_option("--host", mf.hosts, "PROCESS=HOST, one per process (default: all on this host)");
  manifest->add_option("--command", mf.command, "The command line that started the session");
  manifest->add_option("--subject", mf.subject, "Who flew it (scripts/lab compare groups by it)");
  manifest->add_option("--note", mf.note, "The experimenter's note");
  manifest->add_option("--kind", mf.kind, "live, replay or re-simulation")->capture_default_str();
  manifest->add_option("--parent", mf.parent, "A replay's recorded session");

  // compare-esg: replayed ESG frames against recorded ones.
  CLI::App* compare = app.add_subcommand("compare-esg", "Compare a replay's ESG frames with the recorded session's");
  std::string original, replay;
  compare->add_option("original", original, "The recorded session")->required()->check(CLI::ExistingDirectory);
  compare->add_option("replay", replay, "The replay's session folder")->required()->check(CLI::ExistingDirectory);
  // export: every channel to CSV.
  CLI::App* exporter = app.add_subcommand("export", "Every channel of SESSION's log to CSV, decoded, with units");
  std::string e_dir, e_out;
  exporter->add_option("session", e_dir, "Session folder")->required()->check(CLI::ExistingDirectory);
  exporter->add_option("--out", e_out, "Folder for the CSV files (default SESSION/csv)");
  bool e_jsonl = false;
  exporter->add_flag("--jsonl", e_jsonl, "Instead: every message as a JSON line on stdout (for the MCAP writer)");
  // folder: a new session folder (the one writer of them; scripts/lab demo and replay).
  CLI::App* folder = app.add_subcommand("folder", "Make a new session folder and print its absolute path");
  std::string f_dir;
  folder->add_option("dir", f_dir, "The folder")->required();

  // labfile: a lab's host layout, checked, as JSON for scripts/lab.
  CLI::App* labfile = app.add_subcommand("labfile", "Check a lab file (docs/sessions.md) and print it as JSON");
  std::string lab_path;
  labfile->add_option("file", lab_path, "Lab file")->required()->check(CLI::ExistingFile);
  // probe: who else is on an address (scripts/lab, before a session starts).
  CLI::App* probe = app.add_subcommand(
      "probe", "Listen on an LCM address and print, as JSON, every rmslab session heard there (docs/security.md)");
  std::string probe_url;
  double probe_s = 1.2;
  probe->add_option("--lcm-url", probe_url, "The address")->required();
  probe->add_option("--seconds", probe_s, "How long to listen")->capture_default_str()->check(CLI::Range(0.1, 60.0));
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    if (folder->parsed()) {
      std::cout << rms::session::CreateSessionFolder(f_dir) << "\n";
      return 0;
    }
    if (exporter->parsed() && e_jsonl) {
      std::ios::sync_with_stdio(false);
      long malformed = 0;
      const long n = rms::session::ExportJsonLines(e_dir, std::cout, &malformed);
      std::cout.flush();
      std::cerr << "rms_session export: " << n << " messages";
      if (malformed > 0) std::cerr << " (" << malformed << " malformed, left out)";
      std::cerr << "\n";
      return std::cout ? 0 : 1;
    }
    if (exporter->parsed()) {
      if (e_out.empty()) e_out = e_dir + "/csv";
      // Progress only to a person at a terminal (docs/sessions.md "Command lines").
      std::function<void(const std::string&)> progress;
      if (isatty(STDERR_FILENO)) progress = [](const std::string& line) { std::cerr << line << "\n"; };
      const auto files = rms::session::ExportCsv(e_dir, e_out, progress);
      for (const auto& [f, n] : files) std::cout << f << ": " << n << " rows\n";
      return 0;
    }
    if (labfile->parsed()) {
      std::cout << rms::session::LabFileJson(rms::session::LoadLabFile(lab_path)).dump(2) << "\n";
      return 0;
    }
    if (probe->parsed()) {
      std::cout << rms::session::ProbeAddress(probe_url, probe_s).dump(2) << "\n";
      return 0;
    }
    if (manifest->parsed()) {
      const auto j = rms::session::MakeManifest(m_dir, mf);
      rms::WriteWholeFile(m_dir + "/manifest.json", j.dump(2) + "\n");
      return 0;
    }
    if (compare->parsed()) {
      const auto c = rms::session::CompareEsgFrames(original, replay);
      std::cout << c.dump(2) << "\n";
      return c["identical"] == c["recorded"] && c["missing"] == 0 ? 0 : 1;
    }
    const auto j = rms::session::Summarize(dir);
    if (out.empty()) out = dir + "/summary.json";
    rms::WriteWholeFile(out, j.dump(2) + "\n");
    if (!brief) {
      std::cout << j.dump(2) << "\n";
      return 0;
    }
    const auto& fr = j["frames"];
    std::int64_t dropped = 0;
    for (const auto& [k, v] : fr["dropped"].items()) dropped += v.get<std::int64_t>();
    std::cout << "frames: operator " << fr["operator_published"] << ", DCP " << fr["dcp_published"]
              << ", ESG " << fr["esg_published"] << ", rendered " << fr["rendered"] << ", PNG "
              << fr["png_written"] << "; dropped " << dropped << "\n";
    if (!j["log"]["stats_from_log"].empty()) {
      std::cout << "counts of " << j["log"]["stats_from_log"].dump() << " from their last status reports in the log "
                << "(they wrote no stats file at exit: a full disk, a crash): the counts end where the record ends\n";
    }
    {
      const auto& r = fr["refused"];
      if (r.value("other_session", 0) + r.value("other_sender", 0) + r.value("late", 0) + r.value("far_ahead", 0) > 0) {
        std::cout << "refused by the processes: " << r["other_session"] << " of other sessions, " << r["other_sender"]
                  << " from an impostor with this session's id, " << r["late"] << " too late to act on (a stall), "
                  << r["far_ahead"] << " with impossible frame numbers\n";
      }
    }
    if (j["record"].value("lost", 0) > 0) {
      std::cout << "the record lost " << j["record"]["lost"] << " frames (the recorder fell behind, was stopped or its "
                << "disk filled):";
      for (const auto& [ch, r] : j["record"]["by_channel"].items()) {
        if (r["lost"].get<std::int64_t>() > 0) std::cout << " " << ch << " " << r["lost"] << " of " << r["published"];
      }
      std::cout << "\n";
    }
    if (j["ignored"].value("total", 0) > 0) {
      std::cout << "left out " << j["ignored"]["total"] << " logged messages (another session's, or not believed):";
      for (const auto& [why, n] : j["ignored"]["by_reason"].items()) std::cout << " " << why << " " << n;
      if (!j["ignored"]["other_sessions"].empty()) std::cout << " (sessions " << j["ignored"]["other_sessions"].dump() << ")";
      std::cout << "\n";
    }
    if (fr.value("superseded", 0) > 0) {
      std::cout << "renderer: " << fr["superseded"] << " frames overtaken by a newer one before they were drawn "
                << "(superseded): not drawn; the video repeats the image before them\n";
    }
    if (fr.value("video_dropped", 0) > 0) {
      std::cout << "video: " << fr["video_dropped"] << " frames dropped (the encoder fell behind; the video is "
                << "short of the session by as much)\n";
    }
    if (j["latency"].contains("input_to_render")) {
      const auto& l = j["latency"]["input_to_render"];
      std::cout << "operator input to rendered frame: median " << l["p50_ms"].get<double>()
                << " ms, p99 " << l["p99_ms"].get<double>() << " ms\n";
    }
    if (j["log"].value("dcp_frames", 0) == 0) std::cout << "modes: none (no DCP frame in the log)";
    else std::cout << "modes 1";
    std::size_t shown = 0;
    for (const auto& mc : j["mode_changes"]) {
      if (++shown > 8) {
        std::cout << " ... (" << j["mode_changes"].size() - 8 << " more mode changes)";
        break;
      }
      std::cout << " -> " << mc["to"] << " (" << rms::HumanNumber(mc["time_s"].get<double>(), 1) << " s)";
    }
    std::cout << "; acquired " << (j["acquired"].get<bool>() ? "yes" : "no") << ", docked "
              << (j["docked"].get<bool>() ? "yes" : "no");
    if (!j["docking"].is_null()) {
      std::cout << " (" << rms::HumanNumber(j["docking"]["distance_ft"].get<double>()) << " ft, "
                << rms::HumanNumber(j["docking"]["angle_deg"].get<double>(), 2) << " deg)";
    }
    if (!j["docking"].is_null() && j["docking"].value("after_restore", false)) std::cout << " after a restore";
    std::cout << "\ncollisions " << j["collisions"].size() << ", frames held " << j["held_frames"]
              << "; LCM log events " << j["log"]["events"] << "\n";
    if (j["attempts"].size() > 1) {
      std::cout << "attempts: " << j["attempts"].size() << " (";
      for (std::size_t i = 0; i < j["attempts"].size(); ++i) {
        const auto& a = j["attempts"][i];
        std::cout << (i ? "; " : "") << a["index"] << " from the " << a["started_by"].get<std::string>() << " at "
                  << rms::HumanNumber(a["start_s"].get<double>()) << " s: " << a["outcome"].get<std::string>();
      }
      std::cout << ")\n";
    }
    if (!j["control"].empty()) {
      std::map<std::string, int> n;
      for (const auto& c : j["control"]) ++n[c["command"].get<std::string>()];
      std::cout << "session control sent:";
      for (const auto& [what, k] : n) std::cout << " " << what << " " << k;
      std::cout << "\n";
    }
    if (!j["ignored"].value("session_id_checked", true)) {
      std::cout << "this session has no id (made before session ids): every message in its log was read as its own\n";
    }
    if (j.contains("restarts") && !j["restarts"].empty()) {
      std::cout << "restarted after a fault:";
      for (const auto& r : j["restarts"]) {
        std::cout << " " << r["process"].get<std::string>() << " (exit " << r["exit_code"] << ", up again in "
                  << r["restart_s"].get<double>() << " s)";
      }
      std::cout << "\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rms_session: " << e.what() << "\n";
    return 2;
  }
}
