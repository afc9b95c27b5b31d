// Configuration keys set on a command line (rms/base/config_settings.h):
// each setting changes its key alone, exactly; a key the file lacks, a value
// that is no TOML or of another kind, and a table are refused with the key.
#include "rms/base/config_settings.h"

#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/base/toml_reader.h"

namespace rms {
namespace {

std::string DefaultText() { return ReadTextFile(DefaultConfigPath(), "the default configuration"); }

std::string Refusal(const std::vector<ConfigSetting>& s) {
  try {
    ApplyConfigSettings(DefaultText(), "rmslab.toml", s);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ConfigSettings, EachSettingChangesItsKeyAloneAndExactly) {
  const LabConfig before = ParseConfig(DefaultText(), "default");
  const std::string text =
      ApplyConfigSettings(DefaultText(), "rmslab.toml",
                          {{"dcp.tpob_ft", "0.30000000000000004"},
                           {"arm.upper_boom_ft", "21"},  // an integer for a float key: 21.0
                           {"arm.base_position_ft", "[1.5, -8.0, 0.25]"},
                           {"cameras[2].tilt_deg", "[-30, 40.0]"},
                           {"dcp.tpob_ft", "0.45"}});  // the last of two wins
  const LabConfig after = ParseConfig(text, "set");
  EXPECT_EQ(after.dcp.tpob_ft, 0.45);
  EXPECT_EQ(after.arm.upper_boom_ft, 21.0);
  EXPECT_EQ(after.arm.p_RoB_R_ft.y(), -8.0);
  EXPECT_EQ(after.arm.p_RoB_R_ft.z(), 0.25);
  EXPECT_EQ(after.cameras[2].tilt_min_deg, -30.0);
  EXPECT_EQ(after.cameras[2].tilt_max_deg, 40.0);
  // Everything else as it was, to the bit.
  EXPECT_EQ(after.arm.lower_boom_ft, before.arm.lower_boom_ft);
  EXPECT_EQ(after.dcp.dock_angle_deg, before.dcp.dock_angle_deg);
  EXPECT_EQ(after.cameras[1].tilt_min_deg, before.cameras[1].tilt_min_deg);
  EXPECT_EQ(after.session.frame_rate_hz, before.session.frame_rate_hz);
  // No settings: the same configuration.
  EXPECT_EQ(ParseConfig(ApplyConfigSettings(DefaultText(), "x", {}), "x").dcp.dock_angle_deg,
            before.dcp.dock_angle_deg);
}

TEST(ConfigSettings, ABadSettingIsRefusedNamingTheKeyAndWhy) {
  EXPECT_NE(Refusal({{"dcp.no_such", "1"}})
                .find("--set dcp.no_such: the configuration has no key "
                      "'no_such'"),
            std::string::npos);
  EXPECT_NE(Refusal({{"dcp.tpob_ft", "abc"}}).find("'abc' is no TOML value"), std::string::npos);
  EXPECT_NE(Refusal({{"dcp.tpob_ft", "\"0.3\""}}).find("the key is a number, the value a string"),
            std::string::npos);
  EXPECT_NE(Refusal({{"dcp", "1"}}).find("is a table"), std::string::npos);
  EXPECT_NE(Refusal({{"cameras[99].tilt_deg", "1"}}).find("'cameras' has no element 99"),
            std::string::npos);
  for (const char* k : {"cameras[x].tilt_deg", "cameras[+0].tilt_deg", "cameras[0x0].tilt_deg",
                        "cameras[ 0].tilt_deg", "cameras[].tilt_deg", "cameras[-1].tilt_deg"})
    EXPECT_NE(Refusal({{k, "[-30, 40]"}}).find("no index a number"), std::string::npos) << k;
  // An element of an array of numbers is a number.
  const LabConfig c = ParseConfig(
      ApplyConfigSettings(DefaultText(), "x", {{"arm.base_position_ft[1]", "-8"}}), "x");
  EXPECT_EQ(c.arm.p_RoB_R_ft.y(), -8.0);
  EXPECT_THROW(ParseConfigSetting("no_equals"), InputError);
  EXPECT_THROW(ParseConfigSetting("=1"), InputError);
  EXPECT_THROW(ParseConfigSetting("a="), InputError);
  const ConfigSetting s = ParseConfigSetting("dcp.tpob_ft=0.4=x");
  EXPECT_EQ(s.key, "dcp.tpob_ft");
  EXPECT_EQ(s.value, "0.4=x");
}

// A batch's designs (ConfigDesigns, the text parsed once) give what the text
// with the keys set and parsed again gives: the same values, bit for bit,
// and the same refusals, word for word.
TEST(ConfigSettings, DesignsFromTheTextParsedOnceAreTheTextSetAndParsedAgain) {
  const ConfigDesigns designs(DefaultText(), "rmslab.toml");
  const std::vector<std::vector<ConfigSetting>> cases = {
      {{"dcp.tpob_ft", "0.30000000000000004"}, {"arm.upper_boom_ft", "21"}},
      {{"arm.base_position_ft", "[1.5, -8.0, 0.25]"}, {"cameras[2].tilt_deg", "[-30, 40.0]"}},
      {{"session.frame_rate_hz", "60"}, {"dcp.tpob_ft", "0.1"}, {"dcp.tpob_ft", "0.45"}},
  };
  for (const auto& settings : cases) {
    const LabConfig a = designs.With(settings, "cell");
    const LabConfig b =
        ParseConfig(ApplyConfigSettings(DefaultText(), "rmslab.toml", settings), "cell");
    EXPECT_EQ(a.source, b.source);
    EXPECT_EQ(a.dcp.tpob_ft, b.dcp.tpob_ft);
    EXPECT_EQ(a.arm.upper_boom_ft, b.arm.upper_boom_ft);
    EXPECT_EQ(a.arm.p_RoB_R_ft, b.arm.p_RoB_R_ft);
    EXPECT_EQ(a.session.frame_rate_hz, b.session.frame_rate_hz);
    ASSERT_EQ(a.cameras.size(), b.cameras.size());
    for (std::size_t i = 0; i < a.cameras.size(); ++i) {
      EXPECT_EQ(a.cameras[i].tilt_min_deg, b.cameras[i].tilt_min_deg) << i;
      EXPECT_EQ(a.cameras[i].tilt_max_deg, b.cameras[i].tilt_max_deg) << i;
      EXPECT_EQ(a.cameras[i].name, b.cameras[i].name) << i;
    }
  }
  // The text parsed once is not changed by a design.
  EXPECT_EQ(designs.With({}, "none").dcp.tpob_ft, ParseConfig(DefaultText(), "none").dcp.tpob_ft);
  auto refusal = [](auto&& make) -> std::string {
    try {
      make();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  for (const auto& bad : std::vector<std::vector<ConfigSetting>>{
           {{"dcp.no_such_key", "1"}}, {{"dcp.tpob_ft", "\"wide\""}}, {{"dcp.tpob_ft", "-1"}}}) {
    const std::string a = refusal([&] { designs.With(bad, "cell"); });
    const std::string b = refusal(
        [&] { ParseConfig(ApplyConfigSettings(DefaultText(), "rmslab.toml", bad), "cell"); });
    EXPECT_FALSE(a.empty()) << bad[0].key << "=" << bad[0].value;
    EXPECT_EQ(a, b);
  }
}

// A file that cannot be read says why: a folder (which opens, and reads
// as nothing), or what the open's errno says.
TEST(ReadTextFile, SaysWhyAFileCannotBeRead) {
  const std::string dir = ::testing::TempDir() + "/read_text_file_test";
  std::filesystem::create_directories(dir + "/config.toml");
  auto why = [](const std::string& path) {
    try {
      ReadTextFile(path, "the configuration file");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(read)");
  };
  EXPECT_EQ(why(dir + "/config.toml"), "cannot read the configuration file '" + dir +
                                           "/config.toml': a folder, not a regular file");
  EXPECT_EQ(why(dir + "/none.toml"), "cannot read the configuration file '" + dir +
                                         "/none.toml': No such file or directory");
  std::ofstream(dir + "/ok.toml") << "a = 1\n";
  EXPECT_EQ(ReadTextFile(dir + "/ok.toml", "x"), "a = 1\n");
  // A device without end is refused before it is read.
  EXPECT_EQ(why("/dev/zero"),
            "cannot read the configuration file '/dev/zero': a device, not a regular file");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rms
