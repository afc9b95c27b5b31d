#include "rms/wire/malfunction.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <vector>

#include "rms/base/check.h"

namespace rms::wire {

namespace {

constexpr const char* kMalfunctionGrammar =
    "'joint N stuck', 'joint N drift DEG_S', 'joint N slow DEG_S', 'finger jammed open', "
    "'finger jammed closed', 'camera N lost' or 'inputs delayed MS' (joints 1..6, cameras 1..8)";
constexpr const char* kRepairGrammar =
    "'joint N', 'finger', 'camera N', 'inputs' or 'all' (joints 1..6, cameras 1..8)";

std::vector<std::string> Words(std::string_view text) {
  std::vector<std::string> words;
  std::istringstream in{std::string(text)};
  for (std::string w; in >> w;) {
    for (char& c : w) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    words.push_back(w);
  }
  return words;
}

// Control characters shown as '?' (an error message is printed and sent).
std::string Printable(std::string s) {
  for (char& c : s) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = '?';
  }
  return s;
}

// The text as quoted in an error: at most 80 bytes, cut at a character's
// start, control characters shown as '?'.
std::string Quoted(std::string_view text) {
  std::size_t n = std::min<std::size_t>(text.size(), 80);
  while (n > 0 && n < text.size() && (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80) --n;
  return Printable(std::string(text.substr(0, n)));
}

[[noreturn]] void Refuse(std::string_view text, const std::string& why, const char* grammar) {
  const char* what = grammar == kRepairGrammar ? "repair" : "malfunction";
  throw InputError(std::string(what) + " '" + Quoted(text) + "': " + Printable(why) +
                   "; expected " + grammar);
}

int Target(std::string_view text, const std::string& word, int max, const char* what,
           const char* grammar) {
  int n = 0;
  const auto [p, ec] = std::from_chars(word.data(), word.data() + word.size(), n);
  if (ec != std::errc() || p != word.data() + word.size() || n < 1 || n > max) {
    Refuse(text, std::string(what) + " '" + word + "' is not 1.." + std::to_string(max), grammar);
  }
  return n;
}

double Value(std::string_view text, std::string word, const MalfunctionKindInfo& info) {
  if (!word.empty() && word[0] == '+') word.erase(0, 1);
  double v = 0.0;
  const auto [p, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  if (ec != std::errc() || p != word.data() + word.size() || !std::isfinite(v)) {
    Refuse(text, "'" + word + "' is not a number (" + info.value + ")", kMalfunctionGrammar);
  }
  if (v < info.min_value || v > info.max_value) {
    std::ostringstream range;
    range << info.min_value << " .. " << info.max_value;
    Refuse(text, std::string(info.value) + " " + word + " is outside " + range.str(),
           kMalfunctionGrammar);
  }
  if (v == 0.0 && info.kind == MalfunctionKind::kJointDrift)
    Refuse(text, "a drift of 0 is no drift (a joint that stays is 'stuck')", kMalfunctionGrammar);
  if (v == 0.0) v = 0.0;  // no -0: the text reads back the same
  return v;
}

std::string Number(double v) {
  char buf[32];
  const auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, p) : "nan";
}

}  // namespace

const MalfunctionKindInfo& KindInfo(MalfunctionKind kind) {
  const int k = static_cast<int>(kind);
  RMS_CHECK(k >= 0 && k < static_cast<int>(MalfunctionKind::kCount));
  return kMalfunctionKinds[k];
}

const char* JointName(int joint) {
  // (kJointNames' literals end in a NUL: .data() is a C string.)
  return joint >= 1 && joint <= kNumJoints ? kJointNames[joint - 1].data() : "?";
}

Malfunction ParseMalfunction(std::string_view text) {
  if (text.size() > kMaxMalfunctionTextBytes)
    Refuse(text, "longer than " + std::to_string(kMaxMalfunctionTextBytes) + " bytes",
           kMalfunctionGrammar);
  const std::vector<std::string> w = Words(text);
  if (w.empty()) Refuse(text, "empty", kMalfunctionGrammar);
  Malfunction m;
  const auto want = [&](std::size_t n) {
    if (w.size() != n)
      Refuse(text, "expected " + std::to_string(n) + " words", kMalfunctionGrammar);
  };
  if (w[0] == "joint") {
    if (w.size() < 3) Refuse(text, "a joint needs its number and what fails", kMalfunctionGrammar);
    m.target = Target(text, w[1], kNumJoints, "joint", kMalfunctionGrammar);
    if (w[2] == "stuck") {
      want(3);
      m.kind = MalfunctionKind::kJointStuck;
    } else if (w[2] == "drift" || w[2] == "slow") {
      want(4);
      m.kind = w[2] == "drift" ? MalfunctionKind::kJointDrift : MalfunctionKind::kJointSlow;
      m.value = Value(text, w[3], KindInfo(m.kind));
    } else {
      Refuse(text, "a joint is 'stuck', 'drift' or 'slow', not '" + w[2] + "'",
             kMalfunctionGrammar);
    }
  } else if (w[0] == "finger") {
    want(3);
    if (w[1] != "jammed" || (w[2] != "open" && w[2] != "closed"))
      Refuse(text, "the finger is 'jammed open' or 'jammed closed'", kMalfunctionGrammar);
    m.kind =
        w[2] == "open" ? MalfunctionKind::kFingerJammedOpen : MalfunctionKind::kFingerJammedClosed;
  } else if (w[0] == "camera") {
    want(3);
    m.target = Target(text, w[1], kNumCameraStations, "camera station", kMalfunctionGrammar);
    if (w[2] != "lost") Refuse(text, "a camera station is 'lost'", kMalfunctionGrammar);
    m.kind = MalfunctionKind::kCameraLost;
  } else if (w[0] == "inputs") {
    want(3);
    if (w[1] != "delayed") Refuse(text, "the inputs are 'delayed MS'", kMalfunctionGrammar);
    m.kind = MalfunctionKind::kInputsDelayed;
    m.value = Value(text, w[2], KindInfo(m.kind));
  } else {
    Refuse(text, "unknown part '" + w[0] + "'", kMalfunctionGrammar);
  }
  return m;
}

Repair ParseRepair(std::string_view text) {
  if (text.size() > kMaxMalfunctionTextBytes)
    Refuse(text, "longer than " + std::to_string(kMaxMalfunctionTextBytes) + " bytes",
           kRepairGrammar);
  const std::vector<std::string> w = Words(text);
  if (w.size() == 1 && w[0] == "all") return {RepairWhat::kAll, 0};
  if (w.size() == 1 && w[0] == "finger") return {RepairWhat::kFinger, 0};
  if (w.size() == 1 && w[0] == "inputs") return {RepairWhat::kInputs, 0};
  if (w.size() == 2 && w[0] == "joint")
    return {RepairWhat::kJoint, Target(text, w[1], kNumJoints, "joint", kRepairGrammar)};
  if (w.size() == 2 && w[0] == "camera") {
    return {RepairWhat::kCamera,
            Target(text, w[1], kNumCameraStations, "camera station", kRepairGrammar)};
  }
  Refuse(text, "not a repair", kRepairGrammar);
}

std::string MalfunctionText(const Malfunction& m) {
  const std::string n = std::to_string(m.target);
  switch (m.kind) {
    case MalfunctionKind::kJointStuck:
      return "joint " + n + " stuck";
    case MalfunctionKind::kJointDrift:
      return "joint " + n + " drift " + Number(m.value);
    case MalfunctionKind::kJointSlow:
      return "joint " + n + " slow " + Number(m.value);
    case MalfunctionKind::kFingerJammedOpen:
      return "finger jammed open";
    case MalfunctionKind::kFingerJammedClosed:
      return "finger jammed closed";
    case MalfunctionKind::kCameraLost:
      return "camera " + n + " lost";
    case MalfunctionKind::kInputsDelayed:
      return "inputs delayed " + Number(m.value);
    case MalfunctionKind::kCount:
      break;
  }
  RMS_CHECK(false);
  return "";
}

std::string RepairText(const Repair& r) {
  switch (r.what) {
    case RepairWhat::kJoint:
      return "joint " + std::to_string(r.target);
    case RepairWhat::kFinger:
      return "finger";
    case RepairWhat::kCamera:
      return "camera " + std::to_string(r.target);
    case RepairWhat::kInputs:
      return "inputs";
    case RepairWhat::kAll:
      return "all";
  }
  RMS_CHECK(false);
  return "";
}

bool Clears(const Repair& r, const Malfunction& m) {
  switch (r.what) {
    case RepairWhat::kAll:
      return true;
    case RepairWhat::kJoint:
      return (m.kind == MalfunctionKind::kJointStuck || m.kind == MalfunctionKind::kJointDrift ||
              m.kind == MalfunctionKind::kJointSlow) &&
             m.target == r.target;
    case RepairWhat::kFinger:
      return m.kind == MalfunctionKind::kFingerJammedOpen ||
             m.kind == MalfunctionKind::kFingerJammedClosed;
    case RepairWhat::kCamera:
      return m.kind == MalfunctionKind::kCameraLost && m.target == r.target;
    case RepairWhat::kInputs:
      return m.kind == MalfunctionKind::kInputsDelayed;
  }
  return false;
}

Repair RepairFor(const Malfunction& m) {
  switch (m.kind) {
    case MalfunctionKind::kJointStuck:
    case MalfunctionKind::kJointDrift:
    case MalfunctionKind::kJointSlow:
      return {RepairWhat::kJoint, m.target};
    case MalfunctionKind::kFingerJammedOpen:
    case MalfunctionKind::kFingerJammedClosed:
      return {RepairWhat::kFinger, 0};
    case MalfunctionKind::kCameraLost:
      return {RepairWhat::kCamera, m.target};
    case MalfunctionKind::kInputsDelayed:
    case MalfunctionKind::kCount:
      break;
  }
  return {RepairWhat::kInputs, 0};
}

std::vector<std::string> MalfunctionTexts(const nlohmann::json& dcp_state) {
  std::vector<std::string> texts;
  if (!dcp_state.is_object() || !dcp_state.contains(kMalfunctionsKey)) return texts;
  const nlohmann::json& m = dcp_state.at(kMalfunctionsKey);
  if (!m.is_object() || !m.contains("active") || !m.at("active").is_array()) return texts;
  for (const auto& a : m.at("active")) {
    if (a.is_object() && a.contains("text") && a.at("text").is_string())
      texts.push_back(a.at("text").get<std::string>());
  }
  return texts;
}

}  // namespace rms::wire
