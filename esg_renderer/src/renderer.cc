#include "renderer.h"

#include <GL/gl.h>

#include <algorithm>
#include <cmath>

#include "rms/check.h"

namespace rms::esg {

PartPoses ComputePartPoses(const LabConfig& config, const EsgFrameData& f) {
  const ArmPose arm = ComputeArmPose(config.arm, f.arm, f.shoulder_height_ft);
  PartPoses p;
  auto set = [&](PartId id, const Eigen::Affine3d& X) { p[static_cast<int>(id) - 1] = X; };
  auto iso = [](const Eigen::Isometry3d& X) { return Eigen::Affine3d(X.matrix()); };
  set(PartId::kShuttle, Eigen::Affine3d::Identity());
  Eigen::Affine3d post = Eigen::Affine3d::Identity();
  post.translation() = arm.p_RoB_R;
  post.linear() = Eigen::Vector3d(1, 1, std::max(f.shoulder_height_ft, 0.0)).asDiagonal();
  set(PartId::kVerticalArm, post);
  set(PartId::kShoulder, iso(arm.X_RF1));
  set(PartId::kUpperBoom, iso(arm.X_RF2));
  set(PartId::kElbow, iso(arm.X_RF3));
  set(PartId::kLowerBoom, iso(arm.X_RF3));
  set(PartId::kWrist, iso(arm.X_RF6));
  set(PartId::kEffHex1, iso(arm.X_RS2));
  set(PartId::kEffHex2, iso(arm.X_RS2));
  set(PartId::kEffHex3,
      iso(arm.X_RS2) * Eigen::Translation3d(0, MovingFingerCentreY2(config.end_effector, f.finger_gap_ft), 0));
  Eigen::Affine3d X_RP = Eigen::Affine3d::Identity();
  X_RP.linear() = f.R_RP;
  X_RP.translation() = f.p_RoPo_R_ft;
  set(PartId::kPayload, X_RP);
  set(PartId::kReceptacle, X_RP);
  set(PartId::kProbe, X_RP);
  Eigen::Affine3d X_RC = Eigen::Affine3d::Identity();
  X_RC.linear() = config.cae.R_RC;
  X_RC.translation() = config.cae.p_RoCo_R_ft;
  set(PartId::kCae, X_RC);
  return p;
}

Eigen::Matrix4d ViewMatrix(const EsgFrameData& f) {
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

EsgRenderer::EsgRenderer(const LabConfig& config, GlContext* context, RenderOptions options)
    : config_(config), context_(context), options_(options), models_(BuildStaticModels(config)) {
  sun_R_ = Eigen::Vector3f(-0.35f, 0.45f, 1.0f).normalized();
  for (const Part& part : models_.parts) {
    GpuPart g;
    g.id = part.id;
    for (const Triangle& t : part.mesh.triangles()) {
      for (const Eigen::Vector3f* v : {&t.a, &t.b, &t.c}) {
        g.xyz.insert(g.xyz.end(), {v->x(), v->y(), v->z()});
      }
      g.n.push_back(t.n);
      g.rgb.push_back(options_.id_colors ? IdColor(part.id) : t.rgb);
    }
    g.colours.resize(g.rgb.size() * 9);
    parts_.push_back(std::move(g));
  }
  glDisable(GL_LIGHTING);
  glShadeModel(GL_FLAT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_COLOR_ARRAY);
}

std::size_t EsgRenderer::triangle_count() const {
  std::size_t n = 0;
  for (const GpuPart& p : parts_) n += p.n.size();
  return n;
}

void EsgRenderer::DrawPart(GpuPart& part, const Eigen::Affine3d& X_RPart,
                           const Eigen::Matrix4d& view) {
  // Flat shading: one lit colour a triangle from its world-space normal.
  const bool scaled = part.id == PartId::kVerticalArm;  // axis-aligned scale keeps box normals
  const Eigen::Matrix3f R = scaled ? Eigen::Matrix3f(Eigen::Matrix3f::Identity())
                                   : Eigen::Matrix3f(X_RPart.linear().cast<float>());
  constexpr float kAmbient = 0.30f, kDiffuse = 0.70f;
  for (std::size_t i = 0; i < part.n.size(); ++i) {
    float k = 1.0f;
    if (!options_.id_colors) {
      k = kAmbient + kDiffuse * std::max(0.0f, (R * part.n[i]).dot(sun_R_));
    }
    for (int c = 0; c < 3; ++c) {
      const auto v = static_cast<std::uint8_t>(std::min(255.0f, part.rgb[i][c] * k + 0.5f));
      part.colours[9 * i + c] = part.colours[9 * i + 3 + c] = part.colours[9 * i + 6 + c] = v;
    }
  }
  const Eigen::Matrix4d mv = view * X_RPart.matrix();
  glLoadMatrixd(mv.data());
  glVertexPointer(3, GL_FLOAT, 0, part.xyz.data());
  glColorPointer(3, GL_UNSIGNED_BYTE, 0, part.colours.data());
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(part.n.size() * 3));
}

void EsgRenderer::Render(const EsgFrameData& f) {
  const int w = context_->width(), h = context_->height();
  glViewport(0, 0, w, h);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glMatrixMode(GL_PROJECTION);
  const Eigen::Matrix4d P = ProjectionMatrix(f.fov_deg, static_cast<double>(w) / h, kNearFt, kFarFt);
  glLoadMatrixd(P.data());
  glMatrixMode(GL_MODELVIEW);
  const Eigen::Matrix4d view = ViewMatrix(f);
  const PartPoses poses = ComputePartPoses(config_, f);
  for (GpuPart& part : parts_) {
    if (part.id == PartId::kVerticalArm && f.shoulder_height_ft <= 0.0) continue;
    DrawPart(part, poses[static_cast<int>(part.id) - 1], view);
  }
}

}  // namespace rms::esg
