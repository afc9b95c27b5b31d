#include "rms/resim/resim.h"

#include <sodium.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <vector>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/base/other_core.h"
#include "rms/base/text.h"
#include "rms/base/toml_reader.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/session/manifest.h"
#include "rms/session/session_folder.h"
#include "rms/session/session_log.h"
#include "rms/session/session_summary.h"
#include "rms/transport/lcm_interface.h"
#include "rms/transport/process.h"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/message_io.h"

#include "comparison.h"
#include "dcp_run.h"
#include "narrative.h"
#include "outcome.h"
#include "recording.h"

namespace fs = std::filesystem;

namespace rms::resim {

class RecordedSession {
 public:
  // parts: how the log's reading is shared out (SessionLog::ReadInTwo).
  RecordedSession(const std::string& dir, session::SessionLog log,
                  const session::SessionLog::TwoParts& parts = {})
      : dir_(dir),
        rec_(ReadRecording(log, parts)),
        plan_(MakePlan(rec_)),
        unread_(log.unread_bytes()),
        skipped_(log.skipped_bytes()) {}
  const std::string& dir() const { return dir_; }
  const Recording& recording() const { return rec_; }
  const Plan& plan() const { return plan_; }
  std::int64_t unread_bytes() const { return unread_; }
  std::int64_t skipped_bytes() const { return skipped_; }  // damage inside the log
  // Each of the following is made at the first call, once, whichever of
  // the threads running a batch's cells at once comes first (RunCells).
  // The recorded session's summary.json (made now when it has none).
  const nlohmann::json& summary() const {
    std::call_once(summary_once_, [this] {
      const fs::path session(dir_);
      try {
        summary_ =
            nlohmann::json::parse(session::ReadSessionFile(dir_, "summary.json", kMaxJsonBytes));
      } catch (const std::exception&) {
        summary_ = session::Summarize(dir_);
      }
    });
    return summary_;
  }
  // Its telemetry by DCP frame.
  const std::vector<dcp_telemetry_t>& telemetry() const {
    std::call_once(telemetry_once_, [this] { telemetry_ = DecodedTelemetry(rec_); });
    return telemetry_;
  }
  // Its config.toml parsed once for the designs of a batch's cells.
  const ConfigDesigns& config_designs() const {
    std::call_once(designs_once_, [this] {
      const std::string path = (fs::path(dir_) / "config.toml").string();
      designs_ = std::make_unique<const ConfigDesigns>(
          session::ReadSessionFile(dir_, "config.toml", kMaxConfigBytes), path);
    });
    return *designs_;
  }
  // Its config.toml's keys.
  const std::optional<ConfigKeys>& config_keys() const {
    std::call_once(config_keys_once_, [this] {
      config_keys_ = FlattenConfig(session::ReadSessionFile(dir_, "config.toml", kMaxConfigBytes));
    });
    return config_keys_;
  }

 private:
  std::string dir_;
  Recording rec_;
  Plan plan_;
  std::int64_t unread_ = 0, skipped_ = 0;
  // Made once, at the first call (a batch's designs share them).
  // (A call_once whose function throws leaves its flag unset: the next call tries again.)
  mutable std::once_flag summary_once_, telemetry_once_, designs_once_, config_keys_once_;
  mutable nlohmann::json summary_;
  mutable std::vector<dcp_telemetry_t> telemetry_;
  mutable std::optional<ConfigKeys> config_keys_;
  mutable std::unique_ptr<const ConfigDesigns> designs_;
};

namespace {

using Clock = std::chrono::steady_clock;

// The other core's share of the log's bytes when it reads while this thread
// parses the session's configuration first (about a third of the time the
// log's reading takes here: docs/performance.md "Two cores").
constexpr double kOtherCoresShare = 0.6;

// A branch (scripts/lab demo --from; docs/sessions.md "Branching"): its
// recorded session re-simulated up to the instant, word for word, and the
// DCP's state there against the branch's first logged state. Nothing when
// the session is no branch.
// The manifest's "branch", checked: its parent (a path) and frame (a DCP
// frame, an integer >= 0); "" or why it is not usable.
std::string ReadBranch(const nlohmann::json& b, ResimOptions* parent) {
  if (!b.is_object()) return "the manifest's 'branch' is not an object";
  if (!b.contains("parent") || !b["parent"].is_string() || b["parent"].get<std::string>().empty())
    return "the manifest's 'branch.parent' is not a session's path";
  if (!b.contains("frame") || !b["frame"].is_number_integer() || b["frame"].get<long>() < 0)
    return "the manifest's 'branch.frame' is not a DCP frame (an integer >= 0)";
  parent->session = b["parent"].get<std::string>();
  parent->until_frame = b["frame"].get<long>();
  if (!b.contains("time_s")) return "the manifest's 'branch.time_s' is missing";
  {
    double rate = 0;
    try {
      rate = session::LoadSessionConfig(parent->session).session.frame_rate_hz;
    } catch (const std::exception&) {
      return "";  // the prefix's own run says what is wrong with the parent
    }
    if (!b["time_s"].is_number() ||
        std::abs(b["time_s"].get<double>() - parent->until_frame / rate) > 1e-6)
      return "the manifest's 'branch.time_s' is not its frame's session time";
  }
  return "";
}

// "" when the prefix re-simulated word for word and its end state is the
// branch's first logged state; else why not.
std::string PrefixAgrees(const Recording& rec, const ResimResult& p) {
  if (!p.first_difference.empty())
    return "the prefix differs from its recording: " + p.first_difference;
  if (rec.states.empty())
    return "the branch's log holds no RMS_DCP_STATE to check its start against";
  if (wire::ParseCheckpoint(rec.states.front().m.checkpoint, "RMS_DCP_STATE").dcp !=
      wire::ParseCheckpoint(p.checkpoint_text, "the prefix").dcp)
    return "the branch's first state is not the DCP's state at the end of the prefix";
  return "";
}

void CheckBranchPrefix(const fs::path& session, const Recording& rec, ResimResult* result) {
  nlohmann::json m;
  try {
    m = nlohmann::json::parse(
        session::ReadSessionFile(session.string(), "manifest.json", kMaxJsonBytes));
  } catch (const std::exception&) {
    return;  // no manifest, or none readable: no branch to check
  }
  if (!m.is_object() || !m.contains("branch")) return;
  ResimOptions popt;
  std::string why = ReadBranch(m["branch"], &popt);
  const std::string prefix =
      why.empty() ? "DCP frames up to " + std::to_string(popt.until_frame) + " of " + popt.session
                  : "";
  ResimResult p;
  if (why.empty()) {
    try {
      p = Resimulate(popt);
    } catch (const std::exception& e) {
      why = std::string("it cannot be re-simulated: ") + e.what();
    }
  }
  if (why.empty()) why = PrefixAgrees(rec, p);
  result->prefix_frames = p.compared;
  result->prefix_identical = p.identical;
  if (!why.empty()) {
    result->first_difference =
        "the branch's prefix" + (prefix.empty() ? std::string() : " (" + prefix + ")") + ": " + why;
    return;
  }
  result->branch_note = "the branch's prefix, " + prefix +
                        ", re-simulated: " + std::to_string(p.identical) + " of " +
                        std::to_string(p.compared) +
                        " frames identical, word for word; the DCP's state at its end is the "
                        "branch's first state";
}

// `more` after `*notes`, "; " between them; nothing when it is "".
void AddNote(const std::string& more, std::string* notes) {
  if (more.empty()) return;
  if (!notes->empty()) *notes += "; ";
  *notes += more;
}

// "" when the log holds the RMS_DCP_FRAMEs the session's summary counted
// logged (record.by_channel); else what it lacks, said.
std::string LogShorterThanSummary(const nlohmann::json& summary, const Recording& rec) {
  const nlohmann::json* logged = nullptr;
  try {
    logged = &summary.at("record").at("by_channel").at(wire::channels::kDcpFrame).at("logged");
  } catch (const nlohmann::json::exception&) {
    return "";  // a summary without the count (an older session's): nothing to say
  }
  if (!logged->is_number_integer()) return "";
  const std::int64_t counted = logged->get<std::int64_t>();
  const auto held = static_cast<std::int64_t>(rec.dcp_frames.size());
  if (held >= counted) return "";
  return "the log holds " + std::to_string(held) + " of the " + std::to_string(counted) +
         " RMS_DCP_FRAMEs its summary.json counted logged (cut short or changed since): "
         "re-simulated up to DCP frame " +
         std::to_string(rec.dcp_frames.back().frame) +
         ", and the recorded outcome is the whole session's";
}

// The stretches of recorded frames left unchecked after frames lost from
// every source (Plan::unchecked), in words and as the result's list.
void NoteUnchecked(const Recording& rec, const Plan& plan, ResimResult* result) {
  for (const Unchecked& u : plan.unchecked) {
    const long frames = static_cast<long>(u.end - u.begin);
    result->unchecked_frames += frames;
    nlohmann::ordered_json e = {{"lost_from", u.lost_from}, {"lost_to", u.lost_to}, {"why", u.why}};
    std::string where;
    if (frames > 0) {
      const std::int64_t a = rec.dcp_frames[u.begin].frame, b = rec.dcp_frames[u.end - 1].frame;
      e["unchecked_from"] = a;
      e["unchecked_to"] = b;
      e["unchecked_frames"] = frames;
      where = "DCP frames " + std::to_string(a) + ".." + std::to_string(b) + " (" +
              std::to_string(frames) + " recorded) not checked: ";
    }
    const std::string lost =
        u.lost_from == u.lost_to
            ? "DCP frame " + std::to_string(u.lost_from)
            : "DCP frames " + std::to_string(u.lost_from) + ".." + std::to_string(u.lost_to);
    std::string goes_on = "nothing after them was re-simulated (no RMS_DCP_STATE logged later)";
    if (u.end < rec.dcp_frames.size()) {
      e["resumed_at"] = rec.dcp_frames[u.end].frame;
      e["resumed_from_state"] = u.resumed_from;
      goes_on = "re-simulated again from the state logged for DCP frame " +
                std::to_string(u.resumed_from);
      if (u.resumed_from < rec.dcp_frames[u.end].frame)
        goes_on += ", the frames lost after it made again from the logged inputs";
    }
    // With no recorded frame unchecked (a state logged among the lost
    // frames, and the rest made again from it), the lost frames are the subject.
    std::string said = where;
    if (frames > 0) said += "before them, ";
    said.append(lost).append(": ").append(u.why).append("; ");
    if (frames == 0) said += "no recorded frame left unchecked: ";
    said += goes_on;
    AddNote(said, &result->note);
    result->unchecked.push_back(std::move(e));
  }
}

// --until: a frame the re-simulation reaches, with its own design.
void CheckUntil(const Recording& rec, const Plan& plan, const ResimOptions& opt,
                bool other_design) {
  if (other_design)
    throw InputError("--until is for the session's own design (no --config, --set)");
  const std::int64_t first = rec.dcp_frames[plan.first].frame, last = rec.dcp_frames.back().frame;
  if (opt.until_frame < first || opt.until_frame > last) {
    throw InputError(opt.session + " re-simulates DCP frames " + std::to_string(first) + ".." +
                     std::to_string(last) + ": DCP frame " + std::to_string(opt.until_frame) +
                     " is not among them");
  }
}

// Another design: a new session folder with its configuration, ready for the run's log.
std::string OpenNewSession(const ResimOptions& opt, const std::string& config_text,
                           ResimResult* result) {
  result->out_dir = opt.out_dir.empty()
                        ? (fs::path(opt.session).lexically_normal().string() + "-resim")
                        : opt.out_dir;
  session::CreateSessionFolder(result->out_dir);
  WriteWholeFile((fs::path(result->out_dir) / "config.toml").string(), config_text);
  WriteWholeFile((fs::path(result->out_dir) / "run" / "pilot").string(), "resim\n");
  return (fs::path(result->out_dir) / "lcmlog").string();
}

// comparison.md: what changed, and what it did.
std::string ComparisonMarkdown(const fs::path& session, const std::string& config_path,
                               const ResimResult& result) {
  // config_path: where the design came from, with its settings
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

// The sweep's cell (docs/sessions.md "Sweeps"): the outcome against the
// recorded session's (its summary.json, or made now when it has none).
nlohmann::ordered_json CellJson(const nlohmann::json& recorded, const LabConfig& config,
                                const nlohmann::json& summary, const ResimResult& result) {
  nlohmann::ordered_json cell;
  cell["outcome"] = Outcome(summary);
  cell["recorded_outcome"] = Outcome(recorded);
  cell["changes"] = ScorecardChanges(recorded, summary);
  auto at = [&](long frame, const std::string& what) {
    return frame < 0 ? nlohmann::ordered_json(nullptr)
                     : nlohmann::ordered_json{{"frame", frame},
                                              {"time_s", frame / config.session.frame_rate_hz},
                                              {"what", what}};
  };
  // The DCP frame's words (pose, control word, planes, state): its decisions.
  cell["first_divergence"] = at(result.first_decision_frame, result.first_decision);
  // Any output, its telemetry too (the margins to a changed tolerance differ from the first frame).
  cell["first_difference"] = at(result.first_difference_frame, result.first_difference);
  cell["frames_identical"] = result.identical;
  cell["frames_compared"] = result.compared;
  cell["explanation"] = result.comparison["explanation"];
  // What the log lacks or ends in (re-simulated up to there): with the
  // result, so that a sweep's table does not blame the design for it.
  std::string note = result.note;
  AddNote(result.log_note, &note);
  if (!note.empty()) cell["note"] = note;
  return cell;
}

// SHA-256 of a text, 64 hex digits (the manifest's config.sha256, as the
// launcher writes it for a live session).
std::string Sha256Hex(const std::string& text) {
  RMS_CHECK(sodium_init() >= 0);
  unsigned char digest[crypto_hash_sha256_BYTES];
  crypto_hash_sha256(digest, reinterpret_cast<const unsigned char*>(text.data()), text.size());
  char hex[2 * crypto_hash_sha256_BYTES + 1];
  sodium_bin2hex(hex, sizeof hex, digest, sizeof digest);
  return hex;
}

// Another design's session: its manifest (the parent's subject and note go
// with the inputs), summary, comparison.json (result->comparison, with the
// configuration's changes added) and comparison.md.
void WriteNewSession(const RecordedSession& recorded, const std::string& config_path,
                     const std::string& config_text, const LabConfig& config, ResimResult* result) {
  const fs::path dir(result->out_dir), session(recorded.dir());
  session::ManifestFields mf;
  mf.pilot = "re-simulation";
  mf.kind = "re-simulation";
  mf.parent = fs::absolute(session).lexically_normal().string();
  mf.config_source = config_path;
  mf.config_sha256 = Sha256Hex(config_text);
  // Its log's channels carry the recorded session's suffix: its manifest
  // says so, or no reader of it would find them.
  mf.suffix = recorded.recording().suffix;
  if (fs::exists(session / "manifest.json")) {
    try {
      const auto parent = nlohmann::json::parse(
          session::ReadSessionFile(recorded.dir(), "manifest.json", kMaxJsonBytes));
      mf.subject = parent.value("subject", "");
      mf.note = parent.value("note", "");
      // Its log begins as the recorded one's did: a branch's re-simulation
      // is no fresh trial (docs/sessions.md "Compare").
      mf.began_from = session::BeganFrom(parent);
    } catch (const std::exception&) {
    }
  }
  WriteWholeFile((dir / "manifest.json").string(),
                 session::MakeManifest(dir.string(), mf).dump(2) + "\n");
  const nlohmann::ordered_json summary = session::Summarize(dir.string());
  WriteWholeFile((dir / "summary.json").string(), summary.dump(2) + "\n");
  result->comparison["config_changes"] = ConfigChanges(recorded.config_keys(), config_text);
  result->comparison["frames_identical"] = result->identical;
  result->comparison["frames_compared"] = result->compared;
  WriteWholeFile((dir / "comparison.json").string(), result->comparison.dump(2) + "\n");
  WriteWholeFile((dir / "comparison.md").string(),
                 ComparisonMarkdown(session, config_path, *result));
  result->cell = CellJson(recorded.summary(), config, summary, *result);
}

}  // namespace

std::string ConfigSource(const ResimOptions& opt) {
  std::string s = opt.config_path.empty() ? (fs::path(opt.session) / "config.toml").string()
                                          : fs::absolute(opt.config_path).string();
  for (const ConfigSetting& c : opt.settings) s += " --set " + c.key + "=" + c.value;
  return s;
}

bool OtherDesign(const ResimOptions& opt) {
  return !opt.config_path.empty() || !opt.settings.empty();
}

std::string EffectiveConfigText(const ResimOptions& opt) {
  const std::string base =
      opt.config_path.empty() ? (fs::path(opt.session) / "config.toml").string() : opt.config_path;
  // The session's own is read as a folder's file (no link, no FIFO); one
  // the user named with --config as theirs.
  const std::string text =
      opt.config_path.empty()
          ? session::ReadSessionFile(opt.session, "config.toml", kMaxConfigBytes)
          : ReadTextFile(base, "the configuration file");
  return opt.settings.empty() ? text : ApplyConfigSettings(text, base, opt.settings);
}

std::shared_ptr<const RecordedSession> ReadRecordedSession(const std::string& dir) {
  if (!fs::exists(fs::path(dir) / "lcmlog"))
    throw InputError(dir + ": not a session folder (no lcmlog)");
  return std::make_shared<const RecordedSession>(dir, session::SessionLog(dir));
}

namespace {

// A re-simulation that fails leaves no half-made session behind (it would
// refuse the next try): the folder it made goes, or, in a folder given
// that was there, what it wrote (docs/sessions.md "Re-simulation").
constexpr const char* kNewSessionFiles[] = {
    "lcmlog",          "config.toml",   "manifest.json", "summary.json",
    "comparison.json", "comparison.md", "run/pilot",     "stats/dynamics_proc.json"};
struct NewSession {
  fs::path dir;
  bool made_folder = false, done = false;
  std::vector<bool> was_there;         // each of kNewSessionFiles, before: never removed
  std::vector<bool> folder_was_there;  // each of kSessionSubfolders, before
  void Claim(fs::path target) {
    dir = std::move(target);
    made_folder = !fs::exists(dir);
    for (const char* f : kNewSessionFiles) was_there.push_back(fs::exists(dir / f));
    for (const char* f : session::kSessionSubfolders)
      folder_was_there.push_back(fs::exists(dir / f));
  }
  ~NewSession() {
    if (dir.empty() || done) return;
    std::error_code ec;
    if (made_folder) {
      fs::remove_all(dir, ec);
      return;
    }
    for (size_t i = 0; i < was_there.size(); ++i)
      if (!was_there[i]) fs::remove(dir / kNewSessionFiles[i], ec);
    // The folders it made, when empty (fs::remove leaves one that is not).
    for (size_t i = 0; i < folder_was_there.size(); ++i)
      if (!folder_was_there[i]) fs::remove(dir / session::kSessionSubfolders[i], ec);
  }
};

// What the log lacks or holds damaged, and the frames it cannot check,
// said in the result's notes.
void NoteWhatTheLogLacks(const RecordedSession& recorded, bool other_design, ResimResult* result) {
  const Recording& rec = recorded.recording();
  const Plan& plan = recorded.plan();
  if (recorded.unread_bytes() > 0) {
    result->log_note = "the log ends in " + std::to_string(recorded.unread_bytes()) +
                       " bytes that are no whole event (it was cut short or damaged there): "
                       "re-simulated up to them";
  }
  if (recorded.skipped_bytes() > 0) {
    result->log_note += std::string(result->log_note.empty() ? "" : "; ") +
                        "the log is damaged: " + std::to_string(recorded.skipped_bytes()) +
                        " bytes inside it are no event (read past): what they held was not "
                        "checked";
  }
  result->note = plan.note;
  NoteUnchecked(rec, plan, result);
  if (plan.filled_in > 0) {
    result->filled_in = static_cast<long>(plan.filled_in);
    AddNote(std::to_string(plan.filled_in) + " DCP frame(s) between " +
                std::to_string(plan.first_filled_in) + " and " +
                std::to_string(plan.last_filled_in) +
                " are not in the log: made again from the logged inputs they answered, with "
                "nothing to check them against",
            &result->note);
  }
  // Another design is judged against the recorded outcome: a log cut short
  // (or changed) since the session's summary was made holds less than it,
  // and the difference is the log's, not the design's.
  if (other_design) AddNote(LogShorterThanSummary(recorded.summary(), rec), &result->note);
  result->skipped = static_cast<long>(plan.first);
}

}  // namespace

ResimResult Resimulate(const ResimOptions& opt) {
  const auto t0 = Clock::now();
  const fs::path session(opt.session);
  if (!fs::exists(session / "lcmlog"))
    throw InputError(opt.session + ": not a session folder (no lcmlog)");
  const bool other_design = OtherDesign(opt);
  // The session's own design to its end: another core reads half the log
  // and runs half the DCP (docs/sessions.md "Re-simulation"), made first so
  // that its start overlaps the configuration's reading.
  std::optional<OtherCore> other_core;
  std::error_code no_size;
  if (!other_design && opt.until_frame < 0 &&
      fs::file_size(session / "lcmlog", no_size) >= session::SessionLog::kTwoPartsFromBytes &&
      (opt.threads == 2 || (opt.threads == 0 && OtherCore::UsableCpus() >= 2)))
    other_core.emplace(opt.threads == 2);
  OtherCore* other = other_core ? &*other_core : nullptr;
  // A batch's cell (the session read before, its own config with keys set,
  // nothing written) takes the config the session's read parsed once; the
  // text is needed only for a session written.
  const bool batch_cell = opt.recorded && opt.discard && opt.config_path.empty() && other_design;
  const std::string config_path = ConfigSource(opt);
  std::string config_text;
  LabConfig config;
  auto read_config = [&] {
    config_text = batch_cell ? "" : EffectiveConfigText(opt);
    config = batch_cell ? opt.recorded->config_designs().With(opt.settings, config_path)
                        : ParseConfig(config_text, config_path);
  };
  auto progress = [&](double f, const std::string& line) {
    if (opt.progress) opt.progress(f, line);
  };
  // Another design's configuration first; the session's own is read while
  // the other core reads its share of the log (kOtherCoresShare).
  if (other_design) read_config();
  progress(0.0, "reading " + (session / "lcmlog").string());
  std::shared_ptr<const RecordedSession> recorded = opt.recorded;
  if (!other_design) {
    recorded = std::make_shared<const RecordedSession>(
        opt.session, session::SessionLog(opt.session, session::SessionLog::kNoSessionTime),
        session::SessionLog::TwoParts{other, read_config, kOtherCoresShare});
  } else if (!recorded) {
    recorded = ReadRecordedSession(opt.session);
  }
  RMS_CHECK(recorded->dir() == opt.session);
  const Recording& rec = recorded->recording();
  const Plan& plan = recorded->plan();
  const auto t_read = Clock::now();

  ResimResult result;
  NoteWhatTheLogLacks(*recorded, other_design, &result);
  // Another design discarded (a sweep's cell) is made in memory: no session written.
  const bool written = other_design && !opt.discard;
  NewSession new_session;
  std::string out_log;
  if (written) {
    // Claimed before the folder is opened, so that a folder made and then
    // refused goes; a folder refused because it holds a session (the
    // source itself, an earlier re-simulation) keeps every file it had.
    new_session.Claim(opt.out_dir.empty()
                          ? fs::path(fs::path(opt.session).lexically_normal().string() + "-resim")
                          : fs::path(opt.out_dir));
    out_log = OpenNewSession(opt, config_text, &result);
  }
  if (opt.until_frame >= 0) CheckUntil(rec, plan, opt, other_design);
  const Outputs out = RunAndCompare(
      config, rec, plan, {out_log, other_design, opt.until_frame, other, progress}, &result);
  progress(1.0, "done");
  if (!other_design && opt.until_frame < 0) {
    const std::string own = result.first_difference;
    CheckBranchPrefix(session, rec, &result);
    if (!own.empty()) result.first_difference = own;  // the branch's own difference first
  }
  result.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  result.read_seconds = std::chrono::duration<double>(t_read - t0).count();
  result.read_in_two = rec.read_in_two;
  if (!rec.inputs.empty()) {
    result.recorded_seconds =
        (rec.inputs.back().timestamp_us - rec.inputs.front().timestamp_us) / 1e6;
  }
  if (other_design) {
    result.comparison = DesignComparison(recorded->telemetry(), out.telemetry, config,
                                         config.session.frame_rate_hz);
  }
  if (written) {
    WriteNewSession(*recorded, config_path, config_text, config, &result);
    new_session.done = true;
  } else if (other_design) {
    result.cell = CellJson(recorded->summary(), config,
                           session::SummarizeDcpRun(config, out.published), result);
  }
  return result;
}

}  // namespace rms::resim
