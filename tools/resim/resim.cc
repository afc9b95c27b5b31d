#include "resim.h"

#include "rms/acquisition_conditions.h"

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

#include "dcp_node.h"
#include "sender_check.h"
#include "rms/channels.h"
#include "rms/check.h"
#include "rms/text.h"
#include "rms/collision_bits.h"
#include "rms/config.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/message_io.h"
#include "rms/operator_input_t.hpp"
#include "rms/process.h"
#include "rms/session_control_t.hpp"
#include "rms/version.h"
#include "session_summary.h"

namespace fs = std::filesystem;

namespace rms::resim {

namespace {

struct RecordedInput {
  std::int64_t timestamp_us = 0;
  std::vector<std::uint8_t> bytes;
};

struct Recording {
  std::string suffix;
  std::map<std::int64_t, RecordedInput> inputs;      // by operator frame
  std::vector<dcp_frame_t> dcp_frames;               // in log order
  std::map<std::int64_t, dcp_telemetry_t> telemetry;  // by DCP frame
  // Control commands with the number of DCP frames logged before each.
  std::vector<std::pair<std::size_t, session_control_t>> controls;
};

Recording ReadRecording(const fs::path& log_path) {
  lcm::LogFile log(log_path.string(), "r");
  if (!log.good()) throw InputError("cannot read the session's LCM log '" + log_path.string() + "'");
  Recording r;
  bool have_suffix = false;
  // The session's own messages only (docs/security.md "What the summary trusts").
  session::SenderCheck check(log_path.parent_path().string());
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    const std::string base = session::BaseChannel(ev->channel);
    if (ev->channel.rfind(base, 0) != 0) continue;
    if (check.Ignore(base, ev->data, ev->datalen)) continue;
    if (!have_suffix && base == channels::kOperatorInput) {
      r.suffix = ev->channel.substr(base.size());  // the session's channel suffix
      have_suffix = true;
    }
    if (base == channels::kOperatorInput) {
      operator_input_t m;
      if (SafeDecode(ev->data, ev->datalen, 1024, &m) != DecodeError::kNone) continue;
      const auto* p = static_cast<const std::uint8_t*>(ev->data);
      r.inputs[m.frame] = {ev->timestamp, std::vector<std::uint8_t>(p, p + ev->datalen)};
    } else if (base == channels::kDcpFrame) {
      dcp_frame_t m;
      if (SafeDecode(ev->data, ev->datalen, 4096, &m) == DecodeError::kNone) r.dcp_frames.push_back(m);
    } else if (base == channels::kDcpTelemetry) {
      dcp_telemetry_t m;
      if (SafeDecode(ev->data, ev->datalen, 4096, &m) == DecodeError::kNone) r.telemetry[m.frame] = m;
    } else if (base == channels::kControl) {
      session_control_t m;
      if (SafeDecode(ev->data, ev->datalen, 1 << 16, &m) == DecodeError::kNone) {
        r.controls.emplace_back(r.dcp_frames.size(), m);
      }
    }
  }
  if (r.dcp_frames.empty()) throw InputError(log_path.string() + ": no RMS_DCP_FRAME recorded: nothing to re-simulate");
  // Only the DCP's increasing run of frames, as the summary believes them: a
  // frame forged far ahead or behind is not one the DCP made.
  std::vector<std::int64_t> numbers;
  for (const auto& f : r.dcp_frames) numbers.push_back(f.frame);
  const std::vector<std::size_t> run = session::LongestIncreasingRun(numbers);
  if (run.size() != r.dcp_frames.size()) {
    std::vector<dcp_frame_t> kept;
    for (const std::size_t i : run) kept.push_back(r.dcp_frames[i]);
    // A control command keeps its place: the number of kept frames before it.
    for (auto& [before, m] : r.controls) {
      before = static_cast<std::size_t>(std::lower_bound(run.begin(), run.end(), before) - run.begin());
    }
    r.dcp_frames = std::move(kept);
  }
  return r;
}

// The operator frame each DCP frame answered, in DCP frame order, with DCP
// frames the logger lost filled in where that is unambiguous.
std::vector<std::int64_t> InputSequence(const Recording& r) {
  std::map<std::int64_t, std::int64_t> by_frame;  // DCP frame -> input frame
  for (const auto& f : r.dcp_frames) by_frame[f.frame] = f.input_frame;
  if (by_frame.begin()->first != 0) {
    throw InputError("the log starts at DCP frame " + std::to_string(by_frame.begin()->first) +
                     ": the frames before it, and their inputs, are not in it");
  }
  std::vector<std::int64_t> seq;
  std::int64_t prev_frame = -1, prev_input = -1;
  for (const auto& [frame, input] : by_frame) {
    const std::int64_t lost = frame - prev_frame - 1;
    if (lost > 0) {
      // The DCP answered `lost` inputs between prev_input and input that the
      // log does not show: unambiguous only if exactly that many were logged.
      std::vector<std::int64_t> between;
      for (auto it = r.inputs.upper_bound(prev_input); it != r.inputs.end() && it->first < input; ++it) {
        between.push_back(it->first);
      }
      if (static_cast<std::int64_t>(between.size()) != lost) {
        throw InputError("the log lost DCP frames " + std::to_string(prev_frame + 1) + ".." + std::to_string(frame - 1) +
                         " and which inputs they answered cannot be told: the re-simulation cannot be exact");
      }
      seq.insert(seq.end(), between.begin(), between.end());
    }
    seq.push_back(input);
    prev_frame = frame;
    prev_input = input;
  }
  return seq;
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

std::string Kinds(std::uint32_t bits) {
  std::string s;
  for (int b = 0; b < collision_bits::kCount; ++b) {
    if (bits & (1u << b)) s += std::string(s.empty() ? "" : ", ") + CollisionName(b);
  }
  return s;
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
      for (int i = 0; i < 6; ++i) {
        if (!it->second.acquisition_conditions[i]) {
          failing += std::string(failing.empty() ? "" : "; ") + "condition " + std::to_string(i + 1) + ", " + kAcquisitionConditionNames[i].text;
          if (i == 3) failing += Fmt(" (gap %.3f ft, D3Y %.3f ft)", it->second.finger_gap_ft, cfg_now.dcp.d3y_ft);
          if (i == 4) failing += Fmt(" (%.3f ft, TPOB %.3f ft)", it->second.palm_to_bar_ft, cfg_now.dcp.tpob_ft);
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
                  Kinds(b.first_collision_bits) + ".");
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
  const Recording rec = ReadRecording(session / "lcmlog");
  const std::vector<std::int64_t> seq = InputSequence(rec);
  const auto t_read = std::chrono::steady_clock::now();

  ResimResult result;
  std::string out_log;
  if (other_design) {
    result.out_dir = opt.out_dir.empty() ? (fs::path(opt.session).lexically_normal().string() + "-resim") : opt.out_dir;
    if (fs::exists(fs::path(result.out_dir) / "lcmlog")) throw InputError(result.out_dir + " already holds a session");
    fs::create_directories(fs::path(result.out_dir) / "stats");
    fs::create_directories(fs::path(result.out_dir) / "run");
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
  frames_run.reserve(seq.size());
  telemetry_run.reserve(seq.size());
  {
    LogLcm lcm("", out_log, rec.suffix);
    dcp::DcpNode node(config, &lcm);
    lcm.Subscribe(channels::kDcpFrame, [&](const void* d, int n, std::int64_t) {
      frames_run.emplace_back();
      if (SafeDecode(d, n, 4096, &frames_run.back()) != DecodeError::kNone) frames_run.pop_back();
    });
    lcm.Subscribe(channels::kDcpTelemetry, [&](const void* d, int n, std::int64_t) {
      telemetry_run.emplace_back();
      if (SafeDecode(d, n, 4096, &telemetry_run.back()) != DecodeError::kNone) telemetry_run.pop_back();
    });
    std::size_t next_control = 0;
    CheckpointRateLimit restore_rate;
    const auto t_run = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < seq.size(); ++k) {
      // Restores the live DCP applied before this frame (checkpoints it
      // saved and freezes change nothing here).
      while (next_control < rec.controls.size() && rec.controls[next_control].first <= k) {
        const session_control_t& c = rec.controls[next_control++].second;
        if (c.command == session_control_t::RESTORE && restore_rate.Allow(c.send_time_us)) {
          // As the live DCP did: the named checkpoint in the session's
          // folder, at its rate; one it could not read changed nothing.
          const CheckpointFolder folder((session / "checkpoints").string());
          try {
            node.Restore(folder.Read(c.name), folder.PathOf(c.name));
          } catch (const InputError& e) {
            progress(static_cast<double>(k) / seq.size(), std::string("a restore the live DCP refused too: ") + e.what());
          }
        }
      }
      const auto it = rec.inputs.find(seq[k]);
      if (it == rec.inputs.end()) {
        throw InputError("operator frame " + std::to_string(seq[k]) + ", which DCP frame " + std::to_string(k) +
                         " answered, is not in the log: the re-simulation cannot be exact");
      }
      lcm.SetNowUs(it->second.timestamp_us);
      lcm.Publish(channels::kOperatorInput, it->second.bytes.data(), static_cast<int>(it->second.bytes.size()));
      lcm.HandleSubscriptions(0);  // the input to the DCP
      lcm.HandleSubscriptions(0);  // its outputs to the comparison
      if (seq.size() >= 20 && k % (seq.size() / 20) == 0) {
        progress(static_cast<double>(k) / seq.size(), std::to_string(k) + " of " + std::to_string(seq.size()) + " frames");
      }
    }
    result.run_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_run).count();
    for (auto& f : frames_run) frames[f.frame] = std::move(f);
    for (auto& t : telemetry_run) telemetry[t.frame] = std::move(t);
    result.frames = static_cast<long>(frames.size());
    if (other_design) {
      WriteStatsJson((fs::path(result.out_dir) / "stats" / "dynamics_proc.json").string(), "dynamics_proc",
                     node.counters(), node.latencies());
    }
  }
  progress(1.0, std::to_string(seq.size()) + " of " + std::to_string(seq.size()) + " frames");

  // Word for word against the recording.
  for (const dcp_frame_t& r : rec.dcp_frames) {
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
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  result.read_seconds = std::chrono::duration<double>(t_read - t0).count();
  if (!rec.inputs.empty()) {
    result.recorded_seconds =
        (rec.inputs.rbegin()->second.timestamp_us - rec.inputs.begin()->second.timestamp_us) / 1e6;
  }

  if (other_design) {
    const fs::path out(result.out_dir);
    nlohmann::ordered_json manifest;
    manifest["format"] = "rmslab-session-1";
    manifest["kind"] = "re-simulation";
    manifest["resimulation_of"] = fs::absolute(session).lexically_normal().string();
    manifest["config"] = {{"file", "config.toml"}, {"source", fs::absolute(config_path).string()}};
    manifest["software"] = {{"version", VersionString()}, {"describe", Version().describe}, {"commit", Version().commit}};
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
