#include "status_screen.h"

#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdarg>
#include <cstdio>
#include <mutex>
#include <sstream>

#include "rms/collision_bits.h"
#include "rms/text.h"

namespace rms::op {

namespace {

const char* ModeName(int m) {
  switch (m) {
    case 1: return "1 ACQUISITION";
    case 2: return "2 EXTRACTION";
    case 3: return "3 MANOEUVRING AND DOCKING";
    default: return "?";
  }
}


}  // namespace

std::string RenderStatusScreen(const StatusSnapshot& s, const LabConfig& config, int width) {
  std::vector<std::string> L;
  const OperatorInputs& in = s.inputs;
  L.push_back(Sprintf("rmslab operator station -- %s", s.source.c_str()));
  L.back() += std::string(std::max<int>(1, width - 14 - static_cast<int>(L.back().size())), ' ') +
              Sprintf("frame %06lld", static_cast<long long>(s.frame));
  if (s.telemetry) {
    const dcp_telemetry_t& t = *s.telemetry;
    L.push_back(Sprintf("MODE %-26s acquired %-3s  docked %-3s  arm %s", ModeName(t.mode), t.acquired ? "YES" : "no",
                    t.docked ? "YES" : "no",
                    t.held ? "HELD: the command collides" : t.finger_held ? "follows, finger held on the bar" : "follows"));
    std::string coll;
    for (int b = 0; b < collision_bits::kCount; ++b) {
      if (t.collisions & (1 << b)) coll += std::string(coll.empty() ? "" : ", ") + CollisionName(b);
    }
    L.push_back("collisions: " + (coll.empty() ? std::string("none") : coll));
    static const char* kCond[6] = {"BAR past palm d", "BAR past finger b", "BAR past finger e", "gap < D3Y",
                                   "palm-BAR < TPOB", "between BAR ends"};
    for (int half = 0; half < 2; ++half) {
      std::string cond = half == 0 ? "acquisition:" : "            ";
      for (int i = 3 * half; i < 3 * half + 3; ++i) {
        cond += Sprintf(" [%c] %d %-18s", t.acquisition_conditions[i] ? 'x' : ' ', i + 1, kCond[i]);
      }
      L.push_back(cond);
    }
    L.push_back(Sprintf("  finger gap %.3f ft (D3Y %.3f)   palm to BAR %.3f ft (TPOB %.3f)", t.finger_gap_ft,
                    config.dcp.d3y_ft, t.palm_to_bar_ft, config.dcp.tpob_ft));
    L.push_back(Sprintf("docking: distance %.3f ft (<= %.2f)  angle %.2f deg (<= %.2f)  probe in envelope %s",
                    t.dock_distance_ft, config.dcp.dock_distance_ft, t.dock_angle_deg, config.dcp.dock_angle_deg,
                    t.probe_in_envelope ? "yes" : "no"));
  } else {
    L.push_back("MODE ?  (no telemetry from dynamics_proc yet)");
  }
  const int st = in.camera_station;
  L.push_back(Sprintf("camera %d %-34s pan %+6.1f  tilt %+6.1f  zoom %.2f", st,
                  st >= 1 && st <= static_cast<int>(config.cameras.size()) ? config.cameras[st - 1].name.c_str() : "?",
                  in.value[kCameraPan], in.value[kCameraTilt], in.value[kCameraZoom]));
  L.push_back(Sprintf("arm, deg: yaw %+7.2f  pitch %+7.2f  elbow %+7.2f  wrist pitch %+7.2f  yaw %+7.2f  roll %+7.2f",
                  in.value[0], in.value[1], in.value[2], in.value[3], in.value[4], in.value[5]));
  L.push_back(Sprintf("shoulder height %.2f ft   finger %.2f (0 open, 1 closed)   overlay %s", in.value[kShoulderHeight],
                  in.value[kFinger], in.overlay ? "on" : "off"));
  std::string rates = Sprintf("rates: published %.1f Hz   DCP %.1f Hz   rendered ", s.publish_hz, s.telemetry_hz);
  rates += s.render_hz >= 0 ? Sprintf("%.1f Hz", s.render_hz) : "? (no status from esg_renderer)";
  L.push_back(rates);
  std::string lat = "latency: input to DCP ";
  lat += s.input_to_dcp_ms >= 0 ? Sprintf("%.1f ms", s.input_to_dcp_ms) : "?";
  lat += "   input to rendered frame ";
  lat += s.input_to_render_p50_ms >= 0
             ? Sprintf("p50 %.1f ms, p99 %.1f ms", s.input_to_render_p50_ms, s.input_to_render_p99_ms)
             : "? (no status from esg_renderer)";
  L.push_back(lat);
  L.push_back(Sprintf("inputs clamped to their range: %ld", s.clamped_inputs));
  std::string dev = "devices:";
  for (const auto& d : s.devices) dev += " " + d + ";";
  L.push_back(dev);
  L.push_back("--- log ---");
  const std::size_t first = s.log.size() > 6 ? s.log.size() - 6 : 0;
  for (std::size_t i = first; i < s.log.size(); ++i) L.push_back(s.log[i]);
  for (std::size_t i = s.log.size() - first; i < 6; ++i) L.push_back("");
  if (!s.help.empty()) L.push_back(s.help);
  std::string out;
  for (auto& l : L) {
    if (static_cast<int>(l.size()) > width) l.resize(width);
    out += l + "\n";
  }
  return out;
}

namespace {
// Keeps every formatted line (the screen shows the last ones; all are
// written out when the screen closes).
class LineSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  std::vector<std::string> Last(std::size_t n) {
    std::lock_guard<std::mutex> lock(mutex_);
    return {lines_.end() - static_cast<long>(std::min(n, lines_.size())), lines_.end()};
  }
  std::vector<std::string> All() {
    std::lock_guard<std::mutex> lock(mutex_);
    return lines_;
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    spdlog::memory_buf_t buf;
    formatter_->format(msg, buf);
    std::string line(buf.data(), buf.size());
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    lines_.push_back(std::move(line));
  }
  void flush_() override {}

 private:
  std::vector<std::string> lines_;
};
}  // namespace

struct StatusScreen::LogCapture {
  std::shared_ptr<spdlog::logger> logger;
  std::vector<spdlog::sink_ptr> saved;
  std::shared_ptr<LineSink> lines;
};

StatusScreen::StatusScreen(const LabConfig& config) : config_(config), capture_(std::make_unique<LogCapture>()) {
  capture_->logger = spdlog::default_logger();
  capture_->saved = capture_->logger->sinks();
  capture_->lines = std::make_shared<LineSink>();
  capture_->lines->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%n] [%l] %v");
  capture_->logger->sinks() = {capture_->lines};
  std::fputs("\x1b[?1049h\x1b[?25l\x1b[H\x1b[2J", stdout);
  std::fflush(stdout);
}

StatusScreen::~StatusScreen() {
  std::fputs("\x1b[?25h\x1b[?1049l", stdout);
  std::fflush(stdout);
  capture_->logger->sinks() = capture_->saved;
  // Nothing is lost: the lines the screen showed go to the log now.
  for (const std::string& line : capture_->lines->All()) std::fprintf(stderr, "%s\n", line.c_str());
}

void StatusScreen::Draw(StatusSnapshot s) {
  for (std::string& line : capture_->lines->Last(6)) s.log.push_back(std::move(line));
  const std::string text = RenderStatusScreen(s, config_);
  std::string frame = "\x1b[H";
  std::istringstream is(text);
  for (std::string line; std::getline(is, line);) frame += line + "\x1b[K\n";
  frame += "\x1b[J";
  std::fwrite(frame.data(), 1, frame.size(), stdout);
  std::fflush(stdout);
}

}  // namespace rms::op
