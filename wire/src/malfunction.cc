#include "rms/wire/malfunction.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <vector>

#include "rms/base/check.h"

namespace rms::wire {

namespace {

// Which grammar an error shows.
enum class Grammar { kMalfunction, kRepair };

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

[[noreturn]] void Refuse(std::string_view text, const std::string& why, Grammar grammar) {
  const bool repair = grammar == Grammar::kRepair;
  throw InputError(std::string(repair ? "repair" : "malfunction") + " '" + Quoted(text) +
                   "': " + Printable(why) + "; a " + (repair ? "repair" : "malfunction") + " is " +
                   (repair ? RepairGrammar() : MalfunctionGrammar()));
}

int Target(std::string_view text, const std::string& word, const MalfunctionPartInfo& part,
           Grammar grammar) {
  int n = 0;
  const auto [p, ec] = std::from_chars(word.data(), word.data() + word.size(), n);
  if (ec != std::errc() || p != word.data() + word.size() || n < 1 || n > part.count) {
    Refuse(text,
           std::string(part.target) + " '" + word + "' is not 1.." + std::to_string(part.count),
           grammar);
  }
  return n;
}

std::string Number(double v) {
  char buf[32];
  const auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, p) : "nan";
}

double Value(std::string_view text, std::string word, const MalfunctionKindInfo& info) {
  if (!word.empty() && word[0] == '+') word.erase(0, 1);
  if (word.find_first_not_of("-.0123456789") != std::string::npos)
    Refuse(text, "'" + word + "' is not a plain decimal number (" + info.value + ")",
           Grammar::kMalfunction);
  double v = 0.0;
  const auto [p, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  if (ec != std::errc() || p != word.data() + word.size() || !std::isfinite(v)) {
    Refuse(text, "'" + word + "' is not a number (" + info.value + ")", Grammar::kMalfunction);
  }
  if (v < info.min_value || v > info.max_value) {
    Refuse(text,
           word + " is outside " + Number(info.min_value) + ".." + Number(info.max_value) + " (" +
               info.value + ")",
           Grammar::kMalfunction);
  }
  if (v == 0.0 && info.kind == MalfunctionKind::kJointDrift)
    Refuse(text, "a drift of 0 is no drift (a joint that stays is 'stuck')", Grammar::kMalfunction);
  if (v == 0.0) v = 0.0;  // no -0: the text reads back the same
  return v;
}

// A pattern's words as written (N and V upper case).
std::vector<std::string> Split(std::string_view text) {
  std::vector<std::string> words;
  std::istringstream in{std::string(text)};
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

bool IsSlot(const std::string& word) { return word == "N" || word == "V"; }

// Whether the words given so far are the pattern's, slots aside.
bool Fits(const std::vector<std::string>& pattern, const std::vector<std::string>& words) {
  for (std::size_t i = 0; i < std::min(pattern.size(), words.size()); ++i) {
    if (!IsSlot(pattern[i]) && pattern[i] != words[i]) return false;
  }
  return true;
}

// The pattern as the grammar shows it, V as its value word.
std::string Shown(const MalfunctionKindInfo& kind) {
  std::string out;
  for (const std::string& word : Split(kind.pattern)) {
    if (!out.empty()) out += ' ';
    out += word == "V" ? kind.value_word : word;
  }
  return out;
}

// 'a', 'b' or 'c'.
std::string OneOf(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += i + 1 == items.size() ? " or " : ", ";
    out.append("'").append(items[i]).append("'");
  }
  return out;
}

// "(joints 1..6, camera stations 1..8)": the parts' numbers.
std::string Ranges() {
  std::string out;
  for (const MalfunctionPartInfo& part : kMalfunctionParts) {
    if (part.count == 0) continue;
    out.append(out.empty() ? "(" : ", ").append(part.target).append("s 1..");
    out += std::to_string(part.count);
  }
  return out + ")";
}

const MalfunctionPartInfo* PartNamed(const std::string& word) {
  for (const MalfunctionPartInfo& part : kMalfunctionParts) {
    if (word == part.word) return &part;
  }
  return nullptr;
}

void CheckLength(std::string_view text, Grammar grammar) {
  if (text.size() > kMaxMalfunctionTextBytes)
    Refuse(text, "longer than " + std::to_string(kMaxMalfunctionTextBytes) + " bytes", grammar);
}

// The words read as the kind's pattern (which they fit, word for word).
Malfunction Read(std::string_view text, const MalfunctionKindInfo& kind,
                 const std::vector<std::string>& pattern, const std::vector<std::string>& words) {
  Malfunction m;
  m.kind = kind.kind;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] == "N")
      m.target = Target(text, words[i], PartInfo(kind.part), Grammar::kMalfunction);
    if (pattern[i] == "V") m.value = Value(text, words[i], kind);
  }
  return m;
}

}  // namespace

const MalfunctionKindInfo& KindInfo(MalfunctionKind kind) {
  const int k = static_cast<int>(kind);
  RMS_CHECK(k >= 0 && k < static_cast<int>(MalfunctionKind::kCount));
  return kMalfunctionKinds[k];
}

const MalfunctionPartInfo& PartInfo(MalfunctionPart part) {
  const int p = static_cast<int>(part);
  RMS_CHECK(p >= 0 && p < static_cast<int>(MalfunctionPart::kCount));
  return kMalfunctionParts[p];
}

const char* JointName(int joint) {
  // (kJointNames' literals end in a NUL: .data() is a C string.)
  return joint >= 1 && joint <= kNumJoints ? kJointNames[joint - 1].data() : "?";
}

std::string MalfunctionGrammar() {
  std::vector<std::string> forms;
  for (const MalfunctionKindInfo& kind : kMalfunctionKinds) forms.push_back(Shown(kind));
  return OneOf(forms) + " " + Ranges();
}

std::string RepairGrammar() {
  std::vector<std::string> forms;
  for (const MalfunctionPartInfo& part : kMalfunctionParts)
    forms.push_back(std::string(part.word) + (part.count > 0 ? " N" : ""));
  forms.push_back("all");
  return OneOf(forms) + " " + Ranges();
}

Malfunction ParseMalfunction(std::string_view text) {
  CheckLength(text, Grammar::kMalfunction);
  const std::vector<std::string> w = Words(text);
  if (w.empty()) Refuse(text, "empty", Grammar::kMalfunction);
  const MalfunctionPartInfo* part = PartNamed(w[0]);
  if (part == nullptr) Refuse(text, "unknown part '" + w[0] + "'", Grammar::kMalfunction);
  std::vector<std::string> forms;
  std::size_t words_wanted = 0;  // of the first pattern the words fit but for their count
  for (const MalfunctionKindInfo& kind : kMalfunctionKinds) {
    if (kind.part != part->part) continue;
    forms.push_back(Shown(kind));
    const std::vector<std::string> pattern = Split(kind.pattern);
    if (!Fits(pattern, w)) continue;
    if (pattern.size() == w.size()) return Read(text, kind, pattern, w);
    if (words_wanted == 0) words_wanted = pattern.size();
  }
  if (words_wanted > 0) {
    Refuse(text, std::to_string(words_wanted) + " words wanted, as " + OneOf(forms),
           Grammar::kMalfunction);
  }
  Refuse(text, "a malfunction of the " + std::string(part->word) + " is " + OneOf(forms),
         Grammar::kMalfunction);
}

Repair ParseRepair(std::string_view text) {
  CheckLength(text, Grammar::kRepair);
  const std::vector<std::string> w = Words(text);
  if (w.size() == 1 && w[0] == "all") return Repair{};
  const MalfunctionPartInfo* part = w.empty() ? nullptr : PartNamed(w[0]);
  if (part != nullptr && part->count == 0 && w.size() == 1) return {false, part->part, 0};
  if (part != nullptr && part->count > 0 && w.size() == 2)
    return {false, part->part, Target(text, w[1], *part, Grammar::kRepair)};
  if (w.empty()) Refuse(text, "empty", Grammar::kRepair);
  if (part == nullptr) Refuse(text, "unknown part '" + w[0] + "'", Grammar::kRepair);
  Refuse(text,
         part->count > 0 ? std::string("'") + part->word + "' takes its number N and no more"
                         : std::string("'") + part->word + "' takes no number",
         Grammar::kRepair);
}

std::string MalfunctionText(const Malfunction& m) {
  std::string out;
  for (const std::string& word : Split(KindInfo(m.kind).pattern)) {
    if (!out.empty()) out += ' ';
    out += word == "N" ? std::to_string(m.target) : word == "V" ? Number(m.value) : word;
  }
  return out;
}

std::string RepairText(const Repair& r) {
  if (r.all) return "all";
  const MalfunctionPartInfo& part = PartInfo(r.part);
  return part.count > 0 ? std::string(part.word) + " " + std::to_string(r.target) : part.word;
}

bool Clears(const Repair& r, const Malfunction& m) {
  return r.all || (KindInfo(m.kind).part == r.part && m.target == r.target);
}

Repair RepairFor(const Malfunction& m) { return {false, KindInfo(m.kind).part, m.target}; }

std::string MalfunctionTableMarkdown() {
  std::string out = "| Text | What fails | Value |\n|---|---|---|\n";
  for (const MalfunctionKindInfo& kind : kMalfunctionKinds) {
    std::string value = kind.unit;
    if (kind.value[0] != '\0')
      value += ", " + Number(kind.min_value) + ".." + Number(kind.max_value);
    out.append("| `").append(kind.pattern).append("` | ").append(kind.meaning);
    out.append(" | ").append(value).append(" |\n");
  }
  out += "\nN is ";
  for (const MalfunctionPartInfo& part : kMalfunctionParts) {
    if (part.count == 0) continue;
    if (out.back() != ' ') out += ", or ";
    out.append("a ").append(part.target).append(" 1..").append(std::to_string(part.count));
    if (part.part != MalfunctionPart::kJoint) continue;
    out += " (";
    for (int j = 1; j <= kNumJoints; ++j)
      out.append(j > 1 ? ", " : "").append(std::to_string(j)).append(" ").append(JointName(j));
    out += ")";
  }
  out += ". A repair is " + RepairGrammar() + ".\n";
  return out;
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
