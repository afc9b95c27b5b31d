#include "comparison.h"

#include <cstring>
#include <map>
#include <sstream>
#include <toml++/toml.h>
#include <vector>

#include "rms/base/text.h"

namespace rms::resim {

bool SameFrame(const dcp_frame_t& a, const dcp_frame_t& b, std::string* what) {
  auto diff = [&](const char* field, int i) {
    *what = field;
    if (i >= 0) what->append("[").append(std::to_string(i)).append("]");
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

namespace {

// Every key of a TOML file as "a.b.c" -> value text.
void Flatten(const toml::node& n, const std::string& prefix,
             std::map<std::string, std::string>* out) {
  if (const toml::table* t = n.as_table()) {
    for (auto&& [k, v] : *t)
      Flatten(v, prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str()), out);
  } else if (const toml::array* a = n.as_array()) {
    bool tables = !a->empty() && a->front().is_table();
    if (tables) {
      for (std::size_t i = 0; i < a->size(); ++i)
        Flatten(*a->get(i), prefix + "[" + std::to_string(i) + "]", out);
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

}  // namespace

std::optional<ConfigKeys> FlattenConfig(const std::string& toml_text) {
  ConfigKeys keys;
  try {
    Flatten(toml::parse(std::string_view(toml_text)), "", &keys);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return keys;
}

nlohmann::ordered_json ConfigChanges(const std::optional<ConfigKeys>& recorded,
                                     const std::string& now_toml) {
  nlohmann::ordered_json changes = nlohmann::ordered_json::array();
  const std::optional<ConfigKeys> now = FlattenConfig(now_toml);
  if (!recorded || !now) return changes;
  for (const auto& [k, v] : *now) {
    const auto it = recorded->find(k);
    if (it == recorded->end() || it->second != v)
      changes.push_back(
          {{"key", k}, {"recorded", it == recorded->end() ? "" : it->second}, {"now", v}});
  }
  return changes;
}

}  // namespace rms::resim
