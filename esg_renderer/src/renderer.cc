#include "rms/esg_renderer/renderer.h"

#include <algorithm>
#include <cmath>

#include "rms/base/check.h"
#include "rms/wire/priority_words.h"

namespace rms::esg_renderer {

scene_model::Rgb IdColor(int i) {
  return {static_cast<std::uint8_t>(20 + 7 * i), static_cast<std::uint8_t>(250 - 7 * i),
          static_cast<std::uint8_t>(40 + (i * 53) % 200)};
}

int ClusterOfColor(const std::uint8_t* rgb) {
  const int i = (rgb[0] - 20) / 7;
  if (i < 0 || i >= scene_model::kNumClusters) return -1;
  const scene_model::Rgb c = IdColor(i);
  return (c[0] == rgb[0] && c[1] == rgb[1] && c[2] == rgb[2]) ? i : -1;
}

Eigen::Matrix4d ViewMatrix(const wire::EsgFrameData& f) {
  // Eye frame E (X line of sight, Y right, Z down) to GL eye coordinates
  // (x right, y up, z toward the viewer).
  Eigen::Matrix3d M;
  M << 0, 1, 0, 0, 0, -1, -1, 0, 0;
  const Eigen::Matrix3d R = M * f.R_RE.transpose();
  Eigen::Matrix4d V = Eigen::Matrix4d::Identity();
  V.topLeftCorner<3, 3>() = R;
  V.topRightCorner<3, 1>() = -R * f.p_RoEye_R_ft;
  return V;
}

Eigen::Matrix4d ProjectionMatrix(double fov_deg, double aspect, double n, double far) {
  const double fy = 1.0 / std::tan(0.5 * fov_deg * M_PI / 180.0);
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = fy / aspect;
  P(1, 1) = fy;
  P(2, 2) = (far + n) / (n - far);
  P(2, 3) = 2.0 * far * n / (n - far);
  P(3, 2) = -1.0;
  return P;
}

FrameRenderer::FrameRenderer(const LabConfig& config, GlContext* context, RenderOptions options)
    : config_(config),
      context_(context),
      gl_(context->gl()),
      options_(options),
      model_(scene_model::BuildSceneModel(config)) {
  sun_R_ = Eigen::Vector3f(-0.35f, 0.45f, 1.0f).normalized();
  context_->MakeCurrent();
  for (const scene_model::Cluster& c : model_.clusters) {
    GpuCluster g;
    g.id = c.id;
    // The cluster's edges as pairs of its points, for near-plane clipping.
    auto index_of = [&](const Eigen::Vector3f& v) {
      int best = 0;
      double dist = 1e30;
      for (std::size_t i = 0; i < c.points.size(); ++i) {
        const double dd = (c.points[i] - v.cast<double>()).squaredNorm();
        if (dd < dist) {
          dist = dd;
          best = static_cast<int>(i);
        }
      }
      return best;
    };
    for (const scene_model::Triangle& t : c.mesh.triangles()) {
      const int ia = index_of(t.a), ib = index_of(t.b), ic = index_of(t.c);
      for (auto e : {std::pair{ia, ib}, std::pair{ib, ic}, std::pair{ic, ia}}) {
        if (e.first > e.second) std::swap(e.first, e.second);
        if (std::find(g.edges.begin(), g.edges.end(), e) == g.edges.end()) g.edges.push_back(e);
      }
    }
    for (bool decals : {false, true}) {  // base faces first, decals after
      for (const scene_model::Triangle& t : c.mesh.triangles()) {
        if (t.decal != decals) continue;
        for (const Eigen::Vector3f* v : {&t.a, &t.b, &t.c})
          g.xyz.insert(g.xyz.end(), {v->x(), v->y(), v->z()});
        g.n.push_back(t.n);
        g.rgb.push_back(options_.id_colors ? IdColor(c.id) : t.rgb);
      }
    }
    g.colours.resize(g.rgb.size() * 9);
    gpu_.push_back(std::move(g));
  }
  gl_.Disable(GL_LIGHTING);
  gl_.ShadeModel(GL_FLAT);
  gl_.DepthFunc(GL_LEQUAL);
  gl_.CullFace(GL_BACK);
  gl_.FrontFace(GL_CCW);
  gl_.EnableClientState(GL_VERTEX_ARRAY);
  gl_.EnableClientState(GL_COLOR_ARRAY);
}

std::size_t FrameRenderer::triangle_count() const {
  std::size_t n = 0;
  for (const GpuCluster& c : gpu_) n += c.n.size();
  return n;
}

void FrameRenderer::DrawCluster(GpuCluster& c, const Eigen::Affine3d& X,
                                const Eigen::Matrix4d& view) {
  // Flat shading: one lit colour a triangle from its Reference normal.
  const Eigen::Matrix3f R = X.linear().inverse().transpose().cast<float>();
  constexpr float kAmbient = 0.30f, kDiffuse = 0.70f;
  for (std::size_t i = 0; i < c.n.size(); ++i) {
    float k = 1.0f;
    if (!options_.id_colors)
      k = kAmbient + kDiffuse * std::max(0.0f, (R * c.n[i]).normalized().dot(sun_R_));
    for (int ch = 0; ch < 3; ++ch) {
      const auto v = static_cast<std::uint8_t>(std::min(255.0f, c.rgb[i][ch] * k + 0.5f));
      c.colours[9 * i + ch] = c.colours[9 * i + 3 + ch] = c.colours[9 * i + 6 + ch] = v;
    }
  }
  const Eigen::Matrix4d mv = view * X.matrix();
  gl_.LoadMatrixd(mv.data());
  gl_.VertexPointer(3, GL_FLOAT, 0, c.xyz.data());
  gl_.ColorPointer(3, GL_UNSIGNED_BYTE, 0, c.colours.data());
  gl_.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(c.n.size() * 3));
  stats_.triangles_submitted += static_cast<int>(c.n.size());
}

// What of the cluster lies in front of the near plane, projected (its
// vertices there and where its edges cross the near plane); culled when all
// of it lies beyond one plane of the view volume, or when it is a flat,
// one-sided cluster seen from behind.
ScreenBox FrameRenderer::Silhouette(int c, const scene_model::ClusterPoses& poses,
                                    const wire::EsgFrameData& f, const Eigen::Matrix4d& view,
                                    const Eigen::Matrix4d& P) {
  ScreenBox b;
  const scene_model::Cluster& model = model_[c];
  const Eigen::Matrix4d VM = view * poses.X_RC[c].matrix();
  if (options_.backface_cull && model.flat) {
    const Eigen::Vector3d n_R =
        (poses.X_RC[c].linear().inverse().transpose() * model.normals[0]).normalized();
    const Eigen::Vector3d p_R = poses.X_RC[c] * model.points[0];
    if (n_R.dot(f.p_RoEye_R_ft - p_R) <= 0) {
      ++stats_.clusters_backfacing;
      return b;
    }
  }
  std::vector<Eigen::Vector3d> eye_pts;
  eye_pts.reserve(model.points.size());
  unsigned outside_all = 0x3F;
  for (const Eigen::Vector3d& p : model.points) {
    const Eigen::Vector4d e = VM * p.homogeneous();
    eye_pts.push_back(e.head<3>());
    const Eigen::Vector4d q = P * e;
    unsigned out = 0;
    if (q.x() < -q.w()) out |= 1;
    if (q.x() > q.w()) out |= 2;
    if (q.y() < -q.w()) out |= 4;
    if (q.y() > q.w()) out |= 8;
    if (q.z() < -q.w()) out |= 16;
    if (q.z() > q.w()) out |= 32;
    outside_all &= out;
  }
  if (options_.frustum_cull && outside_all != 0) {
    ++stats_.clusters_culled;
    return b;
  }
  // Eye coordinates look down -z; in front of the near plane: z < -near.
  const double zn = -kNearFt;
  std::vector<Eigen::Vector3d> front;
  for (const auto& e : eye_pts) {
    if (e.z() < zn) front.push_back(e);
  }
  if (front.size() != eye_pts.size()) {
    for (const auto& [i, j] : gpu_[c].edges) {
      const Eigen::Vector3d &a = eye_pts[i], &bb = eye_pts[j];
      if ((a.z() < zn) != (bb.z() < zn))
        front.push_back(a + (zn - a.z()) / (bb.z() - a.z()) * (bb - a));
    }
  }
  if (front.empty()) {  // all behind the eye
    ++stats_.clusters_culled;
    return b;
  }
  b.visible = true;
  std::vector<Eigen::Vector2f> projected;
  float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
  for (const auto& e : front) {
    const Eigen::Vector4d q = P * e.homogeneous();
    const float sx = static_cast<float>(q.x() / q.w()), sy = static_cast<float>(q.y() / q.w());
    x0 = std::min(x0, sx);
    x1 = std::max(x1, sx);
    y0 = std::min(y0, sy);
    y1 = std::max(y1, sy);
    projected.emplace_back(sx, sy);
  }
  b.x0 = x0;
  b.y0 = y0;
  b.x1 = x1;
  b.y1 = y1;
  b.outline = ConvexHull2d(std::move(projected));
  return b;
}

void FrameRenderer::DrawInOrder(const wire::EsgFrameData& f, const scene_model::ClusterPoses& poses,
                                const std::array<ScreenBox, scene_model::kNumClusters>& boxes,
                                const Eigen::Matrix4d& view, const Eigen::Matrix4d& P) {
  gl_.Viewport(0, 0, context_->width(), context_->height());
  gl_.ClearColor(0, 0, 0, 1);
  if (options_.backface_cull)
    gl_.Enable(GL_CULL_FACE);
  else
    gl_.Disable(GL_CULL_FACE);
  // The priority bits order the clusters (silhouettes that only share an
  // edge, within rounding, need no order). The ESG's way draws them so with
  // no depth buffer; the reference draws them in the same order with the
  // depth test on, so faces that touch resolve the same way in both and
  // every pixel the depth test changes is a priority error.
  const scene_model::PriorityBits bits = wire::UnpackPriority(f.control, f.priority_words);
  order_ = DrawOrder(bits, boxes, &stats_.cycles_broken, 1e-6f);
  if (options_.visibility == Visibility::kDepth) {
    gl_.Enable(GL_DEPTH_TEST);
    gl_.DepthMask(GL_TRUE);
    gl_.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  } else {
    gl_.Disable(GL_DEPTH_TEST);
    gl_.Clear(GL_COLOR_BUFFER_BIT);
  }
  gl_.MatrixMode(GL_PROJECTION);
  gl_.LoadMatrixd(P.data());
  gl_.MatrixMode(GL_MODELVIEW);
  for (int c : order_) {
    DrawCluster(gpu_[c], poses.X_RC[c], view);
    ++stats_.clusters_drawn;
  }
}

void FrameRenderer::Render(const wire::EsgFrameData& f) {
  stats_ = {};
  context_->MakeCurrent();
  const int w = context_->width(), h = context_->height();
  if (f.control.no_video) {
    // The station is lost (docs/sessions.md "Malfunctions"): no picture.
    gl_.Viewport(0, 0, w, h);
    gl_.ClearColor(0, 0, 0, 1);
    gl_.Clear(GL_COLOR_BUFFER_BIT);
    order_.clear();
    return;
  }
  const Eigen::Matrix4d P =
      ProjectionMatrix(f.fov_deg, static_cast<double>(w) / h, kNearFt, kFarFt);
  const Eigen::Matrix4d view = ViewMatrix(f);
  const scene_model::ClusterPoses poses = scene_model::ComputeClusterPoses(config_, f.scene_pose());
  std::array<ScreenBox, scene_model::kNumClusters> boxes{};
  for (int c = 0; c < scene_model::kNumClusters; ++c) {
    if (poses.present[c]) boxes[c] = Silhouette(c, poses, f, view, P);
  }
  DrawInOrder(f, poses, boxes, view, P);
}

}  // namespace rms::esg_renderer
