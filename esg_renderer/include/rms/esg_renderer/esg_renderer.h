#pragma once
// esg_renderer's LCM side: RMS_ESG_FRAME in; renders the newest frame (frames
// that a newer one overtook before drawing are counted as superseded, never
// drawn late), re-renders only when the frame's words changed, draws the
// overlay, and sends the image to PNG files, the session's video and the live
// window.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rms/base/counters.h"
#include "rms/esg_frame_t.hpp"
#include "rms/esg_renderer/overlay.h"
#include "rms/esg_renderer/renderer.h"
#include "rms/esg_renderer/video.h"
#include "rms/esg_renderer/window.h"
#include "rms/operator_state_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/transport/process.h"
#include "rms/wire/frame_receiver.h"
#include "rms/wire/word_blocks.h"

namespace rms::esg_renderer {

struct EsgOptions {
  int width = 1024;
  int height = 768;
  std::string png_dir;        // --png-dir: where PNG frames go
  int png_every = 0;          // --png-every N: write every Nth ESG frame (by frame number); 0: none
  bool id_colors = false;     // --id-colors
  std::string gl = "osmesa";  // --gl osmesa|egl
  std::string visibility = "priority";  // --visibility priority|depth
  std::string video_path;               // --video FILE: the session's video
  bool window = false;                  // --window: a live window on the desktop
  bool skip_unchanged = true;           // --no-skip-unchanged turns off
  bool frustum_cull = true;             // --no-frustum-cull turns off
  bool backface_cull = true;            // --no-backface-cull turns off
};

class EsgRenderer {
 public:
  EsgRenderer(const LabConfig& config, transport::LcmInterface* lcm, FrameRenderer* renderer,
              EsgOptions options, VideoWriter* video, LiveWindow* window);
  void OnFrame(const void* data, int size, std::int64_t recv_time_us);
  // Renders the newest frame received since the last call, if any.
  bool RenderPending();
  // At the end, for the video: the frame still waiting is drawn, and frames
  // the renderer saw but did not draw at the very end (too late to act on)
  // repeat the last image, so the video has one frame per frame number.
  void FinishVideo();
  // The live window's events: its keys go out on RMS_WINDOW_KEYS at every
  // change and every 100 ms while one is held.
  void PollWindow();
  void OnOperatorState(const void* data, int size);

  Counters& counters() { return counters_; }
  const transport::LatencyMap& latencies() const { return latencies_; }
  std::int64_t last_rendered() const { return last_rendered_; }
  // A live session's receive checks (as DynamicsProc::EnableLiveChecks).
  void EnableLiveChecks(double frame_rate_hz);

 private:
  const LabConfig& config_;
  transport::LcmInterface* lcm_;
  FrameRenderer* renderer_;
  EsgOptions options_;
  VideoWriter* video_;
  LiveWindow* window_;
  OverlayModel overlay_;
  Counters counters_;
  transport::LatencyMap latencies_;
  wire::SequenceTracker frames_;
  wire::LateFrameFilter late_;
  std::optional<std::pair<esg_frame_t, wire::EsgFrameData>> pending_;
  std::int64_t last_rendered_ = -1;
  // The first frame number accepted: the video starts there even when that
  // frame was superseded before it could be drawn.
  std::int64_t first_frame_ = -1;
  std::vector<std::int32_t> last_words_;  // the words of the scene at image_
  // The last output image, overlay included: the renderer's own buffer, which
  // nothing else draws into (not copied: a frame is 3 MB at 1024x768), null
  // before the first frame drawn.
  std::uint8_t* image_ = nullptr;
  CounterBackdrop backdrop_;         // what lies under its frame counter
  std::vector<std::uint8_t> shown_;  // the window's: the output and the operator's guidance
  std::optional<operator_state_t>
      operator_state_;  // the newest RMS_OPERATOR_STATE (the window's guidance)
  std::int64_t keys_sequence_ = 0, keys_sent_us_ = 0;
  bool keys_held_ = false;
};

int RunEsgRenderer(const LabConfig& config, transport::LcmInterface& lcm, const EsgOptions& options,
                   const std::string& stats_path, const std::string& ready_path);

}  // namespace rms::esg_renderer
