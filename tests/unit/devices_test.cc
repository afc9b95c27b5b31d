// The operator's devices and their conditioning: the bindings file (and its
// errors), the keyboard through the bindings, rate limits and clamping with
// a report, a gamepad through SDL2's virtual joystick, a 3D mouse through
// libspnav talking to a stand-in spacenavd on a socket, and the status
// screen's text.
#include <gtest/gtest.h>
#include <SDL2/SDL.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <deque>
#include <thread>

#include "bindings.h"
#include "devices.h"
#include "manual_control.h"
#include "rms/arm_kinematics.h"
#include "rms/check.h"
#include "rms/config.h"
#include "status_screen.h"

namespace rms::op {
namespace {

class Devices : public ::testing::Test {
 protected:
  LabConfig config = LoadConfig(DefaultConfigPath());
  Bindings bindings = LoadBindings(DefaultBindingsPath());
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

TEST_F(Devices, TheBindingsFileIsReadAndBadOnesAreRefusedNamingTheKey) {
  EXPECT_EQ(bindings.keys.at('q').kind, ActionKind::kIncrease);
  EXPECT_EQ(bindings.keys.at('q').input, kShoulderYaw);
  EXPECT_EQ(bindings.keys.at(kKeyUp).input, kCameraTilt);
  EXPECT_EQ(bindings.keys.at('5').camera, 5);
  EXPECT_EQ(bindings.gamepad_axes.at("lefty").sign, -1.0);
  EXPECT_DOUBLE_EQ(bindings.max_rate[kFinger], 0.5);
  const std::string good = DefaultBindingsText();
  struct Case {
    std::string from, to, message;
  };
  const Case cases[] = {
      {"q = \"shoulder_yaw+\"", "q = \"shoulder_yaww+\"", "key 'keyboard.keys.q': unknown action \"shoulder_yaww+\""},
      {"deadband = 0.12", "deadband = 1.5", "key 'conditioning.deadband': must be <= 0.9"},
      {"finger = 0.5 ", "finger = -0.5 ", "key 'conditioning.max_rate.finger': must be > 0"},
      {"leftx = \"shoulder_yaw\"", "leftz = \"shoulder_yaw\"", "key 'gamepad.axes.leftz': is not an SDL game controller axis"},
      {"start = \"reset\"", "start = \"quit\"", "key 'gamepad.buttons.start': quit is for the keyboard only"},
      {"tx = \"X\"", "tx = \"W\"", "key 'spacemouse.translate.tx': must be one of X, Y, Z"},
      {"full_scale = 350.0", "fullscale = 350.0", "key 'spacemouse.full_scale': missing"},
      {"[spacemouse.buttons]", "[spacemouse.buttons]\nextra = 1", "key 'spacemouse.buttons.extra'"},
  };
  for (const Case& c : cases) {
    try {
      ParseBindings(Replace(good, c.from, c.to), "bindings.toml");
      ADD_FAILURE() << "accepted: " << c.to;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bindings.toml: " + c.message), std::string::npos) << e.what();
    }
  }
}

TEST_F(Devices, KeysStepTargetsAndTheOutputFollowsAtTheRateLimit) {
  ManualControl mc(config, bindings);
  std::deque<int> keys;
  mc.AddDevice(std::make_unique<KeyboardDevice>(bindings, [&] {
    if (keys.empty()) return -1;
    const int k = keys.front();
    keys.pop_front();
    return k;
  }));
  const double dt = 1.0 / 30;
  // Ten presses of 'w': the target moves 10 steps at once, the output at max_rate.
  for (int i = 0; i < 10; ++i) keys.push_back('w');
  OperatorInputs out = mc.Step(dt);
  EXPECT_DOUBLE_EQ(mc.target().value[kShoulderPitch], 10 * bindings.key_step[kShoulderPitch]);
  EXPECT_NEAR(out.value[kShoulderPitch], bindings.max_rate[kShoulderPitch] * dt, 1e-12);
  int frames = 1;
  while (out.value[kShoulderPitch] < mc.target().value[kShoulderPitch] && frames < 1000) {
    out = mc.Step(dt);
    ++frames;
  }
  const double expected_s = 10 * bindings.key_step[kShoulderPitch] / bindings.max_rate[kShoulderPitch];
  EXPECT_NEAR(frames * dt, expected_s, dt + 1e-9);
  // Camera, overlay, reset (one frame), quit.
  keys = {'3', 'o', ' '};
  out = mc.Step(dt);
  EXPECT_EQ(out.camera_station, 3);
  EXPECT_FALSE(out.overlay);
  EXPECT_TRUE(out.reset);
  EXPECT_FALSE(mc.Step(dt).reset);
  EXPECT_FALSE(mc.quit());
  keys = {'x'};
  mc.Step(dt);
  EXPECT_TRUE(mc.quit());
}

TEST_F(Devices, OutOfRangeCommandsAreClampedAndReportedOnce) {
  ManualControl mc(config, bindings);
  DeviceCommands close;
  close.step[kFinger] = 0.4;
  for (int i = 0; i < 5; ++i) mc.Apply(close, 1.0 / 30);  // 2.0 asked of a 0..1 lever
  EXPECT_DOUBLE_EQ(mc.target().value[kFinger], config.inputs[kFinger].max);
  EXPECT_EQ(mc.counters().Get("clamped.finger"), 3);  // the 3rd, 4th and 5th presses went beyond
  DeviceCommands down;
  down.rate[kShoulderHeight] = -1000.0;
  mc.Apply(down, 1.0);
  EXPECT_DOUBLE_EQ(mc.target().value[kShoulderHeight], config.inputs[kShoulderHeight].min);
  EXPECT_EQ(mc.counters().Get("clamped.shoulder_height"), 1);
}

TEST_F(Devices, DeadbandZeroesSmallDeflectionsAndKeepsFullScale) {
  EXPECT_EQ(ApplyDeadband(0.1, 0.12), 0.0);
  EXPECT_EQ(ApplyDeadband(-0.12, 0.12), 0.0);
  EXPECT_DOUBLE_EQ(ApplyDeadband(1.0, 0.12), 1.0);
  EXPECT_DOUBLE_EQ(ApplyDeadband(-1.0, 0.12), -1.0);
  EXPECT_NEAR(ApplyDeadband(0.56, 0.12), 0.5, 1e-12);
}

TEST_F(Devices, AGamepadThroughSdlMovesWhatItsBindingsSay) {
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
    // Left stick pushed fully forward: shoulder pitch up at its max rate.
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, -32768);
    DeviceCommands c;
    pad->Poll(&c);
    EXPECT_NEAR(c.rate[kShoulderPitch], bindings.max_rate[kShoulderPitch], 1e-9);
    // Inside the deadband: nothing.
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTY, 0);
    SDL_JoystickSetVirtualAxis(js, SDL_CONTROLLER_AXIS_LEFTX, static_cast<Sint16>(0.1 * 32767));
    c = {};
    pad->Poll(&c);
    EXPECT_EQ(c.rate[kShoulderPitch], 0.0);
    EXPECT_EQ(c.rate[kShoulderYaw], 0.0);
    // A held button moves its input; camera_next fires once per press.
    SDL_JoystickSetVirtualButton(js, SDL_CONTROLLER_BUTTON_A, 1);
    SDL_JoystickSetVirtualButton(js, SDL_CONTROLLER_BUTTON_RIGHTSTICK, 1);
    c = {};
    pad->Poll(&c);
    EXPECT_NEAR(c.rate[kFinger], bindings.max_rate[kFinger], 1e-12);
    ASSERT_EQ(c.events.size(), 1u);
    EXPECT_EQ(c.events[0].kind, ActionKind::kCameraNext);
    c = {};
    pad->Poll(&c);
    EXPECT_TRUE(c.events.empty());  // still held: no second event
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

TEST_F(Devices, A3DMouseThroughSpacenavdMovesSystemTwo) {
  const std::string sock = ::testing::TempDir() + "/rmslab_spnav_" + std::to_string(getpid()) + ".sock";
  FakeSpacenavd daemon(sock);
  setenv("SPNAV_SOCKET", sock.c_str(), 1);
  std::string why;
  auto mouse = SpaceMouseDevice::Open(bindings, &why);
  unsetenv("SPNAV_SOCKET");
  ASSERT_NE(mouse, nullptr) << why;
  // Full deflection along the device's x: System Two moves along +X_R.
  daemon.Send({0, 350, 0, 0, 0, 0, 0, 16});
  daemon.Send({1, 0, 0, 0, 0, 0, 0, 0});  // button 0 pressed: finger+
  ManualControl mc(config, bindings);
  // Start from a pose in the middle of the workspace.
  DeviceCommands pose;
  const double q[6] = {15, 60, -75, -70, 0, -75};
  for (int i = 0; i < 6; ++i) pose.step[i] = q[i];
  mc.Apply(pose, 1.0);
  auto X_of = [&](const OperatorInputs& t) {
    std::array<double, 6> a{};
    for (int i = 0; i < 6; ++i) a[i] = t.value[i];
    return ComputeArmPose(config.arm, SinCosFromDegrees(a), t.value[kShoulderHeight]).X_RS2;
  };
  const Eigen::Isometry3d X0 = X_of(mc.target());
  DeviceCommands c;
  usleep(100000);
  mouse->Poll(&c);
  EXPECT_NEAR(c.v_R_ft_s.x(), bindings.spacemouse_speed_ft_s, 1e-9);
  EXPECT_NEAR(c.v_R_ft_s.tail<2>().norm(), 0.0, 1e-12);
  EXPECT_NEAR(c.rate[kFinger], bindings.max_rate[kFinger], 1e-12);
  mc.Apply(c, 0.5);
  const Eigen::Isometry3d X1 = X_of(mc.target());
  EXPECT_NEAR((X1.translation() - X0.translation() - Eigen::Vector3d(0.5, 0, 0)).norm(), 0.0, 1e-6);
  EXPECT_NEAR(Eigen::AngleAxisd(X0.linear().transpose() * X1.linear()).angle(), 0.0, 1e-9);
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

TEST_F(Devices, TheStatusScreenShowsTheModeCollisionsConditionsAndLatency) {
  StatusSnapshot s;
  s.source = "by hand";
  s.frame = 1234;
  s.inputs = InitialInputs(config.inputs);
  s.inputs.camera_station = 4;
  s.inputs.value[kCameraZoom] = 0.3;
  dcp_telemetry_t t{};
  t.mode = 1;
  t.held = true;
  t.collisions = 1 << 3;  // eff_hex_1-payload
  t.acquisition_conditions[0] = true;
  t.acquisition_conditions[4] = true;
  t.finger_gap_ft = 0.587;
  t.dock_distance_ft = 31.5;
  s.telemetry = t;
  s.publish_hz = 30.0;
  s.telemetry_hz = 29.9;
  s.input_to_dcp_ms = 1.2;
  s.render_hz = 30.0;
  s.input_to_render_p50_ms = 3.1;
  s.input_to_render_p99_ms = 5.5;
  s.devices = {"keyboard (this terminal)", "gamepad: none (no gamepad or joystick found)"};
  const std::string screen = RenderStatusScreen(s, config);
  for (const char* want : {"frame 001234", "MODE 1 ACQUISITION", "HELD", "eff_hex_1-payload", "[x] 1 BAR past palm d",
                           "[ ] 2 BAR past finger b", "[x] 5 palm-BAR < TPOB", "finger gap 0.587 ft",
                           "distance 31.500 ft", "camera 4 wrist", "zoom 0.30", "published 30.0 Hz",
                           "DCP 29.9 Hz", "rendered 30.0 Hz", "input to DCP 1.2 ms", "p50 3.1 ms, p99 5.5 ms",
                           "gamepad: none"}) {
    EXPECT_NE(screen.find(want), std::string::npos) << "missing \"" << want << "\" in\n" << screen;
  }
}

}  // namespace
}  // namespace rms::op
