#pragma once
// The DYNAMIC COLLISION PROGRAM (report, Section IV; docs/collision.md).
//
// Each frame it processes the operator's inputs (IV.B) as the master arm's
// command, generates the models of the active mode in Reference coordinates
// (IV.A.2), tests the mode's pairs with the hexahedron collision algorithm
// (IV.A.1) and decides acquisition, extraction and docking (IV.A.3):
//
//  Mode 1  EFF HEX 1-3 against the BAR (RECPT) and the payload's body; the
//          six acquisition conditions -> Mode 2, payload rigidly attached.
//  Mode 2  the payload's and probe's vertices against the cargo bay's walls
//          and bottom; all above face c -> Mode 3.
//  Mode 3  the payload's and probe's vertices against the CAE's front half;
//          all probe vertices in the docking envelope, within the distance
//          and the angle -> docked.
//
// Collision response: the slave arm (what the scene shows) follows the master
// while the master's command is collision-free; while it would collide, the
// slave holds its last collision-free pose (in Mode 1 the arm may still
// follow with only the finger held) and the collision bits say which pair,
// so the operator can relieve it. A collision never shows as
// interpenetration. The finger closing on the bar is the essential contact:
// the finger stops on it and the acquisition conditions are met.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>

#include "rms/arm/kinematics.h"
#include "rms/base/config.h"
#include "rms/dcp_model/collision.h"
#include "rms/dcp_model/dcp_models.h"
#include "rms/dcp_model/malfunctions.h"
#include "rms/wire/acquisition_conditions.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/input_block.h"
#include "rms/wire/word_blocks.h"

namespace rms::dcp_model {

// The finger stops this far short of touching the bar once acquired (above
// the finger gap word's resolution, so the bar and finger never overlap).
inline constexpr double kFingerContactClearanceFt = 0.01;
// Opening the finger kReleaseOpeningFt (rms/config.h) past the acquisition
// gap lets the payload go: at the dock, or anywhere before it.
using rms::kReleaseOpeningFt;
// The motion test between frames (docs/collision.md "Nothing passes
// through"): no model vertex moves more than this in one substep (less, when
// the thinnest tested solid is thinner than twice it).
inline constexpr double kMaxSubstepTravelFt = 0.1;
// A command whose motion would need more substeps than this is held and
// reported (a jump no arm could make in a frame).
inline constexpr int kMaxSubsteps = 4096;
// Between two substeps whose clearances do not cover the travel, the
// motion is halved this many times at most (to 1/128 of a substep's travel:
// a graze shallower than that may go unseen; docs/collision.md).
inline constexpr int kRefineDepth = 7;
// The essential contact: acquisition needs the movable finger's face e
// within this of the bar (docs/collision.md "The essential contact").
inline constexpr double kFingerContactToleranceFt = 0.01;

// The collision bits of the telemetry: rms/collision_bits.h (in namespace rms).

// The six acquisition conditions of report IV.A.3, in its order:
//  0 all BAR vertices beyond face d of EFF HEX 1
//  1 all BAR vertices beyond face b of EFF HEX 2
//  2 all BAR vertices beyond face e of EFF HEX 3
//  3 the distance between faces b (EFF HEX 2) and e (EFF HEX 3) below D3Y
//  4 the distance from face d of EFF HEX 1 to the centre of the BAR's top
//    face c below TPOB (a distance: |palm_to_bar_ft| < TPOB)
//  5 the end effector between the BAR's ends: no EFF HEX 1 vertex beyond
//    the BAR's faces a or d
// Each condition's margin, ft: by how much it holds (> 0) or how far it is
// from holding (< 0) -- conditions 1-3 the least depth of a BAR vertex
// beyond the face, 4 D3Y - gap, 5 TPOB - |palm_to_bar_ft|, 6 the least
// depth of an EFF HEX 1 vertex inside the BAR's ends (docs/collision.md
// "Margins").
struct AcquisitionCheck {
  std::array<bool, wire::kNumAcquisitionConditions> holds{};
  std::array<double, wire::kNumAcquisitionConditions> margin_ft{};
  double finger_gap_ft = 0.0;
  double palm_to_bar_ft = 0.0;  // signed: positive when the BAR's top is beyond face d
  bool all() const;
};
AcquisitionCheck CheckAcquisition(const DcpConfig& dcp, const EndEffectorModel& ee,
                                  const Hexahedron& bar, double finger_gap_ft,
                                  double relative_tolerance = 1e-12);

// Docking (report IV.A.3): every probe vertex (V21-V24, V31-V36) in the
// docking envelope -- beyond CAE face c, not beyond faces a, b, d, e -- and
// the probe's tip centre within dock_distance_ft of the port's centre, the
// probe's y axis within dock_angle_deg of the port's.
struct DockingCheck {
  bool in_envelope = false;
  double envelope_margin_ft =
      0.0;  // least depth of a probe vertex inside the envelope (< 0: outside by)
  double distance_ft = 0.0;
  double angle_deg = 0.0;
  bool docked = false;
};
DockingCheck CheckDocking(const DcpConfig& dcp, const CaeConfig& cae,
                          const Hexahedron& cae_front_half, const PayloadModel& payload,
                          double relative_tolerance = 1e-12);

// The arm as commanded or as it is.
struct ArmCommand {
  std::array<double, 6> angles_deg{};
  double shoulder_height_ft = 0.0;
  double finger = 0.0;  // lever, 0 open .. 1 closed
};

// What one frame decided, for telemetry.
struct DcpStatus {
  wire::DcpMode mode = wire::DcpMode::kAcquisition;
  bool acquired = false;
  bool docked = false;
  bool released = false;  // docked and let go by the finger: the arm is free
  bool held = false;
  bool finger_held = false;
  bool essential_contact = false;  // the movable finger closing onto the bar stopped on it (RECPT)
  bool motion_collision =
      false;              // the command's pose is free but its motion from the slave's is not
  bool too_fast = false;  // the motion needed more than kMaxSubsteps substeps: held
  int substeps = 0;       // poses tested for the motion this frame (1: the end pose alone)
  bool reset_refused =
      false;  // a reset whose arm pose would collide with the reset scene: not taken
  bool input_refused = false;  // a non-finite input: the frame holds the last command
  bool let_go = false;  // the finger opened and let the payload go before docking (Mode 1 again)
  bool finger_contact =
      false;  // Mode 1: face e of EFF HEX 3 within kFingerContactToleranceFt of the BAR
  std::uint32_t collisions = 0;        // of the master's command
  std::uint32_t slave_collisions = 0;  // of the pose the slave holds
  std::array<bool, wire::kNumAcquisitionConditions>
      acquisition{};  // the six conditions, report order (Mode 1; false after)
  std::array<double, wire::kNumAcquisitionConditions>
      acquisition_margin_ft{};  // their margins (Mode 1; 0 after)
  double finger_gap_ft = 0.0;
  double palm_to_bar_ft = 0.0;
  double bay_clearance_ft = 0.0;  // the lowest payload vertex above bay face c (> 0 for all: clear)
  bool probe_in_envelope = false;
  double envelope_margin_ft = 0.0;
  double dock_distance_ft = 0.0;
  double dock_angle_deg = 0.0;
  std::array<scene_model::SeparatingPlane, 3> planes{};
  std::uint32_t plane_valid = 0;
  ArmCommand master, slave;
  Eigen::Isometry3d X_RS2 = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_RP = Eigen::Isometry3d::Identity();
};

// What a real-time frame may skip; none of it changes a verdict, a mode or
// a control word (docs/performance.md "The DCP's whole frame" measures each
// saving; the planes sent may differ, each one still separating its pair).
struct DcpOptions {
  // Test only the active mode's pairs (report IV.A.3). False: every model
  // pair every frame, for comparison (end effector against the BAR and the
  // payload, the payload against the bay and the CAE).
  bool mode_pairs_only = true;
  // Bounding-volume rejection before the report's algorithm: spheres, then
  // axis-aligned boxes (CollideOptions sphere_reject, aabb_reject).
  bool bounding_reject = true;
  // Frame coherence: the previous frame's separating plane of each pair is
  // tried first (it is part of the checkpoint). Off by default: measured, it
  // costs about as much as it saves (docs/collision.md "Real-time savings").
  bool frame_coherence = false;
  // A still frame -- the slave's command bit for bit what its accepted pose
  // was evaluated at, in the same scene (SceneKey), free -- keeps that
  // evaluation instead of making it again: the same verdicts, planes and
  // clearance (docs/collision.md "Real-time savings"). False: every frame
  // evaluates, for comparison.
  bool reuse_still = true;
};

class DynamicCollisionProgram {
 public:
  explicit DynamicCollisionProgram(const LabConfig& config, const DcpOptions& options = {});
  // Throws rms::InputError when the initial inputs' pose collides.
  DynamicCollisionProgram(const DynamicCollisionProgram&) = delete;  // holds pointers into itself
  DynamicCollisionProgram& operator=(const DynamicCollisionProgram&) = delete;

  // One frame. The returned block's frame / time fields are the caller's.
  // The master's command is tested as a motion from the slave's pose
  // (docs/collision.md "Collision response"); a non-finite input holds.
  wire::DcpFrameData Step(const wire::OperatorInputs& in);

  // Back to the Acquisition Phase (Mode 1) and the initial state: payload in
  // the cargo bay, nothing acquired or docked; the arm stays where it is.
  // Refused (returns false, nothing changed) when the arm where it is would
  // collide with the payload back in the bay. Step acts on the reset
  // button's press, not on each frame it is held.
  bool Reset();

  // A checkpoint (docs/sessions.md "Freeze, run, step, checkpoint"): the
  // program's whole state -- mode, acquired, docked, released, the slave
  // arm's pose, the payload's attachment, free and docked poses, the
  // finger's limits, the reset button -- as JSON, doubles exact.
  // RestoreState refuses a document of another format, or missing or
  // malformed keys, with rms::InputError naming what is wrong, and then
  // changes nothing; after it the program continues as it would have from
  // the saved frame.
  nlohmann::ordered_json SaveState() const;
  void RestoreState(const nlohmann::json& state);

  // Malfunctions (docs/sessions.md "Malfunctions"), between frames: from
  // the next frame on, anchored where the slave arm is now. Kept by a reset
  // (the arm is still broken), saved in the checkpoint.
  void Inject(const wire::Malfunction& m);
  void Repair(const wire::Repair& r) { malfunctions_.Repair(r); }
  const Malfunctions& malfunctions() const { return malfunctions_; }

  wire::DcpMode mode() const { return status_.mode; }
  bool released() const { return released_; }
  const DcpStatus& status() const { return status_; }
  const arm::ArmPose& arm_pose() const { return slave_->pose; }
  const Eigen::Isometry3d& X_RP() const { return status_.X_RP; }
  double FingerGapFt(double lever) const;

 private:
  // What an evaluation depends on besides its command: the mode, docking,
  // the finger's clamps in Modes 2 and 3, and where the payload is (free,
  // held, docked). Compared bit for bit.
  struct SceneKey {
    wire::DcpMode mode = wire::DcpMode::kAcquisition;
    bool docked = false, released = false;
    double contact_gap_ft = 0.0, acquisition_gap_ft = 0.0;
    Eigen::Matrix4d X_RP_free{}, X_S2P{}, X_RP_docked{};
    bool operator==(const SceneKey& o) const;
  };
  SceneKey Scene() const;
  struct Evaluation {
    SceneKey scene;  // what it was evaluated in
    ArmCommand cmd;
    arm::ArmSinCos words{};
    arm::ArmPose pose{};
    double finger_gap_ft = 0.0;
    EndEffectorModel ee{};
    std::array<CollisionResult, 3> ee_bar{};  // EFF HEX k against the BAR (Mode 1)
    // EFF HEX k against the payload body's strip j, at [k * kBodyStrips + j] (Mode 1)
    std::array<CollisionResult, 3 * kBodyStrips> ee_body{};
    std::uint32_t extra_collisions = 0;  // pairs outside the mode (mode_pairs_only false); unused
    Eigen::Isometry3d X_RP = Eigen::Isometry3d::Identity();
    PayloadModel payload{};
    std::uint32_t collisions = 0;
    // A lower bound on the distance from the moving models to what they are
    // tested against, ft (0 when colliding or unknown; infinite when nothing
    // is tested): between two free poses whose clearances add up to more
    // than any vertex's travel, nothing can touch.
    double clearance_ft = 0.0;
    wire::DcpMode mode = wire::DcpMode::kAcquisition;  // the mode it was evaluated in
  };
  // Into *e (not prev). prev: the last accepted evaluation, whose planes are
  // the hints (frame coherence); null: none. e->ee is left as it was outside
  // Mode 1 (only Mode 1 reads it).
  void Evaluate(const ArmCommand& cmd, const Evaluation* prev, Evaluation* e) const;
  // The mode's tests of Evaluate, and every other pair when asked.
  void EvaluateMode1(const Evaluation* prev, Evaluation* e) const;
  PayloadModel HeldPayload(const Eigen::Isometry3d& X_RP) const;
  void EvaluateMode2(Evaluation* e) const;
  void EvaluateMode3(const Evaluation* prev, Evaluation* e) const;
  void EvaluateExtraPairs(Evaluation* e) const;
  // The parts of Step: the inputs taken, the slave's command, the first
  // frame, the output block.
  ArmCommand TakeInputs(const wire::OperatorInputs& in);
  ArmCommand SlaveCommand(const ArmCommand& master);
  void FirstFrame(const ArmCommand& command);
  wire::DcpFrameData FrameOut(const wire::OperatorInputs& in) const;
  // RestoreState's parts: every key read, then checked.
  struct RestoredState;
  std::unique_ptr<RestoredState> ReadRestoredState(const nlohmann::json& j) const;
  void CheckRestoredState(const RestoredState& p) const;
  // The payload's and probe's vertices against the bay's walls and bottom
  // (a vertex below face c beyond one), Modes 2 and 3.
  // EFF HEX 1-3 (out->ee) against the resting payload: collision bits,
  // results and clearance into *out.
  void TestHandAgainstPayload(const Evaluation* prev, Evaluation* out) const;
  // *clearance_ft is lowered to a bound on the vertices' distance from it.
  std::uint32_t BayCollisions(const PayloadModel& p, double* clearance_ft) const;
  // The motion from `from` to `to` (joint angles, height and finger linear
  // in between): the end pose into *out, then substeps so that no model
  // vertex moves more than substep_ft_ between two tested poses, refined
  // where the clearances do not cover the travel. Returns the first
  // collision bits found (0: the whole motion is free).
  std::uint32_t TestMotion(const ArmCommand& from, const ArmCommand& to, Evaluation* out);
  // Between two free poses of the motion (parameters s0 < s1, clearances c0,
  // c1, any vertex's travel between them at most travel_ft, plus slack_ft
  // for the words' rounding): when c0 + c1 cannot cover it, the midpoint is
  // tested, and each half in turn, down to kRefineDepth halvings. Returns the
  // first collision bits found, and where (*hit_s).
  std::uint32_t Refine(const ArmCommand& from, const ArmCommand& to, double s0, double s1,
                       double c0, double c1, double travel_ft, double slack_ft, int depth,
                       double* hit_s);
  // The bound on any model vertex's travel along the motion, ft.
  double TravelFt(const ArmCommand& from, const ArmCommand& to) const;
  // Each joint's reach: the farthest a moving vertex can be from its axis, ft.
  std::array<double, 6> JointReachFt() const;
  // What the arm words' rounding can move a tested pose, twice, ft.
  double WordSlackFt() const;
  // The number of poses a motion of this travel needs (1: the end pose
  // alone), or -1 beyond kMaxSubsteps.
  int Substeps(double travel_ft) const;
  // The command with the arm where the slave is and the finger closed (or
  // opened) toward `finger` as far as it goes free, to within 1e-5 ft of
  // the first contact. Returns the contact's collision bits (0: none).
  std::uint32_t MoveFinger(double finger);
  // What the slave does with the command: follows, holds, or holds the finger.
  void Respond(const ArmCommand& command);
  // The slave's command with the finger lever of its actual (clamped) gap.
  ArmCommand SlaveAsItIs() const;
  // Opening the finger before docking: the payload stays where it is (Mode 1).
  void LetGo();
  // The payload not held (Mode 1): its pose and models.
  void PlacePayload(const Eigen::Isometry3d& X_RP);
  // The spare evaluation becomes the slave's (two buffers, no copy).
  void AcceptSpare();
  void UpdateAcquisition();
  void UpdateExtraction();
  // After a mode change: the slave re-evaluated in the new mode; false (and
  // nothing accepted) when it would collide there.
  bool ReevaluateSlave();
  void UpdateDocking();
  // The status's measures of the slave's pose (planes, conditions, bay
  // clearance, docking), without changing the mode: after a restore.
  void RefreshMeasures();
  void UpdatePlanes();
  double BayClearance(const PayloadModel& p) const;
  // Refuses (rms::InputError) a restored state the program could not reach.
  void CheckRestored(int mode, bool acquired, bool docked, bool released, double contact_gap_ft,
                     double acquisition_gap_ft) const;
  // A held payload's farthest vertex from point A, ft.
  double PayloadReachFt(const Eigen::Isometry3d& X_S2P) const;

  const LabConfig& config_;
  DcpOptions options_;
  double tau_rel_ = 1e-12;
  // Fixed models: the payload in the bay (its pose at start and reset), the
  // bay, the CAE.
  Eigen::Isometry3d X_RP_bay_;
  Hexahedron bay_;
  Hexahedron cae_;
  double substep_ft_ = kMaxSubstepTravelFt;
  // The payload where it rests when not held (Mode 1): in the bay, or where
  // the finger let it go. Its BAR, body and the BAR's posts.
  Eigen::Isometry3d X_RP_free_;
  Hexahedron bar_;
  PayloadShape payload_shape_ = MakePayloadShape(config_.payload);  // made once
  // Its strips are valid where the payload rests at the origin (a payload
  // whose configuration makes them flat or degenerate: HeldPayload always
  // makes them, and the DCP refuses it as before).
  bool payload_strips_valid_ = [this] {
    const PayloadModel m = MakePayload(payload_shape_, Eigen::Isometry3d::Identity());
    return std::all_of(m.body.begin(), m.body.end(), [](const Hexahedron& h) { return h.valid; });
  }();
  // Within this many ft of the origin the held payload's strips, valid at
  // the origin, are valid too: their rounding tolerance there (about 1e-11
  // ft) is far below any strip's thickness.
  static constexpr double kStripsCheckedBeyondFt = 1e4;
  PayloadModel payload_;
  std::array<Hexahedron, 2> posts_{};
  int post_count_ = 0;
  // State. The slave starts at the initial inputs' pose (config [inputs]).
  bool reset_pressed_ = false;  // the reset button as last seen (Step acts on its press)
  bool started_ = false;        // a frame has been made: commands are motions from the slave's pose
  ArmCommand initial_;          // the initial inputs' pose, where the slave starts
  std::array<Evaluation, 4> evaluations_;
  Evaluation* slave_ = &evaluations_[0];    // the slave's (collision-free) evaluation
  Evaluation* spare_ = &evaluations_[1];    // this frame's candidate
  Evaluation* scratch_ = &evaluations_[2];  // substeps
  Evaluation* probe_ = &evaluations_[3];    // refinement between substeps
  Eigen::Isometry3d X_S2P_ =
      Eigen::Isometry3d::Identity();  // payload in System Two, from acquisition
  double payload_reach_ft_ = 0.0;     // held payload's farthest vertex from point A (travel bound)
  // Once acquired, the finger holds the bar: its gap stays between the gap at
  // which it touches the bar and the gap at acquisition.
  double contact_gap_ft_ = 0.0;
  double acquisition_gap_ft_ = 0.0;
  // Docked: the payload is captured at the port; the arm holding it keeps its
  // pose until the finger opens past the acquisition gap (released).
  bool released_ = false;
  Eigen::Isometry3d X_RP_docked_ = Eigen::Isometry3d::Identity();  // payload at the dock
  Malfunctions malfunctions_;
  DcpStatus status_;
};

// The arm words as transmitted: sin/cos of the angles (deg), rounded to SC22
// and read back. The DCP, the scene and the ESG all use these values.
arm::ArmSinCos TransmittedArmWords(const std::array<double, 6>& angles_deg);

}  // namespace rms::dcp_model
