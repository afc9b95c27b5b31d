// The configuration file is refused at start with the key and the reason.
#include "rms/base/config.h"

#include <fstream>
#include <gtest/gtest.h>
#include <regex>
#include <sstream>

#include "rms/base/check.h"

namespace rms {
namespace {

std::string DefaultText() {
  std::ifstream f(DefaultConfigPath());
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Replaces the first match of `pattern` (a regex on one line) in the default file.
std::string Edit(const std::string& pattern, const std::string& replacement) {
  const std::string text = DefaultText();
  std::smatch m;
  const std::regex re(pattern);
  EXPECT_TRUE(std::regex_search(text, m, re)) << pattern;
  return text.substr(0, m.position(0)) + replacement + text.substr(m.position(0) + m.length(0));
}

std::string ErrorOf(const std::string& text) {
  try {
    ParseConfig(text, "test.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Config, TheDefaultFileLoadsWithEightCameras) {
  const LabConfig c = LoadConfig(DefaultConfigPath());
  EXPECT_EQ(c.cameras.size(), 8u);
  EXPECT_DOUBLE_EQ(c.arm.upper_boom_ft, 20.9);
  EXPECT_DOUBLE_EQ(c.session.frame_rate_hz, 30.0);
  EXPECT_EQ(c.inputs[kShoulderHeight].unit, "ft");
  // payload y_axis [1,0,0], z_axis [0,0,1] -> x = y cross z = [0,-1,0]
  EXPECT_NEAR(c.payload.R_RP(1, 0), -1.0, 1e-12);
}

struct Case {
  std::string pattern, replacement, expect_key, expect_reason;
};

TEST(Config, EveryProblemNamesTheKeyAndTheReason) {
  const std::vector<Case> cases = {
      {R"(upper_boom_ft = 20.9)", "", "arm.upper_boom_ft", "missing"},
      {R"(upper_boom_ft = 20.9)", "upper_boom_ft = -2", "arm.upper_boom_ft", "must be > 0"},
      {R"(upper_boom_ft = 20.9)", "upper_boom_ft = \"long\"", "arm.upper_boom_ft",
       "must be a number"},
      {R"(upper_boom_ft = 20.9)", "upper_boom_ft = 20.9\nuper_boom_ft = 3", "arm.uper_boom_ft",
       "unknown key"},
      {R"(frame_rate_hz = 30.0)", "frame_rate_hz = 0.0", "session.frame_rate_hz", "must be >= 1"},
      {R"(base_position_ft = \[1.5, -8.5, 0.0\])", "base_position_ft = [1.5, -8.5]",
       "arm.base_position_ft", "array of 3"},
      {R"(y_axis = \[1.0, 0.0, 0.0\])", "y_axis = [1.0, 1.0, 0.0]", "payload.y_axis",
       "unit vector"},
      {R"(z_axis = \[0.0, 0.0, 1.0\])", "z_axis = [1.0, 0.0, 0.0]", "payload.z_axis",
       "perpendicular"},
      {R"(finger_gap_closed_ft = 0.35)", "finger_gap_closed_ft = 2.0",
       "end_effector.finger_gap_closed_ft", "less than"},
      {R"(mount = "elbow")", "mount = \"knee\"", "cameras[2].mount", "must be one of"},
      {R"(fov_deg = \[15.0, 70.0\])", "fov_deg = [70.0, 15.0]", "cameras[0].fov_deg", "low < high"},
      {R"(units_per_count = 0.001)", "units_per_count = 0.0",
       "inputs.shoulder_height.units_per_count", "must not be zero"},
      {R"(units_per_count = 0.001)", "units_per_count = 0.0001", "inputs.shoulder_height.max",
       "outside the ADC"},
      {R"(initial = 3.0)", "initial = 30.0", "inputs.shoulder_height.initial", "must be <= 20"},
      {R"(\[\[cameras\]\]\nname = "external")", "[[camera]]\nname = \"external\"", "cameras",
       "exactly 8"},
      {R"(d3y_ft = 0.6)", "d3y_ft = 0.3", "dcp.d3y_ft",
       "greater than end_effector.finger_gap_closed_ft"},
      {R"(dock_distance_ft = 0.25)", "", "dcp.dock_distance_ft", "missing"},
      // D3Y against the bar and the finger's gaps (docs/config.md).
      {R"(d3y_ft = 0.6)", "d3y_ft = 0.38", "dcp.d3y_ft",
       "bar's width (payload.bar_size_ft[1] = 0.4 ft)"},
      {R"(d3y_ft = 0.6)", "d3y_ft = 1.28", "dcp.d3y_ft", "could not let the payload go"},
      {R"(finger_gap_closed_ft = 0.35)", "finger_gap_closed_ft = 0.45", "dcp.d3y_ft",
       "finger could not close onto the bar"},
      // Upper bounds on the design keys (docs/config.md "Bounds").
      {R"(upper_boom_ft = 20.9)", "upper_boom_ft = 9000", "arm.upper_boom_ft",
       "must be <= 100, got 9000"},
      {R"(diameter_ft = 10.0)", "diameter_ft = 16.0", "payload.diameter_ft", "must be <= 15"},
      {R"(port_position_ft = \[40.0, 0.0, 40.0\])", "port_position_ft = [40.0, 0.0, 4000.0]",
       "cae.port_position_ft", "must be <= 1000"},
      {R"(tpob_ft = 0.3)", "tpob_ft = 50", "dcp.tpob_ft", "must be <= 5"},
  };
  for (const Case& c : cases) {
    const std::string err = ErrorOf(Edit(c.pattern, c.replacement));
    EXPECT_NE(err.find("key '" + c.expect_key + "'"), std::string::npos)
        << "case " << c.replacement << ": " << err;
    EXPECT_NE(err.find(c.expect_reason), std::string::npos)
        << "case " << c.replacement << ": " << err;
    EXPECT_EQ(err.rfind("test.toml", 0), 0u) << err;
  }
}

TEST(Config, SyntaxErrorsGiveTheLine) {
  const std::string err = ErrorOf("[session]\nframe_rate_hz = = 3\n");
  EXPECT_NE(err.find("test.toml:2"), std::string::npos) << err;
  EXPECT_NE(err.find("syntax"), std::string::npos) << err;
}

TEST(Config, AMissingFileIsNamed) {
  try {
    LoadConfig("/nonexistent/rmslab.toml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/rmslab.toml"), std::string::npos);
  }
}

}  // namespace
}  // namespace rms
