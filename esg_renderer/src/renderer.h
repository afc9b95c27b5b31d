#pragma once
// The Electronic Scene Generator's drawing: the scene from one ESG frame's
// words plus the static models, flat-shaded, with OpenGL's fixed-function
// pipeline on a GlContext (docs/esg.md).
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "gl_context.h"
#include "models.h"
#include "rms/config.h"
#include "rms/word_blocks.h"

namespace rms::esg {

struct RenderOptions {
  // Draw every object in its flat IdColor, unlit (for tests and tools).
  bool id_colors = false;
};

// Each part's pose in R for a frame (affine: the vertical fixed arm is scaled
// to the shoulder height), indexed by PartId - 1.
using PartPoses = std::array<Eigen::Affine3d, static_cast<int>(PartId::kCount) - 1>;
PartPoses ComputePartPoses(const LabConfig& config, const EsgFrameData& frame);

// The GL matrices for a frame's view (column-major, for glLoadMatrixd).
Eigen::Matrix4d ViewMatrix(const EsgFrameData& frame);
Eigen::Matrix4d ProjectionMatrix(double fov_deg, double aspect, double near_ft, double far_ft);

class EsgRenderer {
 public:
  EsgRenderer(const LabConfig& config, GlContext* context, RenderOptions options);
  // Draws the frame. The pixels stay valid until the next Render.
  void Render(const EsgFrameData& frame);
  const std::uint8_t* pixels() { return context_->FinishAndGetPixels(); }
  int width() const { return context_->width(); }
  int height() const { return context_->height(); }
  std::size_t triangle_count() const;

  static constexpr double kNearFt = 0.5;
  static constexpr double kFarFt = 5000.0;

 private:
  struct GpuPart {
    PartId id;
    std::vector<float> xyz;             // 9 floats a triangle, part frame
    std::vector<Eigen::Vector3f> n;     // normal a triangle, part frame
    std::vector<Rgb> rgb;               // colour a triangle
    std::vector<std::uint8_t> colours;  // 9 bytes a triangle, this frame's lit colours
  };
  void DrawPart(GpuPart& part, const Eigen::Affine3d& X_RPart, const Eigen::Matrix4d& view);

  const LabConfig& config_;
  GlContext* context_;
  RenderOptions options_;
  StaticModels models_;
  std::vector<GpuPart> parts_;
  Eigen::Vector3f sun_R_;
};

}  // namespace rms::esg
