#include "rms/operator_station/timeline.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "rms/base/check.h"
#include "rms/base/config.h"

namespace rms::operator_station {

namespace {

std::vector<std::string_view> SplitWs(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < s.size() && !(s[j] == ' ' || s[j] == '\t' || s[j] == '\r')) ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

bool ParseDouble(std::string_view s, double* out) {
  if (s.empty()) return false;
  const char* b = s.data();
  const char* e = s.data() + s.size();
  if (*b == '+') ++b;
  auto r = std::from_chars(b, e, *out);
  return r.ec == std::errc() && r.ptr == e && std::isfinite(*out);
}

std::string KnownKeys() {
  std::string k;
  for (auto n : kAnalogInputNames) k += std::string(n) + ", ";
  return k + "camera, overlay, crosshairs, reset, end";
}

}  // namespace

namespace {

// A line's time: a number of seconds, not negative, not before the line
// before's, at most 1e6; InputError "WHERE: why" otherwise.
double LineTime(std::string_view tok, double prev_t, const std::string& where) {
  double t = 0;
  if (!ParseDouble(tok, &t))
    throw InputError(where + ": '" + std::string(tok) + "' is not a time in seconds");
  if (t < 0) throw InputError(where + ": time " + std::string(tok) + " is negative");
  if (t < prev_t) {
    throw InputError(where + ": time " + std::string(tok) +
                     " s is before the previous line's time; lines must be in time order");
  }
  if (t > 1e6) throw InputError(where + ": time " + std::string(tok) + " s is beyond 1e6 s");
  return t;
}

}  // namespace

// One item of a line at time t: reset, end, or key=value.
void Timeline::AddItem(double t, std::string_view item, const InputCalibrations& cal,
                       const std::string& where, bool* end) {
  auto fail = [&](const std::string& why) -> void { throw InputError(where + ": " + why); };
  if (item == "reset") {
    resets_.push_back(t);
    return;
  }
  if (item == "end") {
    *end = true;
    return;
  }
  const std::size_t eq = item.find('=');
  if (eq == std::string_view::npos)
    fail("'" + std::string(item) + "' is not key=value, reset or end");
  const std::string key(item.substr(0, eq));
  const std::string_view val = item.substr(eq + 1);
  if (key == "camera") {
    double v = 0;
    if (!ParseDouble(val, &v) || v != std::floor(v) || v < 1 || v > kNumCameraStations) {
      fail("camera must be a station number 1-" + std::to_string(kNumCameraStations) + ", got '" +
           std::string(val) + "'");
    }
    camera_.emplace_back(t, static_cast<int>(v));
    return;
  }
  if (key == "overlay" || key == "crosshairs") {
    auto& steps = key == "overlay" ? overlay_ : crosshairs_;
    if (val == "on" || val == "1")
      steps.emplace_back(t, true);
    else if (val == "off" || val == "0")
      steps.emplace_back(t, false);
    else
      fail(std::string(key) + " must be on or off, got '" + std::string(val) + "'");
    return;
  }
  const int idx = AnalogInputIndex(key);
  if (idx < 0) fail("unknown key '" + key + "' (known: " + KnownKeys() + ")");
  double v = 0;
  if (!ParseDouble(val, &v))
    fail("value '" + std::string(val) + "' for '" + key + "' is not a number");
  const InputCalibration& c = cal[idx];
  if (v < c.min || v > c.max) {
    std::ostringstream w;
    w << where << ": " << key << "=" << v << " is outside [" << c.min << ", " << c.max << "] "
      << c.unit << "; it will be clamped";
    warnings_.push_back(w.str());
  }
  auto& keys = analog_[idx];
  if (!keys.empty() && keys.back().t == t)
    keys.back().v = v;
  else
    keys.push_back({t, v});
}

Timeline Timeline::Parse(std::string_view text, const std::string& source,
                         const InputCalibrations& cal) {
  Timeline tl;
  tl.initial_ = wire::InitialInputs(cal);
  double prev_t = 0.0;
  bool have_end = false;
  int line_no = 0;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    std::string_view line = text.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos)
      line = line.substr(0, hash);
    std::vector<std::string_view> tok = SplitWs(line);
    if (tok.empty()) continue;
    const std::string where = source + ":" + std::to_string(line_no);
    if (have_end) throw InputError(where + ": nothing may follow the 'end' line");
    const double t = LineTime(tok[0], prev_t, where);
    prev_t = t;
    tl.end_time_ = t;
    if (tok.size() == 1)
      throw InputError(where + ": a time with nothing to do (expected key=value, reset or end)");
    for (std::size_t i = 1; i < tok.size(); ++i) tl.AddItem(t, tok[i], cal, where, &have_end);
  }
  if (tl.end_time_ <= 0.0) throw InputError(source + ": the timeline must last longer than 0 s");
  // Implicit keyframes at t = 0 with the initial values.
  for (int i = 0; i < kNumAnalogInputs; ++i) {
    auto& keys = tl.analog_[i];
    if (keys.empty() || keys.front().t > 0.0)
      keys.insert(keys.begin(), {0.0, tl.initial_.value[i]});
  }
  return tl;
}

Timeline Timeline::Load(const std::string& path, const InputCalibrations& cal) {
  std::ifstream f(path);
  if (!f) throw InputError(path + ": cannot read the timeline file");
  std::stringstream ss;
  ss << f.rdbuf();
  return Parse(ss.str(), path, cal);
}

wire::OperatorInputs Timeline::Sample(double t) const {
  wire::OperatorInputs in = initial_;
  for (int i = 0; i < kNumAnalogInputs; ++i) {
    const auto& keys = analog_[i];
    RMS_DASSERT(!keys.empty());
    // First keyframe with time > t.
    auto it = std::upper_bound(keys.begin(), keys.end(), t,
                               [](double tt, const Key& k) { return tt < k.t; });
    if (it == keys.begin()) {
      in.value[i] = keys.front().v;
    } else if (it == keys.end()) {
      in.value[i] = keys.back().v;
    } else {
      const Key& a = *(it - 1);
      const Key& b = *it;
      const double u = (t - a.t) / (b.t - a.t);
      in.value[i] = a.v + u * (b.v - a.v);
    }
  }
  for (const auto& [tc, cam] : camera_) {
    if (tc <= t) in.camera_station = cam;
  }
  for (const auto& [to, on] : crosshairs_) {
    if (to <= t) in.crosshairs = on;
  }
  for (const auto& [to, on] : overlay_) {
    if (to <= t) in.overlay = on;
  }
  return in;
}

bool Timeline::ResetIn(double t0, double t1) const {
  for (double r : resets_) {
    if ((t0 < 0 ? r >= 0 : r > t0) && r <= t1) return true;
  }
  return false;
}

}  // namespace rms::operator_station
