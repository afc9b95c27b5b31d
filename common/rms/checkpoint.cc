#include "rms/checkpoint.h"

#include <fstream>
#include <iterator>

#include "rms/check.h"

namespace rms {

namespace {
constexpr const char* kFormat = "rmslab-checkpoint-1";
}  // namespace

void WriteCheckpoint(const std::string& path, const Checkpoint& c) {
  nlohmann::ordered_json j;
  j["format"] = kFormat;
  j["saved_us"] = c.saved_us;
  j["dcp_frame"] = c.dcp_frame;
  j["input_frame"] = c.input_frame;
  j["config"] = c.config;
  nlohmann::ordered_json in;
  for (int i = 0; i < kNumAnalogInputs; ++i) in[std::string(kAnalogInputNames[i])] = c.inputs.value[i];
  in["camera_station"] = c.inputs.camera_station;
  in["overlay"] = c.inputs.overlay;
  in["crosshairs"] = c.inputs.crosshairs;
  j["operator_inputs"] = in;
  j["dcp"] = c.dcp;
  std::ofstream f(path);
  if (f) f << j.dump(2) << "\n";
  if (!f) throw InputError("cannot write checkpoint '" + path + "'");
}

Checkpoint ReadCheckpoint(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw InputError("cannot read checkpoint '" + path + "'");
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  return ParseCheckpoint(text, path);
}

Checkpoint ParseCheckpoint(std::string_view text, const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    throw InputError("checkpoint '" + path + "' is not JSON: " + e.what());
  }
  if (!j.is_object() || j.value("format", "") != kFormat) {
    throw InputError("checkpoint '" + path + "': not an rmslab checkpoint (\"format\" must be \"" + kFormat + "\")");
  }
  Checkpoint c;
  try {
    c.saved_us = j.at("saved_us").get<std::int64_t>();
    c.dcp_frame = j.at("dcp_frame").get<std::int64_t>();
    c.input_frame = j.at("input_frame").get<std::int64_t>();
    c.config = j.at("config").get<std::string>();
    const auto& o = j.at("operator_inputs");
    for (int i = 0; i < kNumAnalogInputs; ++i) c.inputs.value[i] = o.at(std::string(kAnalogInputNames[i])).get<double>();
    c.inputs.camera_station = o.at("camera_station").get<int>();
    c.inputs.overlay = o.at("overlay").get<bool>();
    c.inputs.crosshairs = o.value("crosshairs", false);  // absent before the crosshairs switch
    c.dcp = j.at("dcp");
  } catch (const std::exception& e) {
    throw InputError("checkpoint '" + path + "': " + e.what());
  }
  return c;
}

}  // namespace rms
