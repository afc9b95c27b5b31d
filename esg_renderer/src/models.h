#pragma once
// The ESG's static model data (docs/esg.md): every object's mesh in its own
// frame, built once from the configuration. Per frame, the renderer poses
// them from the ESG frame's words alone.
#include <array>
#include <string_view>
#include <vector>

#include "mesh.h"
#include "rms/config.h"

namespace rms::esg {

// Object identities; in --id-colors mode each is drawn in IdColor(id).
enum class PartId : int {
  kShuttle = 1,    // orbiter, cargo bay, doors (frame R)
  kVerticalArm,    // vertical fixed arm (frame at B, scaled to the shoulder height)
  kShoulder,       // shoulder housing (frame F1)
  kUpperBoom,      // frame F2
  kElbow,          // elbow housing (frame F3)
  kLowerBoom,      // frame F3
  kWrist,          // wrist housing and wrist link (frame F6)
  kEffHex1,        // palm (System Two)
  kEffHex2,        // fixed finger (System Two)
  kEffHex3,        // movable finger (System Two, shifted along Y2 by the finger gap)
  kPayload,        // payload body (payload frame P)
  kReceptacle,     // bar receptacle and its posts (P)
  kProbe,          // docking probe (P)
  kCae,            // central assembly element (CAE frame C)
  kCount
};
std::string_view PartName(PartId id);
Rgb IdColor(PartId id);

struct Part {
  PartId id;
  Mesh mesh;
};

struct StaticModels {
  std::vector<Part> parts;  // indexed by PartId - 1
  const Part& get(PartId id) const { return parts[static_cast<int>(id) - 1]; }
};

StaticModels BuildStaticModels(const LabConfig& config);

// Where EFF HEX 3 (built centred on Y2 = 0) sits along Y2 for a finger gap.
double MovingFingerCentreY2(const EndEffectorConfig& ee, double finger_gap_ft);

}  // namespace rms::esg
