#pragma once
// Shared by the fuzz targets (docs/security.md "Fuzzing"): the default
// configuration, loaded once, and a log-backed LCM with no files, through
// which a target publishes the fuzzer's bytes to a process's real handlers.
#include <cstdint>
#include <cstdlib>
#include <spdlog/spdlog.h>
#include <string>

#include "rms/base/config.h"
#include "rms/transport/lcm_interface.h"

namespace rms::fuzz {

inline const LabConfig& Config() {
  static const LabConfig config = [] {
    spdlog::set_level(spdlog::level::off);
    return LoadConfig(RMSLAB_DEFAULT_CONFIG_PATH);
  }();
  return config;
}

}  // namespace rms::fuzz
