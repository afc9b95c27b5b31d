// esg_renderer: the Electronic Scene Generator. RMS_ESG_FRAME in, images out.
// A thin main over esg_renderer/src; see docs/esg.md.
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <filesystem>

#include "rms/esg_renderer/esg_renderer.h"
#include "rms/transport/process.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab esg_renderer: the Electronic Scene Generator. Renders each ESG frame "
      "(RMS_ESG_FRAME) from its words and the static models, headless (OSMesa or EGL), "
      "with visibility by separating-plane priority, to PNG, video and a live window."};
  rms::transport::CommonOptions common;
  rms::esg_renderer::EsgOptions opt;
  app.add_option("--width", opt.width, "Image width, pixels")
      ->capture_default_str()
      ->check(CLI::Range(16, 8192));
  app.add_option("--height", opt.height, "Image height, pixels")
      ->capture_default_str()
      ->check(CLI::Range(16, 8192));
  app.add_option("--png-dir", opt.png_dir, "Directory for PNG frames (frame_NNNNNN.png)");
  app.add_option("--png-every", opt.png_every, "Write every Nth frame as PNG (0: none)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--video", opt.video_path,
                 "Write the session's video to this file (H.264 via ffmpeg)");
  app.add_flag("--window", opt.window, "Show the frames in a live window on the desktop (SDL2)");
  app.add_option("--gl", opt.gl, "GL backend: osmesa or egl (EGL surfaceless)")
      ->capture_default_str()
      ->check(CLI::IsMember({"osmesa", "egl"}));
  app.add_option(
         "--visibility", opt.visibility,
         "priority (separating planes, no depth buffer: the ESG's way) or depth (the reference)")
      ->capture_default_str()
      ->check(CLI::IsMember({"priority", "depth"}));
  app.add_flag("--id-colors", opt.id_colors, "Draw each cluster in a flat identity colour (tests)");
  bool no_skip = false, no_frustum = false, no_backface = false;
  app.add_flag("--no-skip-unchanged", no_skip, "Re-render frames whose words did not change");
  app.add_flag("--no-frustum-cull", no_frustum, "Draw clusters outside the view volume too");
  app.add_flag("--no-backface-cull", no_backface, "Draw faces turned away too");
  return rms::transport::ProcessMain(
      app, argc, argv, "esg_renderer", &common,
      [&](const rms::LabConfig& config, rms::transport::LcmInterface& lcm) {
        // Restarted by the launcher after a fault (RMSLAB_RESTART=N): the
        // video so far is kept; this run's goes beside it, NAME.restartN.mp4.
        if (const char* r = std::getenv("RMSLAB_RESTART");
            r && *r && std::string(r) != "0" && !opt.video_path.empty()) {
          const std::filesystem::path v(opt.video_path);
          opt.video_path =
              (v.parent_path() / (v.stem().string() + ".restart" + r + v.extension().string()))
                  .string();
        }
        opt.skip_unchanged = !no_skip;
        opt.frustum_cull = !no_frustum;
        opt.backface_cull = !no_backface;
        return rms::esg_renderer::RunEsgRenderer(config, lcm, opt, common.stats_path,
                                                 common.ready_path);
      });
}
