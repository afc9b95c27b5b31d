// The operator's hand controllers: the bindings file (and its errors);
// manual augmented control in each command frame (finite differences of the
// forward kinematics); single joint; a terminal's presses as increments,
// merged and never queued, and the stop key; the live window's held keys
// (hold to move, release to stop, a silent window lets go); a gamepad
// through SDL2's virtual joystick; a 3D mouse through libspnav talking to a
// stand-in spacenavd; clamping with a report; and the status screen.
#include "rms/operator_station/devices.h"

#include <unistd.h>

#include <SDL2/SDL.h>
#include <algorithm>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <gtest/gtest.h>
#include <regex>
#include <sstream>
#include <sys/socket.h>
#include <sys/un.h>
#include <thread>

#include "rms/arm/kinematics.h"
#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/mission/mission_geometry.h"
#include "rms/operator_station/bindings.h"
#include "rms/operator_station/guidance.h"
#include "rms/operator_station/hand_controllers.h"
#include "rms/operator_station/status_screen.h"
#include "rms/wire/dcp_mode.h"

namespace rms::operator_station {
namespace {

constexpr double kDt = 1.0 / 30;
constexpr double kDeg = M_PI / 180.0;

class Devices : public ::testing::Test {
 public:  // (KeyedStation uses MidPose and Telemetry)
  LabConfig config = LoadConfig(DefaultConfigPath());
  Bindings bindings = LoadBindings(DefaultBindingsPath());
  GuidanceGeometry geometry = MakeGuidanceGeometry(config);

  // A pose in the middle of the workspace, over the bay.
  wire::OperatorInputs MidPose() const {
    wire::OperatorInputs in = wire::InitialInputs(config.inputs);
    const double q[6] = {15, 60, -75, -60, 5, -70};
    for (int i = 0; i < 6; ++i) in.value[i] = q[i];
    return in;
  }
  static JointAngles Angles(const wire::OperatorInputs& in) {
    JointAngles q{};
    for (int i = 0; i < 6; ++i) q[i] = in.value[i];
    return q;
  }
  Eigen::Isometry3d X_RS2(const wire::OperatorInputs& in) const {
    return ForwardPose(config.arm, Angles(in), in.value[kShoulderHeight]);
  }
  // Telemetry as the DCP would send it for these inputs: Mode 1, or the
  // payload held (Mode 2) at the grasp's attachment.
  dcp_telemetry_t Telemetry(const wire::OperatorInputs& in, int mode) const {
    dcp_telemetry_t t{};
    t.mode = static_cast<std::int8_t>(mode);
    const Eigen::Isometry3d X = X_RS2(in);
    const Eigen::Isometry3d P =
        mode == wire::DcpMode::kAcquisition
            ? arm::MakeIsometry(config.payload.R_RP, config.payload.p_RoPo_R_ft)
            : X * mission::PlanGeometry(config).X_S2P;
    for (int i = 0; i < 3; ++i) {
      t.p_RoA_R_ft[i] = X.translation()[i];
      t.p_RoPo_R_ft[i] = P.translation()[i];
      for (int j = 0; j < 3; ++j) {
        t.R_RS2[3 * i + j] = X.linear()(i, j);
        t.R_RP[3 * i + j] = P.linear()(i, j);
      }
    }
    for (int i = 0; i < 6; ++i) t.slave_angles_deg[i] = t.master_angles_deg[i] = in.value[i];
    return t;
  }
};

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

std::string DefaultBindingsText() {
  std::ifstream f(DefaultBindingsPath());
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// A keyboard whose keys the test types.
struct TypedKeys {
  std::deque<int> keys;
  std::function<int()> Source() {
    return [this] {
      if (keys.empty()) return -1;
      const int k = keys.front();
      keys.pop_front();
      return k;
    };
  }
};

// A station at Devices::MidPose flown by keys the test types.
struct KeyedStation {
  explicit KeyedStation(const Devices& devices) : d(devices), hc(d.config, d.bindings) {
    hc.AddDevice(std::make_unique<KeyboardDevice>(d.bindings, typed.Source()));
    in = d.MidPose();
    hc.SetInputs(in);
  }
  // `frames` frames, `keys` typed on the first, each against the telemetry
  // the DCP would send of Mode `mode` for the station's inputs.
  void Fly(const std::vector<int>& keys, int frames, int mode) {
    typed.keys = std::deque<int>(keys.begin(), keys.end());
    for (int k = 0; k < frames; ++k) {
      const dcp_telemetry_t t = d.Telemetry(in, mode);
      in = hc.Step(kDt, &t);
      typed.keys.clear();
    }
  }
  const Devices& d;
  TypedKeys typed;
  HandControllers hc;
  wire::OperatorInputs in;
};

TEST_F(Devices, TheBindingsFileIsReadAndBadOnesAreRefusedNamingTheKey) {
  EXPECT_EQ(bindings.keys.at('w').kind, ActionKind::kHand);
  EXPECT_EQ(bindings.keys.at('w').index, kThcX);
  EXPECT_EQ(bindings.keys.at('i').index, kRhcPitch);
  EXPECT_EQ(bindings.keys.at('i').sign, -1.0);
  EXPECT_EQ(bindings.keys.at(' ').kind, ActionKind::kStop);
  EXPECT_EQ(bindings.keys.at(wire::kKeyBackspace).kind, ActionKind::kReset);
  EXPECT_EQ(bindings.keys.at('Q').kind, ActionKind::kQuit);
  EXPECT_EQ(bindings.keys.at(wire::kKeyUp).index, kCameraTilt);
  EXPECT_EQ(bindings.keys.at('5').camera, 5);
  EXPECT_EQ(bindings.gamepad_axes.at("lefty").sign, -1.0);
  EXPECT_EQ(bindings.initial_mode, ControlMode::kManualAugmented);
  EXPECT_DOUBLE_EQ(bindings.rates.vernier_ft_s * 10, bindings.rates.coarse_ft_s);
  const std::string good = DefaultBindingsText();
  struct Case {
    std::string from, to, message;
  };
  const Case cases[] = {
      {"w = \"thc_x+\"", "w = \"thc_w+\"", "key 'keyboard.keys.w': unknown action \"thc_w+\""},
      {"w = \"thc_x+\"", "w = \"shoulder_yaw+\"",
       "key 'keyboard.keys.w': \"shoulder_yaw+\": the arm's joints move"},
      {"deadband = 0.12", "deadband = 1.5", "key 'conditioning.deadband': must be <= 0.9"},
      {"finger = 0.5 ", "finger = -0.5 ", "key 'conditioning.max_rate.finger': must be > 0"},
      {"vernier_ft_s = 0.2", "vernier_ft_s = 3.0",
       "key 'rates.vernier_ft_s': must be less than rates.coarse_ft_s"},
      {"mode = \"manual_augmented\"", "mode = \"auto\"",
       "key 'control.mode': must be \"manual_augmented\""},
      {"frame = \"end_effector\"", "frame = \"payload\"",
       "key 'control.frame': must be \"end_effector\" or \"orbiter\""},
      {"leftx = \"thc_y\"", "leftz = \"thc_y\"",
       "key 'gamepad.axes.leftz': is not an SDL game controller axis"},
      {"start = \"stop\"", "start = \"quit\"",
       "key 'gamepad.buttons.start': quit is for the keyboards only"},
      {"\ntx = \"thc_y\"", "\ntx = \"camera_pan\"",
       "key 'spacemouse.axes.tx': must name a hand-controller axis"},
      {"full_scale = 350.0", "fullscale = 350.0", "key 'spacemouse.full_scale': missing"},
      {"coarse_ft = 5.0", "coarse_ft = 0", "key 'keyboard.increment.coarse_ft': must be > 0"},
      {"[spacemouse.buttons]", "[spacemouse.buttons]\nextra = 1", "key 'spacemouse.buttons.extra'"},
      {"Q = \"quit\"", "Q = \"quit\"\nq = \"stop\"\n\" \" = \"stop\"",
       "key 'keyboard.keys. ': is not a key"},
      {"v = \"vernier\"", "", "key 'keyboard.keys': no key is bound to vernier"},
      {"h = \"square_up\"", "h = \"null_thc_w\"",
       "key 'keyboard.keys.h': unknown action \"null_thc_w\""},
      {"scale = \"coarse\"", "scale = \"finer\"",
       "key 'control.scale': must be \"coarse\", \"vernier\" or \"fine\""},
      {"s = \"thc_x-\"", "s = \"camera_1\"", "key 'keyboard.keys': no key is bound to thc_x-"},
      {"Q = \"quit\"\n", "", "key 'keyboard.keys': no key is bound to quit"},
      {"scale = \"coarse\"", "scale = \"coarse\"\ncameras = [4, 9]",
       "key 'control.cameras': must be camera stations, whole numbers 1..8"},
      {"scale = \"coarse\"", "scale = \"coarse\"\ncameras = [4, 7, 4]",
       "key 'control.cameras': names station 4 twice"},
      {"scale = \"coarse\"", "scale = \"coarse\"\ncameras = []",
       "key 'control.cameras': must name at least one station"},
      {"scale = \"coarse\"", "scale = \"coarse\"\ncameras = 4",
       "key 'control.cameras': must be an array of camera stations"},
  };
  for (const Case& c : cases) {
    try {
      ParseBindings(Replace(good, c.from, c.to), "bindings.toml");
      ADD_FAILURE() << "accepted: " << c.to;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bindings.toml: " + c.message), std::string::npos)
          << e.what();
    }
  }
}

// Manual augmented, each command frame: full deflection of each axis for one
// frame moves the point of resolution (or turns the end effector about it)
// along that frame's axis at the scale's rate, by finite differences of the
// forward kinematics.
TEST_F(Devices, ManualAugmentedMovesThePointOfResolutionAlongEachFramesAxes) {
  struct Case {
    CommandFrame frame;
    int mode;
  };
  for (const Case c : {Case{CommandFrame::kEndEffector, 1}, Case{CommandFrame::kOrbiter, 1},
                       Case{CommandFrame::kPayload, 2}, Case{CommandFrame::kEndEffector, 2}}) {
    for (int axis = 0; axis < kNumHandAxes; ++axis) {
      Bindings b = bindings;
      b.initial_frame = c.frame;
      HandControllers hc(config, b);
      const wire::OperatorInputs in0 = MidPose();
      hc.SetInputs(in0);
      const dcp_telemetry_t t = Telemetry(in0, c.mode);
      DeviceCommands cmd;
      cmd.hand[axis] = 1.0;
      const wire::OperatorInputs in1 = hc.Apply(cmd, kDt, &t);
      ArmState s = ArmStateFrom(t);
      const Eigen::Matrix3d R_RF = CommandAxes(geometry, c.frame, s);
      const Eigen::Vector3d por = PointOfResolution(geometry, s);
      const Eigen::Isometry3d X0 = X_RS2(in0), X1 = X_RS2(in1);
      const Eigen::Vector3d v = (X1 * por - X0 * por) / kDt;
      const Eigen::Vector3d w = RotationVector(X1.linear() * X0.linear().transpose()) / kDt;
      Eigen::Vector3d v_want = Eigen::Vector3d::Zero(), w_want = Eigen::Vector3d::Zero();
      if (axis < 3)
        v_want = R_RF.col(axis) * b.rates.coarse_ft_s;
      else
        w_want = R_RF.col(axis - 3) * b.rates.coarse_deg_s * kDeg;
      SCOPED_TRACE(std::string(CommandFrameName(c.frame)) + " frame, Mode " +
                   std::to_string(c.mode) + ", " + std::string(kHandAxisNames[axis]));
      if (hc.status().rate_limited) {
        // A joint at its rate: slower, the direction kept.
        const double k = axis < 3 ? v.norm() / v_want.norm() : w.norm() / w_want.norm();
        EXPECT_LT(k, 1.0);
        EXPECT_GT(k, 0.2);
        v_want *= k;
        w_want *= k;
      }
      EXPECT_LT((v - v_want).norm(), 0.01 * b.rates.coarse_ft_s);
      EXPECT_LT((w - w_want).norm(), 0.01 * b.rates.coarse_deg_s * kDeg);
      EXPECT_EQ(hc.status().frame, c.frame);
      EXPECT_DOUBLE_EQ(hc.status().rate[axis],
                       axis < 3 ? b.rates.coarse_ft_s : b.rates.coarse_deg_s);
    }
  }
}

TEST_F(Devices, ATerminalPressIsOneIncrementMergedNeverQueuedAndStopHaltsIt) {
  HandControllers hc(config, bindings);
  TypedKeys typed;
  hc.AddDevice(std::make_unique<KeyboardDevice>(bindings, typed.Source()));
  const wire::OperatorInputs in0 = MidPose();
  hc.SetInputs(in0);
  const dcp_telemetry_t t = Telemetry(in0, 1);
  auto por = [&](const wire::OperatorInputs& in) { return X_RS2(in) * geometry.p_S2oG_S2; };
  const Eigen::Vector3d p0 = por(in0);
  // Ten presses of 'w' in one frame: one coarse increment (2 ft) forward.
  for (int i = 0; i < 10; ++i) typed.keys.push_back('w');
  wire::OperatorInputs in = hc.Step(kDt, &t);
  int frames = 1;
  while (hc.status().rate[kThcX] != 0.0 && frames < 1000) {
    in = hc.Step(kDt, &t);
    ++frames;
  }
  const double inc = bindings.increments.coarse_ft;
  EXPECT_NEAR((por(in) - p0).norm(), inc, 0.01 * inc);
  EXPECT_NEAR(frames * kDt, inc / bindings.rates.coarse_ft_s + kDt, 1.5 * kDt);
  EXPECT_EQ(hc.key_actions(), 10);
  // Presses that keep coming while it moves (a held key's repeat) keep it
  // moving but never more than one increment ahead: when they stop, it
  // stops within one increment.
  const Eigen::Vector3d p1 = por(in);
  for (int f = 0; f < 60; ++f) {
    typed.keys = {'w', 'w'};
    in = hc.Step(kDt, &t);
  }
  const double moved_while_held = (por(in) - p1).norm();
  EXPECT_NEAR(moved_while_held, 60 * kDt * bindings.rates.coarse_ft_s, 0.02 * moved_while_held);
  frames = 0;
  const Eigen::Vector3d p2 = por(in);
  while (hc.status().rate[kThcX] != 0.0 && frames < 1000) {
    in = hc.Step(kDt, &t);
    ++frames;
  }
  EXPECT_LE((por(in) - p2).norm(), inc * 1.01);
  // The stop key halts a motion at once; a press the other way stops it too.
  typed.keys = {'d'};
  hc.Step(kDt, &t);
  EXPECT_GT(hc.status().rate[kThcY], 0.0);
  typed.keys = {' '};
  in = hc.Step(kDt, &t);
  EXPECT_EQ(hc.status().rate[kThcY], 0.0);
  EXPECT_EQ(hc.status().pending[kThcY], 0.0);
  const wire::OperatorInputs still = hc.Step(kDt, &t);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(still.value[i], in.value[i]);
  typed.keys = {'f'};
  hc.Step(kDt, &t);
  typed.keys = {'r'};
  hc.Step(kDt, &t);
  EXPECT_EQ(hc.status().pending[kThcZ], 0.0);
  // Vernier: a tenth of the rate, a finer increment.
  typed.keys = {'v', 'w'};
  hc.Step(kDt, &t);
  EXPECT_EQ(hc.status().scale, RateScale::kVernier);
  EXPECT_DOUBLE_EQ(hc.status().rate[kThcX], bindings.rates.vernier_ft_s);
  EXPECT_EQ(hc.counters().Get(Counter::kControlScaleChanges), 1);
  // Fine: vernier's rate, an increment of 0.05 ft.
  typed.keys = {'v', 'w'};
  hc.Step(kDt, &t);
  EXPECT_EQ(hc.status().scale, RateScale::kFine);
  EXPECT_DOUBLE_EQ(hc.status().rate[kThcX], bindings.rates.vernier_ft_s);
  EXPECT_NEAR(hc.status().pending[kThcX],
              bindings.increments.fine_ft - bindings.rates.vernier_ft_s * kDt, 1e-9);
}

// The keys of one frame act in the order they came: a press then a key that
// stops every motion (space, v, n, m, [, ]) leaves nothing moving; the
// other way round, the press moves.
TEST_F(Devices, OneFramesKeysActInTheOrderTheyCame) {
  HandControllers hc(config, bindings);
  TypedKeys typed;
  hc.AddDevice(std::make_unique<KeyboardDevice>(bindings, typed.Source()));
  const wire::OperatorInputs in0 = MidPose();
  hc.SetInputs(in0);
  const dcp_telemetry_t t = Telemetry(in0, 1);
  typed.keys = {'w'};
  hc.Step(kDt, &t);
  ASSERT_GT(hc.status().rate[kThcX], 0.0);
  typed.keys = {'s', 'v'};  // stop the axis, then vernier
  hc.Step(kDt, &t);
  EXPECT_EQ(hc.status().scale, RateScale::kVernier);
  EXPECT_EQ(hc.status().pending[kThcX], 0.0);
  EXPECT_EQ(hc.status().rate[kThcX], 0.0);
  typed.keys = {'v', 'd'};  // fine, then right: it moves
  hc.Step(kDt, &t);
  EXPECT_EQ(hc.status().scale, RateScale::kFine);
  EXPECT_GT(hc.status().rate[kThcY], 0.0);
}

TEST_F(Devices, TheLiveWindowsHeldKeysMoveAndReleasedOnesStopAtOnce) {
  HandControllers hc(config, bindings);
  auto dev = std::make_unique<WindowKeyboardDevice>(bindings, 300000);
  WindowKeyboardDevice* window = dev.get();
  hc.AddDevice(std::move(dev));
  const wire::OperatorInputs in0 = MidPose();
  hc.SetInputs(in0);
  const dcp_telemetry_t t = Telemetry(in0, 1);
  std::int64_t now = 1000000;
  window->Receive({0, {'w'}, {'w'}, true}, now);
  wire::OperatorInputs in = in0;
  std::int64_t seq = 0;
  for (int f = 0; f < 30; ++f) {
    window->SetNow(now += 33333);
    if (f % 3 == 2)
      window->Receive({++seq, {'w'}, {}, true}, now);  // the window's heartbeat while held
    in = hc.Step(kDt, &t);
  }
  EXPECT_DOUBLE_EQ(hc.status().rate[kThcX], bindings.rates.coarse_ft_s);
  const Eigen::Vector3d moved = X_RS2(in) * geometry.p_S2oG_S2 - X_RS2(in0) * geometry.p_S2oG_S2;
  EXPECT_NEAR(moved.norm(), 30 * kDt * bindings.rates.coarse_ft_s, 0.02);
  // Released: the very next frame commands no motion.
  window->Receive({++seq, {}, {}, true}, now);
  window->SetNow(now += 33333);
  const wire::OperatorInputs after = hc.Step(kDt, &t);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(after.value[i], in.value[i]);
  // A stale message is refused; a window that goes silent with a key held
  // is let go of after the timeout.
  EXPECT_FALSE(window->Receive({seq, {'w'}, {}, true}, now));
  window->Receive({++seq, {'d'}, {'d'}, true}, now);
  window->SetNow(now += 33333);
  hc.Step(kDt, &t);
  EXPECT_GT(hc.status().rate[kThcY], 0.0);
  window->SetNow(now += 400000);
  hc.Step(kDt, &t);
  EXPECT_EQ(hc.status().rate[kThcY], 0.0);
  EXPECT_EQ(window->timeouts(), 1);
  EXPECT_EQ(hc.key_actions(), 2);
  // A restarted window (a new esg_renderer) numbers its messages from 0
  // again: taken at once, not refused as stale.
  WindowKeyboardDevice::Message first{++seq, {}, {}, true};
  first.sender_pid = 100;
  EXPECT_TRUE(window->Receive(first, now));
  WindowKeyboardDevice::Message restarted{0, {'d'}, {'d'}, true};
  restarted.sender_pid = 200;
  EXPECT_TRUE(window->Receive(restarted, now));
  window->SetNow(now += 33333);
  hc.Step(kDt, &t);
  EXPECT_GT(hc.status().rate[kThcY], 0.0);
  EXPECT_EQ(window->new_windows(), 1);
}

// The stop key (or a change of scale, frame, mode or joint) stops every
// motion; what is still held down acts again only once let go. Docked and
// not yet released, the arm moves with nothing; frozen, stop and step act.
TEST_F(Devices, StopHoldsUntilReleasedDockedHoldsAndFrozenTakesStopAndSteps) {
  HandControllers hc(config, bindings);
  auto dev = std::make_unique<WindowKeyboardDevice>(bindings, 300000);
  WindowKeyboardDevice* window = dev.get();
  TypedKeys typed;
  hc.AddDevice(std::move(dev));
  hc.AddDevice(std::make_unique<KeyboardDevice>(bindings, typed.Source()));
  const wire::OperatorInputs in0 = MidPose();
  hc.SetInputs(in0);
  dcp_telemetry_t t = Telemetry(in0, 1);
  std::int64_t now = 1000000, seq = 0;
  auto frame = [&](std::vector<std::int32_t> held, std::vector<std::int32_t> down = {}) {
    window->Receive({++seq, std::move(held), std::move(down), true}, now);
    window->SetNow(now += 33333);
    return hc.Step(kDt, &t);
  };
  frame({'w'}, {'w'});
  wire::OperatorInputs in = frame({'w'});
  EXPECT_GT(hc.status().rate[kThcX], 0.0);
  typed.keys = {' '};  // stop, from the terminal, while the window's key stays down
  in = frame({'w'});
  for (int f = 0; f < 10; ++f) {
    const wire::OperatorInputs next = frame({'w'});
    for (int i = 0; i < 6; ++i)
      EXPECT_EQ(next.value[i], in.value[i]) << "a held key acts after the stop";
  }
  frame({});  // let go, press again: it moves
  frame({'w'}, {'w'});
  EXPECT_GT(hc.status().rate[kThcX], 0.0);
  // A change of scale stops a terminal increment in flight.
  frame({});
  typed.keys = {'d'};
  frame({});
  EXPECT_NE(hc.status().pending[kThcY], 0.0);
  typed.keys = {'v'};
  frame({});
  EXPECT_EQ(hc.status().pending[kThcY], 0.0);
  EXPECT_EQ(hc.status().rate[kThcY], 0.0);
  // Docked, the finger not yet open: the hand controllers follow the held arm.
  wire::OperatorInputs closed = in;
  closed.value[kFinger] = 1.0;
  hc.SetInputs(closed);
  t.docked = true;
  t.released = false;
  for (int i = 0; i < 6; ++i) t.slave_angles_deg[i] = in0.value[i] + 1.0;
  frame({'d'}, {'d'});
  in = frame({'d'});
  EXPECT_TRUE(hc.status().held_at_port);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(in.value[i], in0.value[i] + 1.0, 1e-9) << "joint " << i;
  typed.keys = {'x'};  // the finger still opens
  in = frame({'d'});
  in = frame({'d'});
  EXPECT_LT(in.value[kFinger], 1.0 - 1e-3);
  t.released = true;
  frame({'d'});
  EXPECT_FALSE(hc.status().held_at_port);
  // Frozen: each step key is one step; stop acts; other keys are ignored and counted.
  frame({});
  typed.keys = {'.', '.', '.', 'w'};
  hc.PollFrozen();
  EXPECT_EQ(hc.step_requests(), 3);
  EXPECT_EQ(hc.counters().Get(Counter::kFrozenInputsIgnored), 1);
}

TEST_F(Devices, SingleJointDrivesTheSelectedJointAtARateWithinItsLimit) {
  Bindings b = bindings;
  b.initial_mode = ControlMode::kSingleJoint;
  HandControllers hc(config, b);
  const wire::OperatorInputs in0 = MidPose();
  hc.SetInputs(in0);
  DeviceCommands select;
  select.events.push_back(ParseAction("joint_next"));  // shoulder yaw -> shoulder pitch
  hc.Apply(select, kDt, nullptr);
  EXPECT_EQ(hc.status().joint, 1);
  DeviceCommands push;
  push.hand[kThcX] = 1.0;
  push.hand[kThcY] = 1.0;  // not used in single joint
  wire::OperatorInputs in = hc.Apply(push, 1.0, nullptr);
  EXPECT_NEAR(in.value[1] - in0.value[1], b.rates.joint_coarse_deg_s, 1e-9);
  for (int i : {0, 2, 3, 4, 5}) EXPECT_EQ(in.value[i], in0.value[i]);
  // Driven past its limit it stops on it, reported once.
  for (int k = 0; k < 40; ++k) in = hc.Apply(push, 1.0, nullptr);
  EXPECT_DOUBLE_EQ(in.value[1], config.arm.joint_max_deg[1]);
  EXPECT_EQ(hc.counters().Get(Counter::kJointLimitShoulderPitch), 1);
  EXPECT_EQ(hc.status().at_limit, 1u << 1);
  DeviceCommands mode;
  mode.events.push_back(ParseAction("mode"));
  hc.Apply(mode, kDt, nullptr);
  EXPECT_EQ(hc.status().mode, ControlMode::kManualAugmented);
  EXPECT_EQ(hc.counters().Get(Counter::kControlModeChanges), 1);
}

// A camera set (a study's condition, docs/studies.md): the operator starts
// on its first station, selects only its stations (a key for another is
// refused, counted and shown), and next / previous step through it.
TEST_F(Devices, ACameraSetLimitsTheStationsAnOperatorMaySelect) {
  EXPECT_EQ(bindings.cameras, (std::vector<int>{1, 2, 3, 4, 5, 6, 7, 8}));
  const Bindings b = ParseBindings(Replace(DefaultBindingsText(), "scale = \"coarse\"",
                                           "scale = \"coarse\"\ncameras = [4, 7, 8]"),
                                   "bindings.toml");
  HandControllers hc(config, b);
  EXPECT_EQ(hc.Apply({}, kDt, nullptr).camera_station, 4);
  const auto press = [&](const std::string& action) {
    DeviceCommands c;
    c.events.push_back(ParseAction(action));
    return hc.Apply(c, kDt, nullptr).camera_station;
  };
  EXPECT_EQ(press("camera_7"), 7);
  EXPECT_EQ(press("camera_2"), 7) << "a station outside the set was selected";
  EXPECT_EQ(hc.status().camera_refused, 2);
  EXPECT_EQ(hc.counters().Get(Counter::kCameraRefused), 1);
  EXPECT_EQ(press("camera_next"), 8);
  EXPECT_EQ(hc.status().camera_refused, 0);
  EXPECT_EQ(press("camera_next"), 4);
  EXPECT_EQ(press("camera_prev"), 8);
  EXPECT_EQ(press("camera_1"), 8);
  EXPECT_EQ(hc.counters().Get(Counter::kCameraRefused), 2);
}

TEST_F(Devices, ThePayloadFrameIsOfferedOnlyOnceThePayloadIsHeld) {
  HandControllers hc(config, bindings);
  const wire::OperatorInputs in0 = MidPose();
  hc.SetInputs(in0);
  DeviceCommands frame;
  frame.events.push_back(ParseAction("frame"));
  dcp_telemetry_t t = Telemetry(in0, 1);
  hc.Apply(frame, kDt, &t);
  EXPECT_EQ(hc.status().frame, CommandFrame::kOrbiter);
  hc.Apply(frame, kDt, &t);
  EXPECT_EQ(hc.status().frame, CommandFrame::kEndEffector);  // no payload held: skipped
  t = Telemetry(in0, 2);
  hc.Apply(frame, kDt, &t);
  hc.Apply(frame, kDt, &t);
  EXPECT_EQ(hc.status().frame, CommandFrame::kPayload);
  t = Telemetry(in0, 1);  // reset: the payload back in the bay
  hc.Apply({}, kDt, &t);
  EXPECT_EQ(hc.status().frame, CommandFrame::kEndEffector);
  EXPECT_EQ(hc.counters().Get(Counter::kControlFrameChanges), 4);
}

TEST_F(Devices, OutOfRangeCommandsAreClampedAndReportedOnce) {
  HandControllers hc(config, bindings);
  DeviceCommands close;
  close.input_rate[kFinger] = 1.0;
  for (int i = 0; i < 90; ++i) hc.Apply(close, kDt, nullptr);  // 3 s at 0.5/s on a 0..1 lever
  EXPECT_DOUBLE_EQ(hc.target().value[kFinger], config.inputs[kFinger].max);
  // A lever held against its stop is one excursion, counted once; a second push, a second.
  EXPECT_EQ(hc.counters().Get(Counter::kClampedFinger), 1);
  hc.Apply({}, kDt, nullptr);
  for (int i = 0; i < 5; ++i) hc.Apply(close, kDt, nullptr);
  EXPECT_EQ(hc.counters().Get(Counter::kClampedFinger), 2);
  DeviceCommands down;
  down.input_rate[kShoulderHeight] = -1.0;
  for (int i = 0; i < 200; ++i) hc.Apply(down, 0.1, nullptr);
  EXPECT_DOUBLE_EQ(hc.target().value[kShoulderHeight], config.inputs[kShoulderHeight].min);
  // A terminal press closes the finger all the way at its rate; the stop key stops it.
  HandControllers h2(config, bindings);
  DeviceCommands press;
  press.input_presses.push_back({kFinger, 1.0});
  wire::OperatorInputs in = h2.Apply(press, kDt, nullptr);
  EXPECT_NEAR(in.value[kFinger], bindings.max_rate[kFinger] * kDt, 1e-12);
  for (int i = 0; i < 10; ++i) in = h2.Apply({}, kDt, nullptr);
  DeviceCommands stop;
  stop.events.push_back(ParseAction("stop"));
  in = h2.Apply(stop, kDt, nullptr);
  const double held = in.value[kFinger];
  EXPECT_LT(held, 0.5);
  EXPECT_DOUBLE_EQ(h2.Apply({}, kDt, nullptr).value[kFinger], held);
  // From part-way, a press either way runs to the end of the range: a step
  // asked for, never a command out of range (nothing clamped, nothing said).
  DeviceCommands open;
  open.input_presses.push_back({kFinger, -1.0});
  in = h2.Apply(open, kDt, nullptr);
  for (int i = 0; i < 60; ++i) in = h2.Apply({}, kDt, nullptr);
  EXPECT_DOUBLE_EQ(in.value[kFinger], config.inputs[kFinger].min);
  in = h2.Apply(press, kDt, nullptr);
  for (int i = 0; i < 90; ++i) in = h2.Apply({}, kDt, nullptr);
  EXPECT_DOUBLE_EQ(in.value[kFinger], config.inputs[kFinger].max);
  EXPECT_EQ(h2.counters().Get(Counter::kClampedFinger), 0);
}

TEST_F(Devices, DeadbandZeroesSmallDeflectionsAndKeepsFullScale) {
  EXPECT_EQ(ApplyDeadband(0.1, 0.12), 0.0);
  EXPECT_EQ(ApplyDeadband(-0.12, 0.12), 0.0);
  EXPECT_DOUBLE_EQ(ApplyDeadband(1.0, 0.12), 1.0);
  EXPECT_DOUBLE_EQ(ApplyDeadband(-1.0, 0.12), -1.0);
  EXPECT_NEAR(ApplyDeadband(0.56, 0.12), 0.5, 1e-12);
}

TEST_F(Devices, AGamepadsSticksAreProportionalWithADeadband) {
  ASSERT_EQ(SDL_InitSubSystem(SDL_INIT_GAMECONTROLLER), 0) << SDL_GetError();
  SDL_VirtualJoystickDesc desc{};
  desc.version = SDL_VIRTUAL_JOYSTICK_DESC_VERSION;
  desc.type = SDL_JOYSTICK_TYPE_GAMECONTROLLER;
  desc.naxes = SDL_CONTROLLER_AXIS_MAX;
  desc.nbuttons = SDL_CONTROLLER_BUTTON_MAX;
  desc.axis_mask = (1u << SDL_CONTROLLER_AXIS_MAX) - 1;
  desc.button_mask = (1u << SDL_CONTROLLER_BUTTON_MAX) - 1;
  desc.name = "rmslab test gamepad";
  const int index = SDL_JoystickAttachVirtualEx(&desc);
  ASSERT_GE(index, 0) << SDL_GetError();
  SDL_Joystick* js = SDL_JoystickOpen(index);
  ASSERT_NE(js, nullptr) << SDL_GetError();
  {
    std::string why;
    auto pad = GamepadDevice::Open(bindings, &why);
    ASSERT_NE(pad, nullptr) << why;
    EXPECT_NE(pad->Describe().find("rmslab test gamepad"), std::string::npos) << pad->Describe();
    // Left stick pushed fully forward: forward at full rate; half way
    // (beyond the deadband): proportionally less.
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, -32768);
    DeviceCommands c;
    pad->Poll(&c);
    EXPECT_NEAR(c.hand[kThcX], 1.0, 1e-9);
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, static_cast<Sint16>(-0.56 * 32767));
    c = {};
    pad->Poll(&c);
    EXPECT_NEAR(c.hand[kThcX], 0.5, 1e-3);
    // Inside the deadband: nothing.
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, 0);
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_RIGHTX, static_cast<Sint16>(0.1 * 32767));
    c = {};
    pad->Poll(&c);
    EXPECT_EQ(c.hand[kThcX], 0.0);
    EXPECT_EQ(c.hand[kRhcYaw], 0.0);
    // A held button moves its axis; the vernier button fires once per press.
    SDL_JoystickSetVirtualButton(js, SDL_CONTROLLER_BUTTON_RIGHTSHOULDER, 1);
    SDL_JoystickSetVirtualButton(js, SDL_CONTROLLER_BUTTON_X, 1);
    c = {};
    pad->Poll(&c);
    EXPECT_EQ(c.hand[kRhcRoll], 1.0);
    ASSERT_EQ(c.events.size(), 1u);
    EXPECT_EQ(c.events[0].kind, ActionKind::kVernier);
    c = {};
    pad->Poll(&c);
    EXPECT_TRUE(c.events.empty());  // still held: no second event
    EXPECT_EQ(c.hand[kRhcRoll], 1.0);
    EXPECT_TRUE(pad->connected());
  }
  SDL_JoystickClose(js);
  SDL_JoystickDetachVirtual(index);
  SDL_QuitSubSystem(SDL_INIT_GAMECONTROLLER);
}

// A stand-in for spacenavd: a UNIX socket speaking the protocol's version 0
// (8 ints an event), which libspnav falls back to when the daemon does not
// answer its protocol request.
class FakeSpacenavd {
 public:
  explicit FakeSpacenavd(const std::string& path) : path_(path) {
    listen_fd_ = socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::snprintf(a.sun_path, sizeof a.sun_path, "%s", path.c_str());
    unlink(path.c_str());
    EXPECT_EQ(bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    EXPECT_EQ(listen(listen_fd_, 1), 0);
    thread_ = std::thread([this] { client_fd_ = accept(listen_fd_, nullptr, nullptr); });
  }
  ~FakeSpacenavd() {
    if (thread_.joinable()) thread_.join();
    if (client_fd_ >= 0) close(client_fd_);
    close(listen_fd_);
    unlink(path_.c_str());
  }
  void Send(const std::array<int32_t, 8>& ev) {
    if (thread_.joinable()) thread_.join();
    ASSERT_GE(client_fd_, 0);
    ASSERT_EQ(write(client_fd_, ev.data(), sizeof ev), static_cast<ssize_t>(sizeof ev));
  }

 private:
  std::string path_;
  int listen_fd_ = -1, client_fd_ = -1;
  std::thread thread_;
};

TEST_F(Devices, A3DMouseIsBothHandControllers) {
  const std::string sock =
      ::testing::TempDir() + "/rmslab_spnav_" + std::to_string(getpid()) + ".sock";
  FakeSpacenavd daemon(sock);
  setenv("SPNAV_SOCKET", sock.c_str(), 1);
  std::string why;
  auto mouse = SpaceMouseDevice::Open(bindings, &why);
  unsetenv("SPNAV_SOCKET");
  ASSERT_NE(mouse, nullptr) << why;
  // Pushed away at full deflection and twisted clockwise at half:
  // forward, and yaw right at half rate.
  daemon.Send({0, 0, 0, -350, 0, static_cast<int32_t>(-0.56 * 350), 0, 16});
  daemon.Send({1, 0, 0, 0, 0, 0, 0, 0});  // button 0 pressed: finger+
  DeviceCommands c;
  usleep(100000);
  mouse->Poll(&c);
  EXPECT_NEAR(c.hand[kThcX], 1.0, 1e-9);
  EXPECT_NEAR(c.hand[kRhcYaw], 0.5, 1e-3);
  for (int i : {kThcY, kThcZ, kRhcRoll, kRhcPitch}) EXPECT_EQ(c.hand[i], 0.0);
  EXPECT_NEAR(c.input_rate[kFinger], 1.0, 1e-12);
  // Through the hand controllers: the point of resolution moves forward
  // and the end effector turns, in one frame.
  HandControllers hc(config, bindings);
  const wire::OperatorInputs in0 = MidPose();
  hc.SetInputs(in0);
  const dcp_telemetry_t t = Telemetry(in0, 1);
  const wire::OperatorInputs in1 = hc.Apply(c, kDt, &t);
  const Eigen::Isometry3d X0 = X_RS2(in0), X1 = X_RS2(in1);
  const Eigen::Matrix3d R_RF = CommandAxes(geometry, CommandFrame::kEndEffector, ArmStateFrom(t));
  const Eigen::Vector3d v = (X1 * geometry.p_S2oG_S2 - X0 * geometry.p_S2oG_S2) / kDt;
  EXPECT_NEAR(v.dot(R_RF.col(0)), bindings.rates.coarse_ft_s, 0.02);
  const Eigen::Vector3d w = RotationVector(X1.linear() * X0.linear().transpose()) / kDt;
  EXPECT_NEAR(w.dot(R_RF.col(2)), 0.5 * bindings.rates.coarse_deg_s * kDeg, 0.002);
}

TEST_F(Devices, WithoutADaemonThe3DMouseIsReportedAbsent) {
  setenv("SPNAV_SOCKET", "/nonexistent/spnav.sock", 1);
  std::string why;
  // (libspnav also tries /var/run/spnav.sock; no spacenavd runs here.)
  auto mouse = SpaceMouseDevice::Open(bindings, &why);
  unsetenv("SPNAV_SOCKET");
  EXPECT_EQ(mouse, nullptr);
  EXPECT_NE(why.find("no 3D mouse"), std::string::npos) << why;
}

TEST_F(Devices, TheStatusScreenShowsGuidanceMarginsAndFollowsTheWidth) {
  StatusSnapshot s;
  s.source = "by hand";
  s.frame = 1234;
  s.inputs = wire::InitialInputs(config.inputs);
  s.inputs.camera_station = 4;
  s.inputs.value[kCameraZoom] = 0.3;
  dcp_telemetry_t t{};
  t.mode = 1;
  t.held = true;
  t.collisions = 1 << 3;  // eff_hex_1-payload
  t.acquisition_conditions[0] = true;
  t.acquisition_margin_ft[0] = 0.25;
  t.acquisition_margin_ft[1] = -1.5;
  t.finger_gap_ft = 0.587;
  t.palm_to_bar_ft = -20.75;  // the BAR far behind the palm: shown as a distance
  t.dock_distance_ft = 31.5;
  s.telemetry = t;
  Guidance g;
  g.offset_ft = {3.25, -0.5, 1.0};
  g.rotation_deg = {-12.0, 30.0, 0.0};
  g.distance_ft = 3.44;
  s.guidance = g;
  s.hand = HandStatus{};
  for (const auto& [code, a] : bindings.keys) s.keys[ActionName(a)] = wire::KeyName(code);
  s.publish_hz = 30.0;
  s.telemetry_hz = 29.9;
  s.input_to_dcp_ms = 1.2;
  s.render_hz = 30.0;
  s.input_to_render_p50_ms = 3.1;
  s.input_to_render_p99_ms = 5.5;
  s.devices = {"keyboard (this terminal)", "gamepad: none (no gamepad or joystick found)"};
  for (int i = 0; i < 50; ++i) s.log.push_back("event " + std::to_string(i));
  const std::string screen = RenderStatusScreen(s, config, 120, 50);
  for (const char* want : {"frame 001234",
                           "MODE 1 ACQUISITION",
                           "HELD",
                           "eff_hex_1-payload",
                           "[x] 1 BAR beyond palm face d",
                           "holds by 0.250 ft",
                           "short by 1.500 ft",
                           "palm to BAR 20.750 ft",
                           "finger gap 0.587 ft",
                           "x forward 3.25 ft (w)",
                           "y left 0.50 ft (a)",
                           "z down 1.00 ft (f)",
                           "roll left 12.0 deg (u)",
                           "pitch up 30.0 deg (k)",
                           "CONTROL manual augmented",
                           "frame: end effector",
                           "distance 31.500 ft",
                           "camera 4 wrist",
                           "zoom 0.30",
                           "published 30.0 Hz",
                           "DCP 29.9 Hz",
                           "input to DCP 1.2 ms",
                           "p50 3.1 ms, p99 5.5 ms",
                           "gamepad: none",
                           "event 49"}) {
    EXPECT_NE(screen.find(want), std::string::npos) << "missing \"" << want << "\" in\n" << screen;
  }
  EXPECT_EQ(screen.find("-20.75"), std::string::npos) << screen;
  // The screen fits any terminal: never wider than it, never taller.
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{60, 30}, {80, 24}, {200, 60}}) {
    const std::string sc = RenderStatusScreen(s, config, w, h);
    std::istringstream is(sc);
    int lines = 0;
    for (std::string l; std::getline(is, l); ++lines) EXPECT_LE(static_cast<int>(l.size()), w) << l;
    EXPECT_LE(lines, h) << sc;
    EXPECT_NE(sc.find("GUIDANCE"), std::string::npos) << sc;
    EXPECT_NE(sc.find("event 49"), std::string::npos)
        << "the newest event is shown at " << w << "x" << h;
  }
  // Narrow: the conditions by number and tag, still with their margins.
  const std::string narrow = RenderStatusScreen(s, config, 80, 40);
  EXPECT_NE(narrow.find("short by 1.500 ft"), std::string::npos) << narrow;
  EXPECT_EQ(narrow.find("BAR beyond palm face d"), std::string::npos) << narrow;
  // Too small for the screen: it says so, within the terminal, with what is left to go.
  const std::string tiny = RenderStatusScreen(s, config, 40, 10);
  EXPECT_NE(tiny.find("terminal 40x10: needs 60x20"), std::string::npos) << tiny;
  EXPECT_NE(tiny.find("to go 3.44 ft"), std::string::npos) << tiny;
  std::istringstream is(tiny);
  for (std::string l; std::getline(is, l);) EXPECT_LE(static_cast<int>(l.size()), 40) << l;
}

// docs/operator.md "Nulling an axis, squaring up, unwinding": shift-d
// flies y to the guidance's 0 and stops; h squares the whole turn up in
// one rotation; b brings the wrist to the middle of its travel; each is
// counted, and a key of the axis takes it back.
TEST_F(Devices, NullKeysSquareUpAndUnwindFlyToTheirZeroAndStop) {
  KeyedStation station(*this);
  HandControllers& hc = station.hc;
  wire::OperatorInputs& in = station.in;
  auto guidance = [&](const wire::OperatorInputs& now) {
    ArmState s;
    s.X_RS2 = X_RS2(now);
    s.X_RP = arm::MakeIsometry(config.payload.R_RP, config.payload.p_RoPo_R_ft);
    return ComputeGuidance(geometry, s, CommandFrame::kEndEffector);
  };
  auto fly = [&](const std::vector<int>& keys, int frames) { station.Fly(keys, frames, 1); };
  ASSERT_GT(std::abs(guidance(in).offset_ft[1]), 0.5);
  fly({'D'}, 1);
  EXPECT_EQ(hc.status().automatic, 1u << kThcY);
  fly({}, 900);
  EXPECT_LT(std::abs(guidance(in).offset_ft[1]), 0.01);
  EXPECT_EQ(hc.status().automatic, 0u);  // there: it stopped by itself
  EXPECT_EQ(hc.counters().Get(Counter::kControlNulls), 1);

  ASSERT_GT(guidance(in).angle_deg, 5.0);
  fly({'h'}, 1);
  EXPECT_EQ(hc.status().automatic, kAutoSquareUp);
  fly({}, 1200);
  EXPECT_LT(guidance(in).angle_deg, 0.05);
  EXPECT_EQ(hc.status().automatic, 0u);
  // A rotation key takes the square-up back at once.
  fly({'b'}, 1);
  EXPECT_EQ(hc.status().automatic, kAutoUnwind);
  fly({}, 900);
  for (int j = 3; j < 6; ++j) EXPECT_NEAR(in.value[j], 0.0, 1e-6) << j;
  EXPECT_EQ(hc.counters().Get(Counter::kControlUnwinds), 1);
  fly({'h'}, 1);
  fly({'u'}, 1);
  EXPECT_EQ(hc.status().automatic & kAutoSquareUp, 0u);
}

// docs/operator.md "Stowing the arm": in Mode 1, z flies every joint back
// to where the session started it, all arriving together, and stops
// there, counted; holding the payload it is refused, counted, and nothing
// moves.
TEST_F(Devices, StowFliesEveryJointToItsStartInModeOneOnly) {
  KeyedStation station(*this);
  HandControllers& hc = station.hc;
  wire::OperatorInputs& in = station.in;
  station.Fly({'z'}, 1, 2);  // the payload held: refused
  EXPECT_EQ(hc.status().automatic, 0u);
  EXPECT_EQ(hc.counters().Get(Counter::kIncrementsBlocked), 1);
  EXPECT_EQ(hc.counters().Get(Counter::kControlStows), 0);
  for (int j = 0; j < 6; ++j) EXPECT_EQ(in.value[j], MidPose().value[j]) << j;
  station.Fly({'z'}, 1, 1);
  EXPECT_EQ(hc.status().automatic, kAutoStow);
  EXPECT_EQ(hc.counters().Get(Counter::kControlStows), 1);
  // Halfway, every joint is halfway: they arrive together.
  double longest_deg = 0.0;
  int longest = 0;
  for (int j = 0; j < 6; ++j) {
    const double d = std::abs(config.inputs[j].initial - MidPose().value[j]);
    if (d / bindings.max_rate[j] > longest_deg / bindings.max_rate[longest]) {
      longest_deg = d;
      longest = j;
    }
  }
  const int half = static_cast<int>(0.5 * longest_deg / bindings.max_rate[longest] / kDt);
  station.Fly({}, half, 1);
  for (int j = 0; j < 6; ++j) {
    const double start = MidPose().value[j], end = config.inputs[j].initial;
    EXPECT_NEAR((in.value[j] - start) / (end - start), 0.5, 0.05) << j;
  }
  station.Fly({}, 2 * half + 30, 1);
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(in.value[j], config.inputs[j].initial, 1e-6) << j;
  EXPECT_EQ(hc.status().automatic, 0u);
}

// A wrist joint within 10 deg of a limit is warned of (once), with the
// way out.
TEST_F(Devices, AWristNearItsLimitIsWarnedOf) {
  HandControllers hc(config, bindings);
  wire::OperatorInputs in = MidPose();
  in.value[5] = config.inputs[5].max - 5.0;
  hc.SetInputs(in);
  for (int k = 0; k < 3; ++k) {
    const dcp_telemetry_t t = Telemetry(in, 1);
    hc.Apply({}, kDt, &t);
  }
  EXPECT_EQ(hc.status().near_limit, 1u << 5);
  EXPECT_EQ(hc.counters().Get(Counter::kJointNearLimit), 1);
}

// Closing acquires only where every other condition holds too: a finger
// that would stop below D3Y 2.8 ft above the bar does not.
TEST_F(Devices, WouldAcquireOnlyWhereEveryOtherConditionHolds) {
  dcp_telemetry_t t = Telemetry(MidPose(), 1);
  Guidance g;
  g.close_gap_ft = 0.5 * config.dcp.d3y_ft;
  for (auto& c : t.acquisition_conditions) c = 1;
  EXPECT_TRUE(WouldAcquire(t, g, config.dcp.d3y_ft));
  t.acquisition_conditions[4] = false;  // condition 5: the palm not within TPOB of the bar
  EXPECT_FALSE(WouldAcquire(t, g, config.dcp.d3y_ft));
  t.acquisition_conditions[4] = true;
  g.close_gap_ft = 1.5 * config.dcp.d3y_ft;
  EXPECT_FALSE(WouldAcquire(t, g, config.dcp.d3y_ft));
}

// docs/operator.md "Clearance in Mode 3": a payload level 20 ft above the
// sill line, turned 90 deg about its probe's tip until it hangs below it,
// drops its far end by its length and probe: the clearance over the turn
// is the hanging payload's, computed in closed form here.
TEST_F(Devices, TheClearanceOverATurnIsTheLowestThePayloadGoes) {
  Eigen::Isometry3d X_RP = Eigen::Isometry3d::Identity();  // y_P along X_R, level
  X_RP.linear() << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  X_RP.translation() = Eigen::Vector3d(30, 0, 20);
  const double r = geometry.body_radius_ft;
  EXPECT_NEAR(PayloadLowestZ(geometry, X_RP), 20 - r, 1e-9);
  const Eigen::Vector3d tip = X_RP * geometry.p_PoT_P;
  // Probe up: 90 deg about Y_R turns y_P (-X_R) to +Z_R, about the tip; the
  // body's far end ends D = probe + body length below the tip (its end
  // circle then level: no radius below its centre).
  const Eigen::Vector3d phi(0, M_PI / 2, 0);
  const double D = geometry.p_PoT_P.y() + geometry.body_half_length_ft;
  const double least = TurnClearance(geometry, X_RP, tip, phi);
  EXPECT_NEAR(least, tip.z() - std::hypot(D, r), 0.05);
  EXPECT_LT(least, 20 - r - 5.0);
  // No turn: the clearance now.
  EXPECT_NEAR(TurnClearance(geometry, X_RP, tip, Eigen::Vector3d::Zero()), 20 - r, 1e-9);
}

// docs/operator.md "Guidance", "Clearance in Mode 3": each message's
// condition, and only then -- what to fly next with its keys, whether
// closing acquires, the wrist's limit, the arm's real rate, the clearance.
TEST_F(Devices, TheStatusScreenSaysWhatToFlyNextAndWarnsOnlyWhereItHolds) {
  StatusSnapshot s;
  s.source = "by hand";
  s.inputs = wire::InitialInputs(config.inputs);
  s.inputs.value[5] = 172.0;
  dcp_telemetry_t t{};
  t.mode = 1;
  for (auto& c : t.acquisition_conditions) c = 1;
  t.acquisition_conditions[4] = 0;  // condition 5 short
  s.telemetry = t;
  Guidance g;
  g.rotation_deg = {-12.0, 30.0, 0.0};
  g.angle_deg = 32.3;
  g.next_axis = kRhcPitch;
  g.close_gap_ft = 0.5 * config.dcp.d3y_ft;
  s.guidance = g;
  HandStatus h;
  h.near_limit = 1u << 5;
  h.automatic = kAutoSquareUp;
  h.rate[kThcX] = 2.0;
  h.achieved[kThcX] = 0.8;
  s.hand = h;
  for (const auto& [code, a] : bindings.keys) s.keys[ActionName(a)] = wire::KeyName(code);
  auto shows = [&](const char* want) {
    return RenderStatusScreen(s, config, 132, 60).find(want) != std::string::npos;
  };
  EXPECT_TRUE(shows("next: pitch up 30.0 deg (k; K flies it to 0)"));
  EXPECT_TRUE(shows("h squares up the whole 32.3 deg turn at once"));
  EXPECT_TRUE(shows("closing now would not acquire: conditions 5 short"));
  EXPECT_FALSE(shows("CLOSING THE FINGER NOW ACQUIRES"));
  EXPECT_TRUE(shows(
      "WRIST NEAR ITS LIMIT (within 10 deg): wrist_roll +172.0; b unwinds it, z stows the arm"));
  EXPECT_TRUE(shows("SQUARING UP"));
  s.telemetry->mode = 2;  // the payload held: no stow
  EXPECT_TRUE(shows("wrist_roll +172.0; b unwinds it"));
  EXPECT_FALSE(shows("stows the arm"));
  s.telemetry->mode = 1;
  s.hand->mode = ControlMode::kSingleJoint;  // both work in either control mode
  EXPECT_TRUE(shows("wrist_roll +172.0; b unwinds it, z stows the arm"));
  s.hand->mode = ControlMode::kManualAugmented;
  EXPECT_TRUE(shows("moving x +2.00 ft/s [arm +0.80]"));
  EXPECT_FALSE(shows("CLEARANCE"));
  s.telemetry->acquisition_conditions[4] = 1;
  s.hand->near_limit = 0;
  s.hand->achieved[kThcX] = 2.0;
  EXPECT_TRUE(shows("CLOSING THE FINGER NOW ACQUIRES (c)"));
  EXPECT_FALSE(shows("WRIST NEAR"));
  EXPECT_FALSE(shows("[arm"));
  // Mode 3: the payload high now, but the turn shown takes it under the sill line.
  s.telemetry->mode = 3;
  s.telemetry->bay_clearance_ft = 14.2;
  s.guidance->turn_clearance_ft = -3.1;
  s.guidance->clearance_warning = true;
  s.hand->automatic = 0;
  EXPECT_TRUE(shows("payload above the orbiter's sill line by 14.20 ft"));
  EXPECT_TRUE(shows("over the turn shown: BELOW the orbiter's sill line by 3.10 ft"));
  EXPECT_TRUE(shows("CLEARANCE WARNING"));
  EXPECT_FALSE(shows("clear of the bay by"));
  s.guidance->turn_clearance_ft = 6.0;
  s.guidance->clearance_warning = false;
  EXPECT_FALSE(shows("CLEARANCE WARNING"));
}

// The clearance warning is Mode 3's, and computed: a payload held level
// just above the sill line under a turn that swings it down warns; the
// same turn 40 ft up does not.
TEST_F(Devices, ModeThreeWarnsWhereTheTurnShownTakesThePayloadUnderTheMargin) {
  ArmState s;
  s.mode = 3;
  s.X_RP.linear() << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // y_P along -X_R: the probe level
  s.X_RP.translation() = Eigen::Vector3d(30, 0, 8);
  s.X_RS2 = s.X_RP;
  const Guidance low = ComputeGuidance(geometry, s, CommandFrame::kOrbiter);
  ASSERT_GT(low.angle_deg, 45.0);  // the probe level, the port's axis not
  EXPECT_TRUE(low.clearance_warning) << low.turn_clearance_ft;
  s.X_RP.translation().z() = 48;
  s.X_RS2 = s.X_RP;
  const Guidance high = ComputeGuidance(geometry, s, CommandFrame::kOrbiter);
  EXPECT_FALSE(high.clearance_warning) << high.turn_clearance_ft;
  EXPECT_GT(high.turn_clearance_ft, kClearanceMarginFt);
}

// docs/operator.md "Rates": a press moves the distance asked whatever the
// pose -- from the straight (stowed) arm, a singular pose, too, where a
// motion goes slowly at first.
TEST_F(Devices, APressMovesTheDistanceAskedFromTheStraightArm) {
  for (const int key : {'a', 'd', 's', 'f'}) {
    HandControllers hc(config, bindings);
    TypedKeys typed;
    hc.AddDevice(std::make_unique<KeyboardDevice>(bindings, typed.Source()));
    wire::OperatorInputs in = wire::InitialInputs(config.inputs);
    hc.SetInputs(in);
    const Eigen::Isometry3d X0 = X_RS2(in);
    typed.keys = {key};
    int frames = 0;
    for (; frames < 30 * 30; ++frames) {
      const dcp_telemetry_t t = Telemetry(in, 1);
      in = hc.Step(kDt, &t);
      const auto& p = hc.status().pending;
      if (frames > 0 && std::all_of(p.begin(), p.end(), [](double v) { return v == 0.0; })) break;
    }
    // The grasp point's motion, in the end effector's axes at the start.
    const Eigen::Matrix3d R_RF = X0.linear() * geometry.R_S2H;
    const Eigen::Vector3d d_F =
        R_RF.transpose() * (X_RS2(in) * geometry.p_S2oG_S2 - X0 * geometry.p_S2oG_S2);
    const int axis = key == 'a' || key == 'd' ? 1 : key == 's' ? 0 : 2;
    const double sign = key == 'a' || key == 's' ? -1.0 : 1.0;
    std::printf("key %c: %.3f ft along its axis in %.1f s (asked %.1f)\n", key, d_F[axis],
                frames * kDt, sign * bindings.increments.coarse_ft);
    EXPECT_NEAR(d_F[axis], sign * bindings.increments.coarse_ft, 0.1) << static_cast<char>(key);
    EXPECT_EQ(hc.counters().Get(Counter::kIncrementsBlocked), 0) << static_cast<char>(key);
  }
}

// Mode 2, the payload in the bay: a null key flies the way out's 0 (up
// until the payload is 2 ft clear), not the port's; the square-up waits.
TEST_F(Devices, InTheBayANullFliesTheWayOutAndTheSquareUpWaits) {
  KeyedStation station(*this);
  HandControllers& hc = station.hc;
  TypedKeys& typed = station.typed;
  wire::OperatorInputs& in = station.in;
  auto lowest = [&](const wire::OperatorInputs& now) {
    return PayloadLowestZ(geometry, X_RS2(now) * mission::PlanGeometry(config).X_S2P);
  };
  // Lower the pose until the payload is in the bay.
  for (int k = 0; k < 200 && lowest(in) > 0.5; ++k) {
    typed.keys = {'f'};
    const dcp_telemetry_t t = Telemetry(in, 2);
    in = hc.Step(kDt, &t);
  }
  typed.keys = {' ', 'n'};  // stop; the orbiter frame
  for (int k = 0; k < 5; ++k) {
    const dcp_telemetry_t t = Telemetry(in, 2);
    in = hc.Step(kDt, &t);
    typed.keys.clear();
  }
  ASSERT_LT(lowest(in), kLeaveBayMarginFt - 0.5);
  typed.keys = {'h', 'R'};
  for (int k = 0; k < 900 && (k < 2 || hc.status().automatic != 0); ++k) {
    const dcp_telemetry_t t = Telemetry(in, 2);
    in = hc.Step(kDt, &t);
    typed.keys.clear();
  }
  EXPECT_EQ(hc.status().automatic, 0u);
  EXPECT_NEAR(lowest(in), kLeaveBayMarginFt, 0.05);              // out, and no further
  EXPECT_GE(hc.counters().Get(Counter::kIncrementsBlocked), 1);  // the square-up: not in the bay
}

// A terminal's press flown into a collision ends when the DCP holds the
// arm, said and counted -- not flown on into the contact.
TEST_F(Devices, APressIntoACollisionIsCutShortThere) {
  KeyedStation station(*this);
  HandControllers& hc = station.hc;
  TypedKeys& typed = station.typed;
  wire::OperatorInputs& in = station.in;
  typed.keys = {'w'};
  dcp_telemetry_t t = Telemetry(in, 1);
  in = hc.Step(kDt, &t);
  ASSERT_GT(hc.status().pending[kThcX], 1.0);
  t = Telemetry(in, 1);
  t.held = true;  // the command collides: the DCP holds the slave where it was
  in = hc.Step(kDt, &t);
  EXPECT_EQ(hc.status().pending[kThcX], 0.0);
  EXPECT_EQ(hc.counters().Get(Counter::kIncrementsBlocked), 1);
}

}  // namespace
}  // namespace rms::operator_station
