#include "narrative.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "rms/base/check.h"
#include "rms/wire/acquisition_conditions.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/dcp_mode.h"

#include "recording.h"

namespace rms::resim {

namespace {

// In increasing order of frame, one a frame: FindFrame looks one up.
using Telemetry = std::vector<dcp_telemetry_t>;

struct Outcome {
  std::int64_t acquired = -1, clear = -1, docked = -1;  // first DCP frame of each (-1: never)
  long held = 0;
  std::int64_t first_collision = -1;
  std::uint32_t first_collision_bits = 0;
};

Outcome OutcomeOf(const Telemetry& tm) {
  Outcome o;
  for (const dcp_telemetry_t& t : tm) {
    const std::int64_t f = t.frame;
    if (t.mode == wire::DcpMode::kExtraction && o.acquired < 0) o.acquired = f;
    if (t.mode == wire::DcpMode::kManoeuvring && o.clear < 0) o.clear = f;
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

// Where point A went apart: the first frame, and the most.
struct Apart {
  std::int64_t first = -1, max_at = -1;
  double max_ft = 0.0;
};
Apart PointAApart(const Telemetry& recorded, const Telemetry& now) {
  Apart a;
  auto r = recorded.begin();  // both in increasing order of frame
  for (const dcp_telemetry_t& t : now) {
    const std::int64_t f = t.frame;
    while (r != recorded.end() && r->frame < f) ++r;
    if (r == recorded.end() || r->frame != f) continue;
    double d2 = 0;
    for (int i = 0; i < 3; ++i) d2 += std::pow(t.p_RoA_R_ft[i] - r->p_RoA_R_ft[i], 2);
    const double d = std::sqrt(d2);
    if (d > 1e-9 && a.first < 0) a.first = f;
    if (d > a.max_ft) {
      a.max_ft = d;
      a.max_at = f;
    }
  }
  return a;
}

// The acquisition conditions that failed in a frame, in words.
std::string FailingConditions(const dcp_telemetry_t& t, const LabConfig& cfg) {
  std::string failing;
  for (int i = 0; i < wire::kNumAcquisitionConditions; ++i) {
    if (t.acquisition_conditions[i]) continue;
    failing += std::string(failing.empty() ? "" : "; ") + "condition " + std::to_string(i + 1) +
               ", " + wire::kAcquisitionConditionNames[i].text;
    if (i == wire::kFingerGapBelowD3Y)
      failing += Fmt(" (gap %.3f ft, D3Y %.3f ft)", t.finger_gap_ft, cfg.dcp.d3y_ft);
    if (i == wire::kPalmWithinTpob)
      failing += Fmt(" (%.3f ft, TPOB %.3f ft)", t.palm_to_bar_ft, cfg.dcp.tpob_ft);
  }
  return failing;
}

std::string ExplainAcquisition(const Outcome& a, const Outcome& b, const Telemetry& now,
                               const LabConfig& cfg, double rate_hz) {
  if (a.acquired >= 0 && b.acquired < 0) {
    std::string s =
        Fmt("No acquisition: at %.1f s, where the recorded session acquired the payload,",
            a.acquired / rate_hz);
    if (const dcp_telemetry_t* t = FindFrame(now, a.acquired)) {
      const std::string failing = FailingConditions(*t, cfg);
      s += " the conditions that failed: " +
           (failing.empty() ? std::string("none (but the slave was held)") : failing) + ".";
    }
    return s;
  }
  if (a.acquired >= 0 && b.acquired >= 0 && a.acquired != b.acquired) {
    return Fmt("Acquired at %.1f s (recorded: %.1f s).", b.acquired / rate_hz,
               a.acquired / rate_hz);
  }
  if (a.acquired < 0 && b.acquired >= 0) {
    return Fmt("Acquired at %.1f s, which the recorded session never did.", b.acquired / rate_hz);
  }
  return "";
}

std::string ExplainDocking(const Outcome& a, const Outcome& b, const Telemetry& now,
                           const LabConfig& cfg, double rate_hz) {
  if (a.docked >= 0 && b.docked < 0) {
    std::string s =
        Fmt("No docking: at %.1f s, where the recorded session docked,", a.docked / rate_hz);
    if (const dcp_telemetry_t* found = FindFrame(now, a.docked)) {
      const dcp_telemetry_t& t = *found;
      s += Fmt(
          " the probe's tip was %.3f ft from the port's centre (at most %.2f ft) and %.2f deg off "
          "its axis "
          "(at most %.2f deg)",
          t.dock_distance_ft, cfg.dcp.dock_distance_ft, t.dock_angle_deg, cfg.dcp.dock_angle_deg);
      s += t.probe_in_envelope ? ", inside the docking envelope."
                               : ", outside the docking envelope.";
    }
    return s;
  }
  if (b.docked >= 0) {
    const dcp_telemetry_t* found = FindFrame(now, b.docked);
    RMS_CHECK(found != nullptr);  // b.docked is one of its frames
    const dcp_telemetry_t& t = *found;
    return Fmt("Docked at %.1f s: %.3f ft, %.3f deg.", b.docked / rate_hz, t.dock_distance_ft,
               t.dock_angle_deg);
  }
  return "";
}

// The outcome, explained by the DCP's own tests at the moments that mattered.
std::vector<std::string> Explain(const Outcome& a, const Outcome& b, const Apart& apart,
                                 const Telemetry& now, const LabConfig& cfg, double rate_hz) {
  std::vector<std::string> why;
  if (apart.first < 0) {
    why.push_back("The end effector went exactly where it went in the recorded session.");
  } else {
    why.push_back(
        Fmt("The same inputs put the end effector elsewhere from %.1f s on (frame %.0f), up to "
            "%.2f ft away "
            "(at %.1f s).",
            apart.first / rate_hz, static_cast<double>(apart.first), apart.max_ft,
            apart.max_at / rate_hz));
  }
  if (std::string s = ExplainAcquisition(a, b, now, cfg, rate_hz); !s.empty()) why.push_back(s);
  if (b.held > a.held) {
    why.push_back(Fmt("The arm was held by collisions for %.0f frames (recorded: %.0f); the first "
                      "at %.1f s: ",
                      static_cast<double>(b.held), static_cast<double>(a.held),
                      b.first_collision / rate_hz) +
                  wire::CollisionNames(b.first_collision_bits) + ".");
  }
  if (a.clear >= 0 && b.acquired >= 0 && b.clear < 0) {
    why.push_back(
        Fmt("The payload never left the cargo bay (the recorded session cleared it at %.1f s).",
            a.clear / rate_hz));
  }
  if (std::string s = ExplainDocking(a, b, now, cfg, rate_hz); !s.empty()) why.push_back(s);
  return why;
}

}  // namespace

nlohmann::ordered_json DesignComparison(const Telemetry& recorded, const Telemetry& now,
                                        const LabConfig& config_now, double rate_hz) {
  const Outcome a = OutcomeOf(recorded), b = OutcomeOf(now);
  auto at = [&](std::int64_t f) -> nlohmann::ordered_json {
    if (f < 0) return nullptr;
    return {{"frame", f}, {"time_s", f / rate_hz}};
  };
  nlohmann::ordered_json j;
  j["recorded"] = {{"acquired", at(a.acquired)},
                   {"clear_of_bay", at(a.clear)},
                   {"docked", at(a.docked)},
                   {"held_frames", a.held}};
  j["resimulated"] = {{"acquired", at(b.acquired)},
                      {"clear_of_bay", at(b.clear)},
                      {"docked", at(b.docked)},
                      {"held_frames", b.held}};
  const Apart apart = PointAApart(recorded, now);
  j["point_A"] = {{"first_frame_apart", apart.first},
                  {"max_apart_ft", apart.max_ft},
                  {"max_at_frame", apart.max_at}};
  j["explanation"] = Explain(a, b, apart, now, config_now, rate_hz);
  return j;
}

}  // namespace rms::resim
