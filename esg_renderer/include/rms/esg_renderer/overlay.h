#pragma once
// The ESG's overlay (docs/esg.md "Overlay"): the frame counter, the camera
// station, the mode and the collision / receptacle / acquired / docked
// indicators, drawn into the frame in a 5 x 7 dot font when the control
// word's OVERLAY bit is set; the crosshairs of the wrist and port cameras
// when its CROSSHAIRS bit is set; and, in the live window only, the operator
// station's guidance (RMS_OPERATOR_STATE).
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rms/base/config.h"
#include "rms/operator_state_t.hpp"
#include "rms/scene_model/mesh.h"
#include "rms/wire/word_blocks.h"

namespace rms::esg_renderer {

// Draws `text` (A-Z, 0-9, space, - : . / ,; others as blanks) with its top
// left at (x, y), each dot `scale` pixels square, into an RGBA image.
void DrawText(std::uint8_t* rgba, int width, int height, int x, int y, std::string_view text,
              const scene_model::Rgb& colour, int scale);
void FillRect(std::uint8_t* rgba, int width, int height, int x0, int y0, int x1, int y1,
              const scene_model::Rgb& colour);

// A line from (x0, y0) to (x1, y1), `thick` pixels wide.
void DrawLine(std::uint8_t* rgba, int width, int height, int x0, int y0, int x1, int y1,
              const scene_model::Rgb& colour, int thick);

// What the overlay needs of the configuration, from its static models.
struct OverlayModel {
  std::vector<std::string> camera_names;  // the stations' names, config order
  std::vector<CameraMount> mounts;        // and mounts: crosshairs on "wrist" and "cae" stations
  // Where the grapple target's cross is, in System Two, when the end
  // effector holds the bar at the grasp: the wrist camera's crosshair.
  Eigen::Vector3d p_S2oT_S2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_RoPort_R = Eigen::Vector3d::Zero();  // the docking port's centre
  Eigen::Vector3d y_port_R = Eigen::Vector3d::UnitZ();   // its axis, into the CAE
  ArmGeometry arm;
};
OverlayModel MakeOverlayModel(const LabConfig& config);

// Where a point in R appears in the frame's image, pixels (x right, y down);
// false when it is behind the eye.
bool ProjectToImage(const wire::EsgFrameData& frame, int width, int height,
                    const Eigen::Vector3d& p_R, double* x, double* y);

// The pixels under the frame counter as they were just before it was drawn
// (docs/esg.md "Skipping what the scene does not need"): a frame whose words
// but the counter equal the last one's has the same overlay but for the
// counter, and all of it is drawn opaque, so the last output image with
// these put back and the overlay drawn again is the image a full redraw
// gives, without copying the scene.
struct CounterBackdrop {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the rectangle, pixels (x1, y1 past its end)
  std::vector<std::uint8_t> rgba;      // its pixels, rows top down
};
void RestoreCounterBackdrop(std::uint8_t* rgba, int width, int height, const CounterBackdrop& b);

// The overlay over the frame's image; `backdrop`, if given, takes the pixels
// under the frame counter first (an empty rectangle when none is drawn).
void DrawOverlay(std::uint8_t* rgba, int width, int height, const wire::EsgFrameData& frame,
                 const OverlayModel& model, CounterBackdrop* backdrop = nullptr);

// The crosshairs (control word CROSSHAIRS, docs/esg.md "Crosshairs"): on a
// wrist camera, a cross where the grapple target's cross appears when the
// end effector is at the grasp (align the two); on a camera at the CAE, the
// port's axis out to 12 ft with a tick every 2 ft (the probe's tip rides
// along it).
void DrawCrosshairs(std::uint8_t* rgba, int width, int height, const wire::EsgFrameData& frame,
                    const OverlayModel& model);

// The operator station's guidance, a panel at the image's foot (the live
// window only; docs/operator.md "Guidance").
void DrawGuidance(std::uint8_t* rgba, int width, int height, const operator_state_t& state);

}  // namespace rms::esg_renderer
