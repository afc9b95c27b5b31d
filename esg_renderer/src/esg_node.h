#pragma once
// esg_renderer's LCM side: RMS_ESG_FRAME in; renders the newest frame (frames
// that a newer one overtook before drawing are counted as superseded), writes
// PNG frames on request, and measures latency.
#include <cstdint>
#include <optional>
#include <string>

#include "renderer.h"
#include "rms/counters.h"
#include "rms/esg_frame_t.hpp"
#include "rms/lcm_interface.h"
#include "rms/process.h"
#include "rms/word_blocks.h"

namespace rms::esg {

struct EsgOptions {
  int width = 1024;
  int height = 768;
  std::string png_dir;  // --png-dir: where PNG frames go
  int png_every = 0;    // --png-every N: write every Nth ESG frame (by frame number); 0: none
  bool id_colors = false;
};

class EsgNode {
 public:
  EsgNode(const LabConfig& config, LcmInterface* lcm, EsgRenderer* renderer, EsgOptions options);
  void OnFrame(const void* data, int size, std::int64_t recv_time_us);
  // Renders the newest frame received since the last call, if any.
  bool RenderPending();

  Counters& counters() { return counters_; }
  const LatencyMap& latencies() const { return latencies_; }
  std::int64_t last_rendered() const { return last_rendered_; }

 private:
  LcmInterface* lcm_;
  EsgRenderer* renderer_;
  EsgOptions options_;
  Counters counters_;
  LatencyMap latencies_;
  SequenceTracker frames_;
  std::optional<std::pair<esg_frame_t, EsgFrameData>> pending_;
  std::int64_t last_rendered_ = -1;
};

int RunEsgRenderer(const LabConfig& config, LcmInterface& lcm, const EsgOptions& options,
                   const std::string& stats_path, const std::string& ready_path);

}  // namespace rms::esg
