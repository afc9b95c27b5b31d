#include "rms/lesson/lesson.h"

#include <algorithm>
#include <cstdio>
#include <regex>

#include "rms/base/check.h"
#include "rms/base/folder_file.h"
#include "rms/base/toml_reader.h"
#include "rms/session_control_t.hpp"
#include "rms/wire/collision_bits.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/malfunction.h"

namespace rms::lesson {

namespace {

constexpr std::size_t kMaxEvents = 1000;

struct QuantityName {
  LessonQuantity quantity;
  const char* name;
  int mode;  // the mode in which it is tested (0: every mode)
};
// docs/lessons.md "Conditions": one table of the quantities a condition may test.
constexpr QuantityName kQuantities[] = {
    {LessonQuantity::kDockDistanceFt, "dock_distance_ft", 3},
    {LessonQuantity::kDockAngleDeg, "dock_angle_deg", 3},
    {LessonQuantity::kCollisions, "collisions", 0},
};

double Value(LessonQuantity q, const dcp_telemetry_t& t) {
  switch (q) {
    case LessonQuantity::kDockDistanceFt:
      return t.dock_distance_ft;
    case LessonQuantity::kDockAngleDeg:
      return t.dock_angle_deg;
    case LessonQuantity::kCollisions:  // as the summary counts them: not the essential contact
      return wire::DetrimentalCollisions(static_cast<std::uint32_t>(t.collisions), t.finger_held,
                                         t.held, t.master_finger > t.slave_finger) != 0
                 ? 1.0
                 : 0.0;
  }
  return 0.0;
}

int ModeOf(LessonQuantity q) {
  for (const auto& n : kQuantities)
    if (n.quantity == q) return n.mode;
  return 0;
}

LessonEvent::Condition ParseCondition(TomlReader& r, const std::string& text) {
  static const std::regex re(R"(\s*([a-z_]+)\s*(<=|>=|<|>)\s*([-+0-9.eE]+)\s*)");
  std::smatch m;
  std::string names;
  for (const auto& n : kQuantities) names += std::string(names.empty() ? "" : ", ") + n.name;
  if (!std::regex_match(text, m, re)) {
    r.Fail("when", "must be QUANTITY OP NUMBER, e.g. \"dock_distance_ft < 5\" (QUANTITY one of " +
                       names + "; OP <, <=, > or >=), got \"" + text + "\"");
  }
  LessonEvent::Condition c{};
  const auto q = std::find_if(std::begin(kQuantities), std::end(kQuantities),
                              [&](const QuantityName& n) { return m[1] == n.name; });
  if (q == std::end(kQuantities))
    r.Fail("when", "'" + m[1].str() + "' is not a quantity a condition may test (" + names + ")");
  c.quantity = q->quantity;
  const std::string op = m[2];
  c.comparison = op == "<"    ? LessonComparison::kLess
                 : op == "<=" ? LessonComparison::kLessOrEqual
                 : op == ">"  ? LessonComparison::kGreater
                              : LessonComparison::kGreaterOrEqual;
  try {
    std::size_t used = 0;
    c.value = std::stod(m[3].str(), &used);
    if (static_cast<std::ptrdiff_t>(used) != m[3].length()) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    r.Fail("when", "'" + m[3].str() + "' is not a number");
  }
  return c;
}

void ParseAction(TomlReader& r, LessonEvent* e) {
  const std::string what = r.String("do");
  const auto space = what.find(' ');
  const std::string verb = what.substr(0, space);
  const std::string rest = space == std::string::npos ? "" : what.substr(space + 1);
  try {
    if (verb == "malfunction") {
      e->command = session_control_t::MALFUNCTION;
      e->name = wire::MalfunctionText(wire::ParseMalfunction(rest));
    } else if (verb == "repair") {
      e->command = session_control_t::REPAIR;
      e->name = wire::RepairText(wire::ParseRepair(rest));
    } else if (verb == "freeze" && rest.empty()) {
      e->command = session_control_t::FREEZE;
    } else {
      r.Fail("do",
             "must be \"malfunction WHAT\", \"repair WHAT\" or \"freeze\" (docs/lessons.md), got "
             "\"" +
                 what + "\"");
    }
  } catch (const InputError& err) {
    if (std::string(err.what()).find("key '") != std::string::npos) throw;
    r.Fail("do", err.what());
  }
  if (r.Has("for_s")) {
    if (e->command != session_control_t::FREEZE) r.Fail("for_s", "is for a freeze only");
    e->for_s = r.Number("for_s", 0.0, 3600.0, true);
  }
}

LessonEvent ParseEvent(TomlReader& r) {
  LessonEvent e;
  const int triggers = r.Has("at_s") + r.Has("on_mode") + r.Has("when");
  if (triggers != 1) {
    throw InputError(r.source() + ": " + r.path() + ": " +
                     (triggers == 0 ? "no trigger" : "more than one trigger") +
                     ": give exactly one of at_s, on_mode or when (docs/lessons.md)");
  }
  char trigger[96] = {};
  if (r.Has("at_s")) {
    e.at_s = r.Number("at_s", 0.0, 86400.0);
    std::snprintf(trigger, sizeof trigger, "at %g s", *e.at_s);
  } else if (r.Has("on_mode")) {
    // A DCP mode's number, 1 .. wire::kNumDcpModes (rms/wire/dcp_mode.h).
    const double mode = r.Number("on_mode", 1, wire::kNumDcpModes);
    e.on_mode = static_cast<int>(mode);
    if (e.on_mode != mode)
      r.Fail("on_mode", "must be a mode's number, 1.." + std::to_string(wire::kNumDcpModes));
    std::snprintf(trigger, sizeof trigger, "on entering Mode %d", e.on_mode);
  } else {
    e.when_text = r.String("when");
    e.when = ParseCondition(r, e.when_text);
    std::snprintf(trigger, sizeof trigger, "when %s", e.when_text.c_str());
  }
  ParseAction(r, &e);
  e.text = std::string(trigger) + ": " +
           (e.command == session_control_t::MALFUNCTION ? "malfunction "
            : e.command == session_control_t::REPAIR    ? "repair "
                                                        : "freeze") +
           e.name;
  if (e.for_s > 0) {
    char for_s[48];
    std::snprintf(for_s, sizeof for_s, " for %g s", e.for_s);
    e.text += for_s;
  }
  r.Finish();
  return e;
}

bool Holds(const LessonEvent::Condition& c, const dcp_telemetry_t& t) {
  const int mode = ModeOf(c.quantity);
  if (mode != 0 && t.mode != mode) return false;
  const double v = Value(c.quantity, t);
  switch (c.comparison) {
    case LessonComparison::kLess:
      return v < c.value;
    case LessonComparison::kLessOrEqual:
      return v <= c.value;
    case LessonComparison::kGreater:
      return v > c.value;
    case LessonComparison::kGreaterOrEqual:
      return v >= c.value;
  }
  return false;
}

}  // namespace

Lesson Lesson::Load(const std::string& path) {
  return Parse(ReadRegularFile(path, "lesson", kMaxConfigBytes, Links::kFollow), path);
}

Lesson Lesson::Parse(std::string_view text, const std::string& source) {
  toml::table root = ParseToml(text, source);
  TomlReader top(&root, "", &source, "docs/lessons.md");
  const toml::array* events = top.Array("events");
  if (events->empty() || events->size() > kMaxEvents)
    top.Fail("events", "must be 1 to " + std::to_string(kMaxEvents) + " [[events]] tables");
  Lesson l;
  for (std::size_t i = 0; i < events->size(); ++i) {
    const toml::table* t = (*events)[i].as_table();
    const std::string path = "events[" + std::to_string(i) + "]";
    if (t == nullptr) top.Fail(path, "must be a table");
    TomlReader r(t, path, &source, "docs/lessons.md");
    l.events_.push_back(ParseEvent(r));
  }
  top.Finish();
  l.fired_.assign(l.events_.size(), false);
  return l;
}

std::vector<std::size_t> Lesson::Due(double t_s, const dcp_telemetry_t* tm) {
  std::vector<std::size_t> due;
  const int mode = tm ? tm->mode : 0;
  for (std::size_t i = 0; i < events_.size(); ++i) {
    if (fired_[i]) continue;
    const LessonEvent& e = events_[i];
    const bool now = e.at_s           ? t_s + 1e-9 >= *e.at_s
                     : e.on_mode != 0 ? (mode == e.on_mode && last_mode_ != 0 && last_mode_ != mode)
                     : (e.when && tm) ? Holds(*e.when, *tm)
                                      : false;
    if (now) {
      fired_[i] = true;
      due.push_back(i);
    }
  }
  if (mode != 0) last_mode_ = mode;
  return due;
}

std::size_t Lesson::fired() const {
  return static_cast<std::size_t>(std::count(fired_.begin(), fired_.end(), true));
}

}  // namespace rms::lesson
