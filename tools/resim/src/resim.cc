#include "rms/resim/resim.h"

#include "rms/wire/acquisition_conditions.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <optional>
#include <sstream>
#include <toml++/toml.h>

#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/wire/checkpoint.h"
#include "rms/dcp_state_t.hpp"
#include "rms/wire/channels.h"
#include "rms/base/check.h"
#include "rms/base/text.h"
#include "rms/wire/collision_bits.h"
#include "rms/base/config.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/wire/message_io.h"
#include "rms/operator_input_t.hpp"
#include "rms/transport/process.h"
#include "rms/session_control_t.hpp"
#include "rms/base/version.h"
#include "rms/session/session_folder.h"
#include "rms/session/session_log.h"
#include "rms/session/session_summary.h"

namespace fs = std::filesystem;

namespace rms::resim {

namespace {

struct RecordedInput {
  std::int64_t timestamp_us = 0;
  std::vector<std::uint8_t> bytes;
};

// An RMS_DCP_STATE as logged, with the number of the DCP's (believed)
// frames logged before it: its place among them.
struct LoggedState {
  std::size_t before = 0;
  dcp_state_t m;
};

struct Recording {
  std::string suffix;
  std::map<std::int64_t, RecordedInput> inputs;      // by operator frame
  std::vector<dcp_frame_t> dcp_frames;               // in log order
  std::map<std::int64_t, dcp_telemetry_t> telemetry;  // by DCP frame
  std::vector<LoggedState> states;                   // in log order
};

Recording ReadRecording(session::SessionLog& log) {
  Recording r;
  r.suffix = log.suffix();
  log.Read({wire::channels::kOperatorInput, wire::channels::kDcpFrame, wire::channels::kDcpTelemetry, wire::channels::kDcpState},
           [&](const session::LogMessage& ev) {
             if (ev.base == wire::channels::kOperatorInput) {
               operator_input_t m;
               if (!log.Decode(ev, &m)) return;
               const auto* p = static_cast<const std::uint8_t*>(ev.data);
               r.inputs[m.frame] = {ev.log_us, std::vector<std::uint8_t>(p, p + ev.size)};
             } else if (ev.base == wire::channels::kDcpFrame) {
               dcp_frame_t m;
               if (log.Decode(ev, &m)) r.dcp_frames.push_back(m);
             } else if (ev.base == wire::channels::kDcpTelemetry) {
               dcp_telemetry_t m;
               if (log.Decode(ev, &m)) r.telemetry[m.frame] = m;
             } else {
               LoggedState st;
               st.before = r.dcp_frames.size();
               if (log.Decode(ev, &st.m)) r.states.push_back(std::move(st));
             }
           });
  if (r.dcp_frames.empty()) {
    throw InputError(log.log_path() + ": no RMS_DCP_FRAME recorded: nothing to re-simulate");
  }
  // Only the DCP's increasing run of frames, as the summary believes them: a
  // frame forged far ahead or behind is not one the DCP made.
  std::vector<std::int64_t> numbers;
  for (const auto& f : r.dcp_frames) numbers.push_back(f.frame);
  const std::vector<std::size_t> run = session::LongestIncreasingRun(numbers);
  if (run.size() != r.dcp_frames.size()) {
    std::vector<dcp_frame_t> kept;
    for (const std::size_t i : run) kept.push_back(r.dcp_frames[i]);
    // A state keeps its place: the number of kept frames before it.
    for (auto& st : r.states) {
      st.before = static_cast<std::size_t>(std::lower_bound(run.begin(), run.end(), st.before) - run.begin());
    }
    r.dcp_frames = std::move(kept);
  }
  return r;
}

// What the re-simulation does, step by step: a logged state to take (or,
// PERIODIC, to check against), then an operator frame to answer.
struct Step {
  const dcp_state_t* state = nullptr;
  std::int64_t input_frame = -1;  // -1: a state only
  bool first = false;             // the state the re-simulation starts from (taken, whatever its reason)
};

struct Plan {
  std::vector<Step> steps;
  std::size_t first = 0;  // the index of the first recorded DCP frame re-simulated
  std::string note;       // what the log lacks, when it does not start at the session's start
};

std::string Frames(std::int64_t a, std::int64_t b) {
  return a == b ? "DCP frame " + std::to_string(a) : "DCP frames " + std::to_string(a) + ".." + std::to_string(b);
}

// Where the re-simulation can start: the state logged before the first
// frame (the DCP sends it at start and until its first frame), or, when the
// log begins later, the first state logged (every 5 s of frames); a log from
// frame 0 with no state at all (recorded before RMS_DCP_STATE) starts from
// the initial state.
const LoggedState* StartState(const Recording& r, Plan* plan) {
  const LoggedState* start = nullptr;
  for (const LoggedState& st : r.states) {
    if (st.before == 0) start = &st;
  }
  if (start) return start;
  const std::int64_t first = r.dcp_frames.front().frame;
  if (r.states.empty()) {
    if (first == 0) return nullptr;
    throw InputError("the log starts at DCP frame " + std::to_string(first) +
                     " and holds no RMS_DCP_STATE: the DCP's state there is not in it (the log misses the "
                     "session's start, and was recorded before the DCP logged its state), so nothing can be "
                     "re-simulated");
  }
  start = &r.states.front();
  if (start->before >= r.dcp_frames.size()) {
    throw InputError("the log's only RMS_DCP_STATE comes after its last DCP frame: nothing to re-simulate from");
  }
  plan->first = start->before;
  const std::int64_t skipped_to = r.dcp_frames[plan->first].frame - 1;
  plan->note = Frames(first, skipped_to) + " not re-simulated: the log starts at DCP frame " + std::to_string(first) +
               " without the DCP's state there; re-simulated from the state it logged before DCP frame " +
               std::to_string(r.dcp_frames[plan->first].frame);
  return start;
}

// The operator frame each DCP frame answered, in DCP frame order, with the
// logged states in their places, and DCP frames the recorder lost filled in
// where that is unambiguous.
Plan MakePlan(const Recording& r) {
  Plan plan;
  const LoggedState* start = StartState(r, &plan);
  std::int64_t prev_frame = -1, prev_input = -1;
  bool pending_resume = false;
  // Where a state leaves the numbering: the next frame's, or (a resumed
  // process) the first frame after it sets it.
  auto take = [&](const dcp_state_t& m, bool first) {
    plan.steps.push_back({&m, -1, first});
    if (m.reason == dcp_state_t::PERIODIC && !first) return;
    pending_resume = m.resume_pending;
    prev_frame = m.next_frame - 1;
    prev_input = m.input_frame;
  };
  if (start) take(start->m, true);
  std::size_t next_state = start ? static_cast<std::size_t>(start - r.states.data()) + 1 : 0;
  for (std::size_t k = plan.first; k < r.dcp_frames.size(); ++k) {
    for (; next_state < r.states.size() && r.states[next_state].before <= k; ++next_state) {
      if (r.states[next_state].before == k) take(r.states[next_state].m, false);
    }
    const dcp_frame_t& f = r.dcp_frames[k];
    if (pending_resume) {  // the first frame after a resume: nothing between was made
      prev_frame = f.frame - 1;
      pending_resume = false;
    }
    const std::int64_t lost = f.frame - prev_frame - 1;
    if (lost > 0) {
      // The DCP answered `lost` inputs between prev_input and this frame's
      // that the log does not show: unambiguous only if exactly that many
      // were logged.
      std::vector<std::int64_t> between;
      for (auto it = r.inputs.upper_bound(prev_input); it != r.inputs.end() && it->first < f.input_frame; ++it) {
        between.push_back(it->first);
      }
      if (static_cast<std::int64_t>(between.size()) != lost) {
        throw InputError("the log lost " + Frames(prev_frame + 1, f.frame - 1) +
                         " and which operator frames they answered cannot be told (" + std::to_string(between.size()) +
                         " logged between): the re-simulation cannot be exact");
      }
      for (const std::int64_t in : between) plan.steps.push_back({nullptr, in, false});
    } else if (lost < 0) {
      throw InputError("DCP frame " + std::to_string(f.frame) + " follows " + Frames(prev_frame, prev_frame) +
                       " with no RMS_DCP_STATE between to say why: the log cannot be re-simulated");
    }
    plan.steps.push_back({nullptr, f.input_frame, false});
    prev_frame = f.frame;
    prev_input = f.input_frame;
  }
  return plan;
}

bool SameFrame(const dcp_frame_t& a, const dcp_frame_t& b, std::string* what) {
  auto diff = [&](const char* field, int i) {
    *what = std::string(field) + (i >= 0 ? "[" + std::to_string(i) + "]" : "");
    return false;
  };
  if (a.frame != b.frame) return diff("frame", -1);
  if (a.input_frame != b.input_frame) return diff("input_frame", -1);
  if (a.input_send_time_us != b.input_send_time_us) return diff("input_send_time_us", -1);
  for (int i = 0; i < 12; ++i) {
    if (a.arm_words[i] != b.arm_words[i]) return diff("arm_words", i);
  }
  if (a.control_word != b.control_word) return diff("control_word", -1);
  for (int i = 0; i < 12; ++i) {
    if (a.plane_words[i] != b.plane_words[i]) return diff("plane_words", i);
  }
  if (a.plane_status != b.plane_status) return diff("plane_status", -1);
  for (int i = 0; i < 17; ++i) {
    if (a.state_words[i] != b.state_words[i]) return diff("state_words", i);
  }
  return true;
}

bool SameTelemetry(dcp_telemetry_t a, dcp_telemetry_t b, std::string* what) {
  // Everything but the wall-clock send time and the sender (a re-simulation
  // is another process), field for field: the message's encoding with those
  // equalised compares every bit of every other field.
  a.send_time_us = b.send_time_us = 0;
  a.sender = b.sender = sender_t{};
  std::vector<std::uint8_t> ea(a.getEncodedSize()), eb(b.getEncodedSize());
  a.encode(ea.data(), 0, static_cast<int>(ea.size()));
  b.encode(eb.data(), 0, static_cast<int>(eb.size()));
  if (ea == eb) return true;
  *what = "telemetry";
  return false;
}

// Every key of a TOML file as "a.b.c" -> value text.
void Flatten(const toml::node& n, const std::string& prefix, std::map<std::string, std::string>* out) {
  if (const toml::table* t = n.as_table()) {
    for (auto&& [k, v] : *t) Flatten(v, prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str()), out);
  } else if (const toml::array* a = n.as_array()) {
    bool tables = !a->empty() && a->front().is_table();
    if (tables) {
      for (std::size_t i = 0; i < a->size(); ++i) Flatten(*a->get(i), prefix + "[" + std::to_string(i) + "]", out);
    } else {
      std::ostringstream os;
      os << *a;
      (*out)[prefix] = os.str();
    }
  } else if (const auto* d = n.as_floating_point()) {
    (*out)[prefix] = HumanNumber(d->get(), 9);  // 0.6, not 0.59999999999999998
  } else {
    std::ostringstream os;
    n.visit([&](auto&& v) { os << v; });
    (*out)[prefix] = os.str();
  }
}

nlohmann::ordered_json ConfigChanges(const std::string& a_path, const std::string& b_path) {
  nlohmann::ordered_json changes = nlohmann::ordered_json::array();
  std::map<std::string, std::string> a, b;
  try {
    Flatten(toml::parse_file(a_path), "", &a);
    Flatten(toml::parse_file(b_path), "", &b);
  } catch (const std::exception&) {
    return changes;
  }
  for (const auto& [k, v] : b) {
    const auto it = a.find(k);
    if (it == a.end() || it->second != v) changes.push_back({{"key", k}, {"recorded", it == a.end() ? "" : it->second}, {"now", v}});
  }
  return changes;
}

struct Outcome {
  std::int64_t acquired = -1, clear = -1, docked = -1;  // first DCP frame of each (-1: never)
  long held = 0;
  std::int64_t first_collision = -1;
  std::uint32_t first_collision_bits = 0;
};

Outcome OutcomeOf(const std::map<std::int64_t, dcp_telemetry_t>& tm) {
  Outcome o;
  for (const auto& [f, t] : tm) {
    if (t.mode == 2 && o.acquired < 0) o.acquired = f;
    if (t.mode == 3 && o.clear < 0) o.clear = f;
    if (t.docked && o.docked < 0) o.docked = f;
    if (t.held) {
      ++o.held;
      if (o.first_collision < 0) {
        o.first_collision = f;
        o.first_collision_bits = static_cast<std::uint32_t>(t.collisions);
      }
    }
  }
  return o;
}

std::string Fmt(const char* f, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}

nlohmann::ordered_json Compare(const Recording& rec, const std::map<std::int64_t, dcp_telemetry_t>& now,
                               const LabConfig& cfg_now, double rate_hz) {
  const Outcome a = OutcomeOf(rec.telemetry), b = OutcomeOf(now);
  auto at = [&](std::int64_t f) -> nlohmann::ordered_json {
    if (f < 0) return nullptr;
    return {{"frame", f}, {"time_s", f / rate_hz}};
  };
  nlohmann::ordered_json j;
  j["recorded"] = {{"acquired", at(a.acquired)}, {"clear_of_bay", at(a.clear)}, {"docked", at(a.docked)},
                   {"held_frames", a.held}};
  j["resimulated"] = {{"acquired", at(b.acquired)}, {"clear_of_bay", at(b.clear)}, {"docked", at(b.docked)},
                      {"held_frames", b.held}};
  // Where the end effector went apart: point A, recorded against now.
  double max_ft = 0.0;
  std::int64_t max_at = -1, first_apart = -1;
  for (const auto& [f, t] : now) {
    const auto it = rec.telemetry.find(f);
    if (it == rec.telemetry.end()) continue;
    double d2 = 0;
    for (int i = 0; i < 3; ++i) d2 += std::pow(t.p_RoA_R_ft[i] - it->second.p_RoA_R_ft[i], 2);
    const double d = std::sqrt(d2);
    if (d > 1e-9 && first_apart < 0) first_apart = f;
    if (d > max_ft) {
      max_ft = d;
      max_at = f;
    }
  }
  j["point_A"] = {{"first_frame_apart", first_apart}, {"max_apart_ft", max_ft}, {"max_at_frame", max_at}};

  // The outcome, explained by the DCP's own tests at the moments that mattered.
  std::vector<std::string> why;
  if (first_apart < 0) {
    why.push_back("The end effector went exactly where it went in the recorded session.");
  } else {
    why.push_back(Fmt("The same inputs put the end effector elsewhere from %.1f s on (frame %.0f), up to %.2f ft away "
                      "(at %.1f s).",
                      first_apart / rate_hz, static_cast<double>(first_apart), max_ft, max_at / rate_hz));
  }
  if (a.acquired >= 0 && b.acquired < 0) {
    std::string s = Fmt("No acquisition: at %.1f s, where the recorded session acquired the payload,", a.acquired / rate_hz);
    const auto it = now.find(a.acquired);
    if (it != now.end()) {
      std::string failing;
      for (int i = 0; i < wire::kNumAcquisitionConditions; ++i) {
        if (!it->second.acquisition_conditions[i]) {
          failing += std::string(failing.empty() ? "" : "; ") + "condition " + std::to_string(i + 1) + ", " + wire::kAcquisitionConditionNames[i].text;
          if (i == wire::kFingerGapBelowD3Y) failing += Fmt(" (gap %.3f ft, D3Y %.3f ft)", it->second.finger_gap_ft, cfg_now.dcp.d3y_ft);
          if (i == wire::kPalmWithinTpob) failing += Fmt(" (%.3f ft, TPOB %.3f ft)", it->second.palm_to_bar_ft, cfg_now.dcp.tpob_ft);
        }
      }
      s += " the conditions that failed: " + (failing.empty() ? std::string("none (but the slave was held)") : failing) + ".";
    }
    why.push_back(s);
  } else if (a.acquired >= 0 && b.acquired >= 0 && a.acquired != b.acquired) {
    why.push_back(Fmt("Acquired at %.1f s (recorded: %.1f s).", b.acquired / rate_hz, a.acquired / rate_hz));
  } else if (a.acquired < 0 && b.acquired >= 0) {
    why.push_back(Fmt("Acquired at %.1f s, which the recorded session never did.", b.acquired / rate_hz));
  }
  if (b.held > a.held) {
    why.push_back(Fmt("The arm was held by collisions for %.0f frames (recorded: %.0f); the first at %.1f s: ",
                      static_cast<double>(b.held), static_cast<double>(a.held), b.first_collision / rate_hz) +
                  wire::CollisionNames(b.first_collision_bits) + ".");
  }
  if (a.clear >= 0 && b.acquired >= 0 && b.clear < 0) {
    why.push_back(Fmt("The payload never left the cargo bay (the recorded session cleared it at %.1f s).", a.clear / rate_hz));
  }
  if (a.docked >= 0 && b.docked < 0) {
    std::string s = Fmt("No docking: at %.1f s, where the recorded session docked,", a.docked / rate_hz);
    const auto it = now.find(a.docked);
    if (it != now.end()) {
      const auto& t = it->second;
      s += Fmt(" the probe's tip was %.3f ft from the port's centre (at most %.2f ft) and %.2f deg off its axis "
               "(at most %.2f deg)",
               t.dock_distance_ft, cfg_now.dcp.dock_distance_ft, t.dock_angle_deg, cfg_now.dcp.dock_angle_deg);
      s += t.probe_in_envelope ? ", inside the docking envelope." : ", outside the docking envelope.";
    }
    why.push_back(s);
  } else if (b.docked >= 0) {
    const auto& t = now.at(b.docked);
    why.push_back(Fmt("Docked at %.1f s: %.3f ft, %.3f deg.", b.docked / rate_hz, t.dock_distance_ft, t.dock_angle_deg));
  }
  j["explanation"] = why;
  return j;
}

// A logged state: a restore, a resume or a start is taken as the live DCP
// took it (another design keeps its own state at a resume: only the
// numbering); a periodic one is checked against the re-simulated state
// (the same design only: another one is expected to differ).
void TakeState(const dcp_state_t& m, bool first, bool other_design, dynamics_proc::DynamicsProc* node, ResimResult* result) {
  if (m.reason == dcp_state_t::PERIODIC && !first) {
    if (other_design || !result->state_difference.empty()) return;
    ++result->states_checked;
    const wire::Checkpoint logged = wire::ParseCheckpoint(m.checkpoint, "RMS_DCP_STATE");
    if (logged.dcp != node->MakeCheckpoint().dcp) {
      result->state_difference = "the DCP's state before DCP frame " + std::to_string(m.next_frame) +
                                 " differs from the state it logged there";
    }
    return;
  }
  node->ApplyState(m, first || !(other_design && m.reason == dcp_state_t::RESUME));
  ++result->states_taken;
  // Into the new session's log too, so it can be re-simulated and its
  // summary sees the same restores (its attempts).
  node->PublishState(m.reason == dcp_state_t::PERIODIC ? dcp_state_t::START : m.reason);
}

}  // namespace

ResimResult Resimulate(const ResimOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path session(opt.session);
  if (!fs::exists(session / "lcmlog")) throw InputError(opt.session + ": not a session folder (no lcmlog)");
  const bool other_design = !opt.config_path.empty();
  const std::string config_path = other_design ? opt.config_path : (session / "config.toml").string();
  const LabConfig config = LoadConfig(config_path);
  auto progress = [&](double f, const std::string& line) {
    if (opt.progress) opt.progress(f, line);
  };
  progress(0.0, "reading " + (session / "lcmlog").string());
  session::SessionLog log(opt.session);
  const Recording rec = ReadRecording(log);
  const Plan plan = MakePlan(rec);
  const auto t_read = std::chrono::steady_clock::now();

  ResimResult result;
  if (log.unread_bytes() > 0) {
    result.log_note = "the log ends in " + std::to_string(log.unread_bytes()) +
                      " bytes that are no whole event (it was cut short or damaged there): re-simulated up to them";
  }
  result.note = plan.note;
  result.skipped = static_cast<long>(plan.first);
  std::string out_log;
  if (other_design) {
    result.out_dir = opt.out_dir.empty() ? (fs::path(opt.session).lexically_normal().string() + "-resim") : opt.out_dir;
    session::CreateSessionFolder(result.out_dir);
    fs::copy_file(config_path, fs::path(result.out_dir) / "config.toml", fs::copy_options::overwrite_existing);
    WriteWholeFile((fs::path(result.out_dir) / "run" / "pilot").string(), "resim\n");
    out_log = (fs::path(result.out_dir) / "lcmlog").string();
  }

  std::map<std::int64_t, dcp_frame_t> frames;
  std::map<std::int64_t, dcp_telemetry_t> telemetry;
  // During the run the outputs are appended to vectors reserved up front (no
  // allocation a frame); the maps the comparison looks them up in are built
  // after it.
  std::vector<dcp_frame_t> frames_run;
  std::vector<dcp_telemetry_t> telemetry_run;
  frames_run.reserve(plan.steps.size());
  telemetry_run.reserve(plan.steps.size());
  {
    transport::LogLcm lcm("", out_log, rec.suffix);
    dynamics_proc::DynamicsProc node(config, &lcm);
    lcm.Subscribe(wire::channels::kDcpFrame, [&](const void* d, int n, std::int64_t) {
      frames_run.emplace_back();
      if (wire::SafeDecode(d, n, &frames_run.back()) != wire::DecodeError::kNone) frames_run.pop_back();
    });
    lcm.Subscribe(wire::channels::kDcpTelemetry, [&](const void* d, int n, std::int64_t) {
      telemetry_run.emplace_back();
      if (wire::SafeDecode(d, n, &telemetry_run.back()) != wire::DecodeError::kNone) telemetry_run.pop_back();
    });
    const auto t_run = std::chrono::steady_clock::now();
    const std::size_t n = plan.steps.size();
    for (std::size_t k = 0; k < n; ++k) {
      const Step& step = plan.steps[k];
      if (step.state) {
        TakeState(*step.state, step.first, other_design, &node, &result);
        continue;
      }
      const auto it = rec.inputs.find(step.input_frame);
      if (it == rec.inputs.end()) {
        throw InputError("operator frame " + std::to_string(step.input_frame) +
                         ", which the DCP answered, is not in the log: the re-simulation cannot be exact");
      }
      lcm.SetNowUs(it->second.timestamp_us);
      lcm.Publish(wire::channels::kOperatorInput, it->second.bytes.data(), static_cast<int>(it->second.bytes.size()));
      lcm.HandleSubscriptions(0);  // the input to the DCP
      lcm.HandleSubscriptions(0);  // its outputs to the comparison
      if (n >= 20 && k % (n / 20) == 0) {
        progress(static_cast<double>(k) / n, std::to_string(k) + " of " + std::to_string(n) + " steps");
      }
    }
    result.run_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_run).count();
    for (auto& f : frames_run) frames[f.frame] = std::move(f);
    for (auto& t : telemetry_run) telemetry[t.frame] = std::move(t);
    result.frames = static_cast<long>(frames.size());
    if (other_design) {
      transport::WriteStatsJson((fs::path(result.out_dir) / "stats" / "dynamics_proc.json").string(), "dynamics_proc",
                     node.counters(), node.latencies());
    }
  }
  progress(1.0, "done");

  // Word for word against the recording.
  for (std::size_t i = plan.first; i < rec.dcp_frames.size(); ++i) {
    const dcp_frame_t& r = rec.dcp_frames[i];
    ++result.compared;
    const auto it = frames.find(r.frame);
    std::string what;
    bool same = it != frames.end() && SameFrame(it->second, r, &what);
    if (same) {
      const auto rt = rec.telemetry.find(r.frame);
      const auto nt = telemetry.find(r.frame);
      if (rt != rec.telemetry.end() && nt != telemetry.end()) same = SameTelemetry(nt->second, rt->second, &what);
    } else if (it == frames.end()) {
      what = "missing";
    }
    if (same) ++result.identical;
    else if (result.first_difference.empty()) result.first_difference = "DCP frame " + std::to_string(r.frame) + ": " + what;
  }
  if (result.first_difference.empty() && !result.state_difference.empty()) {
    result.first_difference = result.state_difference;
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  result.read_seconds = std::chrono::duration<double>(t_read - t0).count();
  if (!rec.inputs.empty()) {
    result.recorded_seconds =
        (rec.inputs.rbegin()->second.timestamp_us - rec.inputs.begin()->second.timestamp_us) / 1e6;
  }

  if (other_design) {
    const fs::path out(result.out_dir);
    session::ManifestFields mf;
    mf.pilot = "resim";
    mf.kind = "re-simulation";
    mf.parent = fs::absolute(session).lexically_normal().string();
    mf.config_source = fs::absolute(config_path).string();
    if (fs::exists(session / "manifest.json")) {
      try {  // the subject and the note go with the inputs
        const auto parent = nlohmann::json::parse(std::ifstream((session / "manifest.json").string()));
        mf.subject = parent.value("subject", "");
        mf.note = parent.value("note", "");
      } catch (const std::exception&) {
      }
    }
    const nlohmann::ordered_json manifest = session::MakeManifest(out.string(), mf);
    WriteWholeFile((out / "manifest.json").string(), manifest.dump(2) + "\n");
    WriteWholeFile((out / "summary.json").string(), session::Summarize(out.string()).dump(2) + "\n");
    result.comparison = Compare(rec, telemetry, config, config.session.frame_rate_hz);
    result.comparison["config_changes"] = ConfigChanges((session / "config.toml").string(), config_path);
    result.comparison["frames_identical"] = result.identical;
    result.comparison["frames_compared"] = result.compared;
    WriteWholeFile((out / "comparison.json").string(), result.comparison.dump(2) + "\n");
    std::ostringstream md;
    md << "# Re-simulation of " << fs::absolute(session).lexically_normal().string() << "\n\n";
    md << "The recorded operator inputs, flown again with `" << config_path << "`.\n\n## What changed\n\n";
    for (const auto& c : result.comparison["config_changes"]) {
      md << "- `" << c["key"].get<std::string>() << "`: " << c["recorded"].get<std::string>() << " -> "
         << c["now"].get<std::string>() << "\n";
    }
    md << "\n## What it did\n\n";
    for (const auto& s : result.comparison["explanation"]) md << "- " << s.get<std::string>() << "\n";
    md << "\n" << result.identical << " of " << result.compared << " DCP frames identical to the recording.\n";
    WriteWholeFile((out / "comparison.md").string(), md.str());
  }
  return result;
}

}  // namespace rms::resim
