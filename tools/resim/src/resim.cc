#include "rms/resim/resim.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/base/text.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/session/session_folder.h"
#include "rms/session/session_log.h"
#include "rms/session/session_summary.h"
#include "rms/transport/lcm_interface.h"
#include "rms/transport/process.h"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/message_io.h"

#include "comparison.h"
#include "narrative.h"
#include "recording.h"

namespace fs = std::filesystem;

namespace rms::resim {

namespace {

using Clock = std::chrono::steady_clock;

// A logged state: a restore, a resume, a malfunction or a start is taken as
// the live DCP took it (another design keeps its own state at a resume: only
// the numbering; at a malfunction, the numbering and the malfunctions in
// force); a periodic one is checked against the re-simulated state (the same
// design only: another one is expected to differ).
void TakeState(const dcp_state_t& m, bool first, bool other_design,
               dynamics_proc::DynamicsProc* node, ResimResult* result) {
  if (m.reason == dcp_state_t::PERIODIC && !first) {
    if (other_design || !result->state_difference.empty()) return;
    ++result->states_checked;
    const wire::Checkpoint logged = wire::ParseCheckpoint(m.checkpoint, "RMS_DCP_STATE");
    if (logged.dcp != node->MakeCheckpoint().dcp) {
      result->state_difference = "the DCP's state before DCP frame " +
                                 std::to_string(m.next_frame) +
                                 " differs from the state it logged there";
    }
    return;
  }
  const bool own_state =
      other_design && (m.reason == dcp_state_t::RESUME || m.reason == dcp_state_t::MALFUNCTION);
  node->ApplyState(m, first || !own_state);
  ++result->states_taken;
  // Into the new session's log too, so it can be re-simulated and its
  // summary sees the same restores (its attempts).
  node->PublishState(m.reason == dcp_state_t::PERIODIC ? dcp_state_t::START : m.reason);
}

// What the re-simulated DCP sent, in DCP frame order, one message a frame
// (the last sent, were there two); Find looks one up.
struct Outputs {
  std::vector<dcp_frame_t> frames;
  std::vector<dcp_telemetry_t> telemetry;
};

// The DCP's own node over a log-backed transport, step by step through the
// plan (out_log: the new session's log, "" for none).
Outputs RunDcp(const LabConfig& config, const Recording& rec, const Plan& plan,
               const std::string& out_log, bool other_design,
               const std::function<void(double, const std::string&)>& progress,
               ResimResult* result) {
  // During the run the outputs are appended to vectors reserved up front (no
  // allocation a frame), in frame order; the comparison finds them there.
  std::vector<dcp_frame_t> frames_run;
  std::vector<dcp_telemetry_t> telemetry_run;
  frames_run.reserve(plan.steps.size());
  telemetry_run.reserve(plan.steps.size());
  transport::LogLcm lcm("", out_log, rec.suffix);
  dynamics_proc::DynamicsProc node(config, &lcm);
  lcm.Subscribe(wire::channels::kDcpFrame, [&](const void* d, int n, std::int64_t) {
    frames_run.emplace_back();
    if (wire::SafeDecode(d, n, &frames_run.back()) != wire::DecodeError::kNone)
      frames_run.pop_back();
  });
  lcm.Subscribe(wire::channels::kDcpTelemetry, [&](const void* d, int n, std::int64_t) {
    telemetry_run.emplace_back();
    if (wire::SafeDecode(d, n, &telemetry_run.back()) != wire::DecodeError::kNone)
      telemetry_run.pop_back();
  });
  const auto t_run = Clock::now();
  const std::size_t n = plan.steps.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Step& step = plan.steps[k];
    if (step.state) {
      TakeState(*step.state, step.first, other_design, &node, result);
      continue;
    }
    const RecordedInput* input = FindFrame(rec.inputs, step.input_frame);
    if (!input) {
      throw InputError(
          "operator frame " + std::to_string(step.input_frame) +
          ", which the DCP answered, is not in the log: the re-simulation cannot be exact");
    }
    lcm.SetNowUs(input->timestamp_us);
    lcm.Publish(wire::channels::kOperatorInput, rec.input_bytes.data() + input->offset,
                static_cast<int>(input->size));
    lcm.HandleSubscriptions(0);  // the input to the DCP
    lcm.HandleSubscriptions(0);  // its outputs to the comparison
    if (n >= 20 && k % (n / 20) == 0)
      progress(static_cast<double>(k) / n,
               std::to_string(k) + " of " + std::to_string(n) + " steps");
  }
  result->run_seconds = std::chrono::duration<double>(Clock::now() - t_run).count();
  Outputs out{std::move(frames_run), std::move(telemetry_run)};
  SortByFrame(&out.frames);
  SortByFrame(&out.telemetry);
  result->frames = static_cast<long>(out.frames.size());
  if (other_design) {
    transport::WriteStatsJson((fs::path(result->out_dir) / "stats" / "dynamics_proc.json").string(),
                              "dynamics_proc", node.counters(), node.latencies());
  }
  return out;
}

// Word for word against the recording, from the plan's first frame.
void CompareWithRecording(const Recording& rec, std::size_t first, const Outputs& out,
                          ResimResult* result) {
  for (std::size_t i = first; i < rec.dcp_frames.size(); ++i) {
    const dcp_frame_t& r = rec.dcp_frames[i];
    ++result->compared;
    const dcp_frame_t* made = FindFrame(out.frames, r.frame);
    std::string what;
    bool same = made && SameFrame(*made, r, &what);
    if (same) {
      const dcp_telemetry_t* rt = FindFrame(rec.telemetry, r.frame);
      const dcp_telemetry_t* nt = FindFrame(out.telemetry, r.frame);
      if (rt && nt) same = SameTelemetry(*nt, *rt, &what);
    } else if (!made) {
      what = "missing";
    }
    if (same)
      ++result->identical;
    else if (result->first_difference.empty())
      result->first_difference = "DCP frame " + std::to_string(r.frame) + ": " + what;
  }
  if (result->first_difference.empty() && !result->state_difference.empty()) {
    result->first_difference = result->state_difference;
  }
}

// Another design: a new session folder with its configuration, ready for the run's log.
std::string OpenNewSession(const ResimOptions& opt, const std::string& config_path,
                           ResimResult* result) {
  result->out_dir = opt.out_dir.empty()
                        ? (fs::path(opt.session).lexically_normal().string() + "-resim")
                        : opt.out_dir;
  session::CreateSessionFolder(result->out_dir);
  fs::copy_file(config_path, fs::path(result->out_dir) / "config.toml",
                fs::copy_options::overwrite_existing);
  WriteWholeFile((fs::path(result->out_dir) / "run" / "pilot").string(), "resim\n");
  return (fs::path(result->out_dir) / "lcmlog").string();
}

// comparison.md: what changed, and what it did.
std::string ComparisonMarkdown(const fs::path& session, const std::string& config_path,
                               const ResimResult& result) {
  std::ostringstream md;
  md << "# Re-simulation of " << fs::absolute(session).lexically_normal().string() << "\n\n";
  md << "The recorded operator inputs, flown again with `" << config_path
     << "`.\n\n## What changed\n\n";
  for (const auto& c : result.comparison["config_changes"]) {
    md << "- `" << c["key"].get<std::string>() << "`: " << c["recorded"].get<std::string>()
       << " -> " << c["now"].get<std::string>() << "\n";
  }
  md << "\n## What it did\n\n";
  for (const auto& s : result.comparison["explanation"]) md << "- " << s.get<std::string>() << "\n";
  md << "\n"
     << result.identical << " of " << result.compared
     << " DCP frames identical to the recording.\n";
  return md.str();
}

// Another design's session: its manifest (the parent's subject and note go
// with the inputs), summary, comparison.json and comparison.md.
void WriteNewSession(const fs::path& session, const std::string& config_path,
                     const LabConfig& config, const Recording& rec, const Outputs& out,
                     ResimResult* result) {
  const fs::path dir(result->out_dir);
  session::ManifestFields mf;
  mf.pilot = "resim";
  mf.kind = "re-simulation";
  mf.parent = fs::absolute(session).lexically_normal().string();
  mf.config_source = fs::absolute(config_path).string();
  if (fs::exists(session / "manifest.json")) {
    try {
      const auto parent =
          nlohmann::json::parse(std::ifstream((session / "manifest.json").string()));
      mf.subject = parent.value("subject", "");
      mf.note = parent.value("note", "");
    } catch (const std::exception&) {
    }
  }
  WriteWholeFile((dir / "manifest.json").string(),
                 session::MakeManifest(dir.string(), mf).dump(2) + "\n");
  WriteWholeFile((dir / "summary.json").string(), session::Summarize(dir.string()).dump(2) + "\n");
  result->comparison =
      DesignComparison(TelemetryByFrame(rec.telemetry), TelemetryByFrame(out.telemetry), config,
                       config.session.frame_rate_hz);
  result->comparison["config_changes"] =
      ConfigChanges((session / "config.toml").string(), config_path);
  result->comparison["frames_identical"] = result->identical;
  result->comparison["frames_compared"] = result->compared;
  WriteWholeFile((dir / "comparison.json").string(), result->comparison.dump(2) + "\n");
  WriteWholeFile((dir / "comparison.md").string(),
                 ComparisonMarkdown(session, config_path, *result));
}

}  // namespace

ResimResult Resimulate(const ResimOptions& opt) {
  const auto t0 = Clock::now();
  const fs::path session(opt.session);
  if (!fs::exists(session / "lcmlog"))
    throw InputError(opt.session + ": not a session folder (no lcmlog)");
  const bool other_design = !opt.config_path.empty();
  const std::string config_path =
      other_design ? opt.config_path : (session / "config.toml").string();
  const LabConfig config = LoadConfig(config_path);
  auto progress = [&](double f, const std::string& line) {
    if (opt.progress) opt.progress(f, line);
  };
  progress(0.0, "reading " + (session / "lcmlog").string());
  // The session's own config is read once (another design's is not its).
  session::SessionLog log = other_design
                                ? session::SessionLog(opt.session)
                                : session::SessionLog(opt.session, config.session.frame_rate_hz);
  const Recording rec = ReadRecording(log);
  const Plan plan = MakePlan(rec);
  const auto t_read = Clock::now();

  ResimResult result;
  if (log.unread_bytes() > 0) {
    result.log_note = "the log ends in " + std::to_string(log.unread_bytes()) +
                      " bytes that are no whole event (it was cut short or damaged there): "
                      "re-simulated up to them";
  }
  result.note = plan.note;
  result.skipped = static_cast<long>(plan.first);
  const std::string out_log = other_design ? OpenNewSession(opt, config_path, &result) : "";
  const Outputs out = RunDcp(config, rec, plan, out_log, other_design, progress, &result);
  progress(1.0, "done");
  CompareWithRecording(rec, plan.first, out, &result);
  result.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  result.read_seconds = std::chrono::duration<double>(t_read - t0).count();
  if (!rec.inputs.empty()) {
    result.recorded_seconds =
        (rec.inputs.back().timestamp_us - rec.inputs.front().timestamp_us) / 1e6;
  }
  if (other_design) WriteNewSession(session, config_path, config, rec, out, &result);
  return result;
}

}  // namespace rms::resim
