#include "outcome.h"

#include <map>
#include <string>

namespace rms::resim {

namespace {

// The summary's result attempt, or an empty object.
nlohmann::json ResultAttempt(const nlohmann::json& summary) {
  const auto& attempts = summary.value("attempts", nlohmann::json::array());
  // null when the session had no attempt (no DCP frame it believed)
  const nlohmann::json& r =
      summary.contains("result_attempt") ? summary["result_attempt"] : nlohmann::json();
  const long i = r.is_number_integer() ? r.get<long>() : 0;
  if (i >= 1 && i <= static_cast<long>(attempts.size())) return attempts[i - 1];
  return nlohmann::json::object();
}

nlohmann::json Get(const nlohmann::json& j, const char* key) {
  return j.is_object() && j.contains(key) ? j[key] : nlohmann::json(nullptr);
}

// Every leaf number, bool and null as "a.b.c" -> value (strings and arrays left out).
void Leaves(const nlohmann::json& j, const std::string& prefix,
            std::map<std::string, nlohmann::json>* out) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) {
      std::string key = prefix;
      if (!key.empty()) key += '.';
      key += k;
      Leaves(v, key, out);
    }
  } else if (j.is_number() || j.is_boolean() || j.is_null()) {
    (*out)[prefix] = j;
  }
}

}  // namespace

nlohmann::ordered_json Outcome(const nlohmann::json& summary) {
  const nlohmann::json a = ResultAttempt(summary);
  const nlohmann::json reached = Get(a, "reached_s");
  const nlohmann::json docking = Get(summary, "docking");
  nlohmann::ordered_json o;
  o["acquired"] = summary.value("acquired", false);
  o["docked"] = summary.value("docked", false);
  o["final_mode"] = Get(summary, "final_mode");
  o["reached_s"] = {{"acquired", Get(reached, "acquired")},
                    {"clear_of_bay", Get(reached, "clear_of_bay")},
                    {"docked", Get(reached, "docked")}};
  o["phase_durations_s"] = Get(summary, "phase_durations_s");
  o["collisions"] = Get(Get(summary, "totals"), "collisions");
  o["held_frames"] = Get(summary, "held_frames");
  o["docking"] = docking.is_object()
                     ? nlohmann::ordered_json{{"distance_ft", docking["distance_ft"]},
                                              {"angle_deg", docking["angle_deg"]}}
                     : nlohmann::ordered_json(nullptr);
  return o;
}

nlohmann::ordered_json ScorecardChanges(const nlohmann::json& recorded_summary,
                                        const nlohmann::json& now_summary) {
  std::map<std::string, nlohmann::json> was, now;
  Leaves(nlohmann::json(Outcome(recorded_summary)), "", &was);
  Leaves(nlohmann::json(Outcome(now_summary)), "", &now);
  Leaves(Get(ResultAttempt(recorded_summary), "scorecard"), "scorecard", &was);
  Leaves(Get(ResultAttempt(now_summary), "scorecard"), "scorecard", &now);
  for (const auto& [k, v] : was) now.emplace(k, nullptr);  // a figure only one has
  nlohmann::ordered_json changes = nlohmann::ordered_json::array();
  for (const auto& [k, v] : now) {
    const auto it = was.find(k);
    const nlohmann::json before = it == was.end() ? nlohmann::json(nullptr) : it->second;
    if (before != v) changes.push_back({{"field", k}, {"recorded", before}, {"now", v}});
  }
  return changes;
}

}  // namespace rms::resim
