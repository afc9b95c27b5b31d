#pragma once
// The Electronic Scene Generator's drawing (docs/esg.md): the scene from one
// ESG frame's words and the static model data, flat-shaded, on a GlContext.
//
// Visibility: in priority mode (the ESG's way, the default) clusters are drawn
// back to front in the order the frame's priority bits select, with no depth
// buffer; depth mode uses a depth buffer instead and is the reference the
// priority mode is measured against.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "rms/base/config.h"
#include "rms/esg_renderer/draw_order.h"
#include "rms/esg_renderer/gl_context.h"
#include "rms/scene_model/scene_model.h"
#include "rms/wire/word_blocks.h"

namespace rms::esg_renderer {

enum class Visibility { kPriority, kDepth };

struct RenderOptions {
  Visibility visibility = Visibility::kPriority;
  bool id_colors = false;     // each cluster in its flat IdColor, unlit (tests and tools)
  bool frustum_cull = true;   // skip clusters outside the view volume
  bool backface_cull = true;  // skip faces turned away
};

// The GL matrices for a frame's view (column-major, for glLoadMatrixd).
Eigen::Matrix4d ViewMatrix(const wire::EsgFrameData& frame);
Eigen::Matrix4d ProjectionMatrix(double fov_deg, double aspect, double near_ft, double far_ft);

// Identity colours: cluster id i is drawn in IdColor(i) in id-colour mode.
scene_model::Rgb IdColor(int cluster);
// The cluster an id colour belongs to, or -1 (black, or not an id colour).
int ClusterOfColor(const std::uint8_t* rgb);

struct RenderStats {
  int clusters_drawn = 0;
  int clusters_culled = 0;      // outside the view volume
  int clusters_backfacing = 0;  // flat clusters seen from behind
  int triangles_submitted = 0;
  int cycles_broken = 0;  // priority cycles (none in a well-formed scene)
};

class FrameRenderer {
 public:
  FrameRenderer(const LabConfig& config, GlContext* context, RenderOptions options);
  void Render(const wire::EsgFrameData& frame);
  // The last Render's pixels, RGBA, rows top down: the context's own
  // buffer, valid until the next Render on it. The caller may draw over them
  // (the ESG draws its overlay there, and keeps the image between frames).
  std::uint8_t* pixels() {
    context_->MakeCurrent();
    return context_->FinishAndGetPixels();
  }
  int width() const { return context_->width(); }
  int height() const { return context_->height(); }
  const RenderStats& stats() const { return stats_; }
  const std::vector<int>& last_order() const { return order_; }
  std::size_t triangle_count() const;
  RenderOptions& options() { return options_; }

  static constexpr double kNearFt = 0.5;
  static constexpr double kFarFt = 5000.0;

 private:
  struct GpuCluster {
    int id;
    std::vector<std::pair<int, int>> edges;  // pairs of indices into the model's points
    std::vector<float> xyz;          // 9 floats a triangle, cluster frame; base faces then decals
    std::vector<Eigen::Vector3f> n;  // a triangle's normal
    std::vector<scene_model::Rgb> rgb;  // a triangle's colour
    std::vector<std::uint8_t> colours;
  };
  void DrawCluster(GpuCluster& c, const Eigen::Affine3d& X_RC, const Eigen::Matrix4d& view);
  // Cluster c's silhouette on the screen (view: R to eye; P: projection);
  // not visible, and counted, when culled.
  ScreenBox Silhouette(int c, const scene_model::ClusterPoses& poses, const wire::EsgFrameData& f,
                       const Eigen::Matrix4d& view, const Eigen::Matrix4d& P);
  // The clusters drawn in the order the frame's priority bits give.
  void DrawInOrder(const wire::EsgFrameData& f, const scene_model::ClusterPoses& poses,
                   const std::array<ScreenBox, scene_model::kNumClusters>& boxes,
                   const Eigen::Matrix4d& view, const Eigen::Matrix4d& P);

  const LabConfig& config_;
  GlContext* context_;
  const GlApi& gl_;
  RenderOptions options_;
  scene_model::SceneModel model_;
  std::vector<GpuCluster> gpu_;
  Eigen::Vector3f sun_R_;
  RenderStats stats_;
  std::vector<int> order_;
};

}  // namespace rms::esg_renderer
