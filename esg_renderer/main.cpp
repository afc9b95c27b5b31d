// esg_renderer: the Electronic Scene Generator. RMS_ESG_FRAME in, images out.
// A thin main over esg_renderer/src; see docs/esg.md.
#include <CLI/CLI.hpp>

#include "esg_node.h"
#include "rms/process.h"

int main(int argc, char** argv) {
  CLI::App app{"rmslab esg_renderer: the Electronic Scene Generator. Renders each ESG frame "
               "(RMS_ESG_FRAME) from its words and the static models with OSMesa (headless), "
               "and writes PNG frames on request."};
  rms::CommonOptions common;
  rms::esg::EsgOptions opt;
  app.add_option("--width", opt.width, "Image width, pixels")->capture_default_str()->check(CLI::Range(16, 8192));
  app.add_option("--height", opt.height, "Image height, pixels")->capture_default_str()->check(CLI::Range(16, 8192));
  app.add_option("--png-dir", opt.png_dir, "Directory for PNG frames (frame_NNNNNN.png)");
  app.add_option("--png-every", opt.png_every, "Write every Nth frame as PNG (0: none)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--id-colors", opt.id_colors, "Draw each object in a flat identity colour (tests)");
  return rms::ProcessMain(app, argc, argv, "esg_renderer", &common,
                          [&](const rms::LabConfig& config, rms::LcmInterface& lcm) {
                            return rms::esg::RunEsgRenderer(config, lcm, opt, common.stats_path,
                                                            common.ready_path);
                          });
}
