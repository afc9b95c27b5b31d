// Malfunctions (docs/sessions.md "Malfunctions"): their text, what the DCP
// does with each, their place in the checkpoint, and the operator station's
// watch that sees a part not following its command.
#include "rms/wire/malfunction.h"

#include <cstring>
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>
#include <string>
#include <vector>

#include "rms/base/check.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/dcp_model/malfunctions.h"
#include "rms/dcp_state_t.hpp"
#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/mission/mission_plan.h"
#include "rms/operator_station/follow_watch.h"
#include "rms/operator_station/timeline.h"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/word_blocks.h"

#include "dcp_fixture.h"

namespace rms {
namespace {

using wire::MalfunctionKind;

TEST(MalfunctionText, EveryKindReadsBackAsWritten) {
  const std::vector<wire::Malfunction> all = {
      {MalfunctionKind::kJointStuck, 1, 0.0},       {MalfunctionKind::kJointDrift, 6, -0.25},
      {MalfunctionKind::kJointSlow, 3, 1.5},        {MalfunctionKind::kFingerJammedOpen, 0, 0.0},
      {MalfunctionKind::kFingerJammedClosed, 0, 0}, {MalfunctionKind::kCameraLost, 8, 0.0},
      {MalfunctionKind::kInputsDelayed, 0, 250.0},
  };
  ASSERT_EQ(all.size(), wire::kMalfunctionKinds.size());
  for (const wire::Malfunction& m : all) {
    const std::string t = wire::MalfunctionText(m);
    EXPECT_EQ(wire::ParseMalfunction(t), m) << t;
  }
  EXPECT_EQ(wire::MalfunctionText(all[1]), "joint 6 drift -0.25");
  // Case and spaces are forgiven; the text sent is the canonical one.
  EXPECT_EQ(wire::MalfunctionText(wire::ParseMalfunction("  JOINT 2   Stuck ")), "joint 2 stuck");
  EXPECT_EQ(wire::ParseMalfunction("joint 4 drift +2").value, 2.0);
  for (const char* r : {"joint 2", "finger", "camera 5", "inputs", "all"})
    EXPECT_EQ(wire::RepairText(wire::ParseRepair(r)), r);
}

TEST(MalfunctionText, BadTextIsRefusedNamingWhatIsWrong) {
  struct Case {
    const char* text;
    const char* says;
  };
  for (const Case& c : std::vector<Case>{
           {"", "empty"},
           {"joint 7 stuck", "joint '7' is not 1..6"},
           {"joint 0 stuck", "joint '0' is not 1..6"},
           {"joint two stuck", "joint 'two'"},
           {"joint 2 broken", "'joint N stuck', 'joint N drift DEG_S' or 'joint N slow DEG_S'"},
           {"joint 2 drift", "4 words wanted"},
           {"joint 2 drift 50", "outside"},
           {"joint 2 slow 0", "outside"},
           {"joint 2 drift nan", "not a plain decimal number"},
           {"joint 2 drift -0", "a drift of 0 is no drift"},
           {"joint 2 drift 1e400", "not a plain decimal number"},
           {"joint 2 stuck now", "3 words wanted, as 'joint N stuck'"},
           {"finger jammed", "3 words wanted, as 'finger jammed open' or"},
           {"camera 2", "3 words wanted, as 'camera N lost'"},
           {"joint 2 drift 1e1", "not a plain decimal number"},
           {"finger jammed sideways", "'finger jammed open' or 'finger jammed closed'"},
           {"camera 9 lost", "camera station '9' is not 1..8"},
           {"inputs delayed 0", "outside"},
           {"inputs delayed 99999", "99999 is outside 1..3000 (the delay, ms)"},
           {"elbow stuck", "unknown part 'elbow'"},
           {"joint 2 stuck                                                          x", "longer"},
       }) {
    try {
      wire::ParseMalfunction(c.text);
      ADD_FAILURE() << "accepted '" << c.text << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.says), std::string::npos)
          << "'" << c.text << "': " << e.what();
      EXPECT_NE(std::string(e.what()).find("; a malfunction is 'joint N stuck'"), std::string::npos)
          << "shows the grammar";
    }
  }
  for (const Case& c : std::vector<Case>{{"", "empty"},
                                         {"joint", "'joint' takes its number N"},
                                         {"joint 9", "joint '9' is not 1..6"},
                                         {"camera 0", "camera station '0'"},
                                         {"finger 1", "'finger' takes no number"},
                                         {"everything", "unknown part 'everything'"}}) {
    try {
      wire::ParseRepair(c.text);
      ADD_FAILURE() << "accepted repair '" << c.text << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.says), std::string::npos) << e.what();
    }
  }
  // Said as a repair; a quoted text is cut at a character, controls shown.
  try {
    wire::ParseRepair("joint 9");
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("repair 'joint 9'", 0), 0u) << e.what();
  }
  try {
    wire::ParseMalfunction(std::string("joint\x01") + std::string(39, 'x') + "\xc3\xa9\xc3\xa9");
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_EQ(w.find('\x01'), std::string::npos) << w;
    EXPECT_NE(w.find("joint?"), std::string::npos) << w;
  }
  try {
    wire::ParseMalfunction(std::string(79, 'x') +
                           "\xc3\xa9");  // the cut falls inside the last character
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find(std::string(79, 'x') + "'"), std::string::npos) << "cut before it, whole";
  }
}

TEST(MalfunctionText, ARepairClearsOnlyItsOwn) {
  const wire::Malfunction stuck2{MalfunctionKind::kJointStuck, 2, 0.0};
  const wire::Malfunction cam2{MalfunctionKind::kCameraLost, 2, 0.0};
  EXPECT_TRUE(wire::Clears(wire::ParseRepair("joint 2"), stuck2));
  EXPECT_FALSE(wire::Clears(wire::ParseRepair("joint 3"), stuck2));
  EXPECT_FALSE(wire::Clears(wire::ParseRepair("camera 2"), stuck2));
  EXPECT_TRUE(wire::Clears(wire::ParseRepair("camera 2"), cam2));
  EXPECT_TRUE(wire::Clears(wire::ParseRepair("all"), cam2));
  EXPECT_FALSE(wire::Clears(wire::ParseRepair("inputs"), cam2));
  // Each malfunction's own part.
  for (const char* t :
       {"joint 4 drift 1", "finger jammed closed", "camera 3 lost", "inputs delayed 10"}) {
    const wire::Malfunction m = wire::ParseMalfunction(t);
    EXPECT_TRUE(wire::Clears(wire::RepairFor(m), m)) << t;
  }
  EXPECT_EQ(wire::RepairText(wire::RepairFor(wire::ParseMalfunction("joint 4 slow 1"))), "joint 4");
}

// The one table: each pattern starts with its part's word and has N exactly
// when the part is numbered; the grammar, help and docs are made from it.
TEST(MalfunctionText, TheTableMakesTheGrammarAndTheDocs) {
  for (const wire::MalfunctionKindInfo& k : wire::kMalfunctionKinds) {
    const wire::MalfunctionPartInfo& part = wire::PartInfo(k.part);
    const std::string pattern = k.pattern;
    EXPECT_EQ(pattern.rfind(std::string(part.word) + " ", 0), 0u) << pattern;
    EXPECT_EQ(pattern.find(" N ") != std::string::npos, part.count > 0) << pattern;
    EXPECT_EQ(pattern.find(" V") != std::string::npos, k.value[0] != '\0') << pattern;
    EXPECT_EQ(k.value_word[0] != '\0', k.value[0] != '\0') << pattern;
    EXPECT_NE(wire::MalfunctionGrammar().find(pattern.substr(0, pattern.find(" V"))),
              std::string::npos)
        << pattern;
  }
  EXPECT_NE(wire::MalfunctionGrammar().find("(joints 1..6, camera stations 1..8)"),
            std::string::npos);
  EXPECT_EQ(wire::RepairGrammar().rfind("'joint N', 'finger', 'camera N', 'inputs' or 'all'", 0),
            0u);
  std::ifstream f(std::string(RMSLAB_SOURCE_DIR) + "/docs/sessions.md");
  std::stringstream docs;
  docs << f.rdbuf();
  EXPECT_NE(docs.str().find(wire::MalfunctionTableMarkdown()), std::string::npos)
      << "docs/sessions.md \"Malfunctions\" is not the table: build/tools/rms_session "
         "malfunctions prints it";
}

// The Malfunctions object alone, at 10 Hz: every number exact.
class MalfunctionsAlone : public ::testing::Test {
 protected:
  dcp_model::Malfunctions m{
      10.0, {-180, -180, -180, -180, -180, -180}, {180, 180, 180, 180, 180, 180}};
  std::array<double, 6> slave{10, 20, 30, 40, 50, 60};
};

TEST_F(MalfunctionsAlone, AStuckJointStaysWhereItFailedWhateverIsCommanded) {
  m.Inject(wire::ParseMalfunction("joint 2 stuck"), slave, 0.3);
  std::array<double, 6> cmd{11, 25, 31, 41, 51, 61};
  double finger = 0.9;
  m.Apply(slave, &cmd, &finger);
  EXPECT_EQ(cmd[1], 20.0);
  EXPECT_EQ(cmd[0], 11.0) << "the others as commanded";
  EXPECT_EQ(finger, 0.9);
  m.Repair(wire::ParseRepair("joint 2"));
  cmd[1] = 25;
  m.Apply(slave, &cmd, &finger);
  EXPECT_EQ(cmd[1], 25.0);
  EXPECT_FALSE(m.any());
}

TEST_F(MalfunctionsAlone, ADriftingJointTurnsAtItsRateFromWhereItIs) {
  m.Inject(wire::ParseMalfunction("joint 1 drift -2"), slave, 0.3);
  std::array<double, 6> cmd = slave;
  double finger = 0.3;
  m.Apply(slave, &cmd, &finger);
  EXPECT_DOUBLE_EQ(cmd[0], 10.0 - 0.2);  // 2 deg/s at 10 Hz
  // Within the joint's range.
  dcp_model::Malfunctions edge(10.0, {9.9, 0, 0, 0, 0, 0}, {180, 180, 180, 180, 180, 180});
  edge.Inject(wire::ParseMalfunction("joint 1 drift -20"), slave, 0.3);
  edge.Apply(slave, &cmd, &finger);
  EXPECT_EQ(cmd[0], 9.9);
}

TEST_F(MalfunctionsAlone, ASlowJointMovesAtMostItsRate) {
  m.Inject(wire::ParseMalfunction("joint 3 slow 5"), slave, 0.3);
  std::array<double, 6> cmd = slave;
  double finger = 0.3;
  cmd[2] = 40;  // 10 deg away: 0.5 deg a frame at most
  m.Apply(slave, &cmd, &finger);
  EXPECT_DOUBLE_EQ(cmd[2], 30.5);
  cmd[2] = 30.2;  // within a frame's step: reached
  m.Apply(slave, &cmd, &finger);
  EXPECT_DOUBLE_EQ(cmd[2], 30.2);
}

TEST_F(MalfunctionsAlone, AJammedFingerCannotMoveTheWayItJammed) {
  std::array<double, 6> cmd = slave;
  double finger = 1.0;
  m.Inject(wire::ParseMalfunction("finger jammed open"), slave, 0.3);
  m.Apply(slave, &cmd, &finger);
  EXPECT_EQ(finger, 0.3) << "cannot close past where it jammed";
  finger = 0.1;
  m.Apply(slave, &cmd, &finger);
  EXPECT_EQ(finger, 0.1) << "may still open";
  m.Inject(wire::ParseMalfunction("finger jammed closed"), slave, 0.8);
  finger = 0.0;
  m.Apply(slave, &cmd, &finger);
  EXPECT_EQ(finger, 0.8) << "cannot open";
  EXPECT_EQ(m.active().size(), 1u) << "one finger malfunction: the new replaces the old";
}

TEST_F(MalfunctionsAlone, DelayedInputsAreAnsweredExactlyThatManyFramesLate) {
  auto block = [](int k) {
    wire::OperatorInputs in;
    in.value[0] = k;
    return in;
  };
  for (int k = 0; k < 5; ++k) EXPECT_EQ(m.Delay(block(k)).value[0], k) << "no delay";
  // 250 ms at 10 Hz: 3 frames (rounded); the last block answered (4) is held
  // until the first delayed one is due.
  m.Inject(wire::ParseMalfunction("inputs delayed 250"), slave, 0.3);
  EXPECT_EQ(m.delay_frames(), 3);
  std::vector<double> got;
  for (int k = 5; k < 12; ++k) got.push_back(m.Delay(block(k)).value[0]);
  EXPECT_EQ(got, (std::vector<double>{4, 4, 4, 5, 6, 7, 8}));
  // Through the checkpoint: the line goes on the same.
  dcp_model::Malfunctions copy(10.0, {-180, -180, -180, -180, -180, -180},
                               {180, 180, 180, 180, 180, 180});
  copy.FromJson(nlohmann::json::parse(m.ToJson().dump()));
  for (int k = 12; k < 20; ++k)
    EXPECT_EQ(copy.Delay(block(k)).value[0], m.Delay(block(k)).value[0]);
  // Repaired: the next frame answers its own block.
  m.Repair(wire::ParseRepair("inputs"));
  EXPECT_EQ(m.Delay(block(20)).value[0], 20);
}

TEST_F(MalfunctionsAlone, ABadStateIsRefusedAndChangesNothing) {
  m.Inject(wire::ParseMalfunction("camera 3 lost"), slave, 0.3);
  nlohmann::json j = m.ToJson();
  j["active"].push_back({{"text", "joint 9 stuck"}, {"anchor", 1.0}});
  EXPECT_THROW(m.FromJson(j), InputError);
  j = m.ToJson();
  j["active"].push_back({{"text", "joint 1 stuck"}});  // no anchor
  EXPECT_THROW(m.FromJson(j), InputError);
  EXPECT_TRUE(m.CameraLost(3));
  EXPECT_EQ(m.active().size(), 1u);
}

}  // namespace

namespace dcp_model {
namespace {

class DcpMalfunction : public testing::DcpFixture {
 protected:
  std::vector<wire::OperatorInputs> MissionInputs() const {
    const std::string text = mission::FormatTimeline(mission::PlanMission(config), "");
    const operator_station::Timeline tl =
        operator_station::Timeline::Parse(text, "mission", config.inputs);
    std::vector<wire::OperatorInputs> inputs;
    for (double t = 0; t <= tl.end_time(); t += 1.0 / config.session.frame_rate_hz)
      inputs.push_back(tl.Sample(t));
    return inputs;
  }
};

TEST_F(DcpMalfunction, AStuckJointStopsTheSlaveNotTheMasterAndIsRepaired) {
  const auto inputs = MissionInputs();
  DynamicCollisionProgram dcp(config);
  for (std::size_t k = 0; k < 60; ++k) dcp.Step(inputs[k]);
  // Find a joint the mission moves over the next second.
  int joint = -1;
  for (int i = 0; i < 6 && joint < 0; ++i) {
    if (std::abs(inputs[90].value[i] - inputs[60].value[i]) > 1.0) joint = i;
  }
  ASSERT_GE(joint, 0);
  const double at = dcp.status().slave.angles_deg[joint];
  dcp.Inject({MalfunctionKind::kJointStuck, joint + 1, 0.0});
  for (std::size_t k = 60; k < 90; ++k) {
    dcp.Step(inputs[k]);
    EXPECT_EQ(dcp.status().slave.angles_deg[joint], at) << k;
    EXPECT_EQ(dcp.status().master.angles_deg[joint], inputs[k].value[joint])
        << "the telemetry's master is the operator's command";
  }
  EXPECT_GT(std::abs(dcp.status().master.angles_deg[joint] - at), 1.0);
  dcp.Repair(wire::ParseRepair("joint " + std::to_string(joint + 1)));
  dcp.Step(inputs[90]);
  EXPECT_EQ(dcp.status().slave.angles_deg[joint], inputs[90].value[joint]) << "follows again";
}

TEST_F(DcpMalfunction, ALostStationSetsNoVideoOnlyWhenSelected) {
  DynamicCollisionProgram dcp(config);
  wire::OperatorInputs in = wire::InitialInputs(config.inputs);
  in.camera_station = 4;
  dcp.Inject({MalfunctionKind::kCameraLost, 4, 0.0});
  EXPECT_TRUE(dcp.Step(in).control.no_video);
  in.camera_station = 5;
  EXPECT_FALSE(dcp.Step(in).control.no_video);
  dcp.Repair(wire::ParseRepair("camera 4"));
  in.camera_station = 4;
  EXPECT_FALSE(dcp.Step(in).control.no_video);
}

TEST_F(DcpMalfunction, ACheckpointWithMalfunctionsGoesOnWordForWord) {
  const auto inputs = MissionInputs();
  DynamicCollisionProgram live(config);
  for (std::size_t k = 0; k < 100; ++k) live.Step(inputs[k]);
  live.Inject(wire::ParseMalfunction("joint 1 drift 0.5"));
  live.Inject(wire::ParseMalfunction("inputs delayed 300"));
  live.Inject(wire::ParseMalfunction("camera 2 lost"));
  for (std::size_t k = 100; k < 120; ++k) live.Step(inputs[k]);
  const nlohmann::json saved = nlohmann::json::parse(live.SaveState().dump());
  EXPECT_EQ(wire::MalfunctionTexts(saved),
            (std::vector<std::string>{"joint 1 drift 0.5", "camera 2 lost", "inputs delayed 300"}));
  DynamicCollisionProgram restored(config);
  restored.RestoreState(saved);
  for (std::size_t k = 120; k < 300; ++k) {
    const wire::DcpFrameData a = live.Step(inputs[k]), b = restored.Step(inputs[k]);
    dcp_frame_t wa, wb;
    wire::PackDcpFrame(a, &wa, nullptr);
    wire::PackDcpFrame(b, &wb, nullptr);
    ASSERT_EQ(std::memcmp(wa.arm_words, wb.arm_words, sizeof wa.arm_words), 0) << k;
    ASSERT_EQ(wa.control_word, wb.control_word) << k;
  }
  // A state without malfunctions has no key (as before they existed).
  DynamicCollisionProgram plain(config);
  EXPECT_FALSE(plain.SaveState().contains(wire::kMalfunctionsKey));
  plain.RestoreState(saved);
  plain.Repair(wire::ParseRepair("all"));
  EXPECT_FALSE(plain.SaveState().contains(wire::kMalfunctionsKey));
}

TEST_F(DcpMalfunction, AnotherDesignTakesTheRecordedMalfunctionsFromAState) {
  // Re-simulation with another design (docs/sessions.md "Re-simulation"):
  // a logged MALFUNCTION state brings its malfunctions, not its state.
  transport::LogLcm lcm("", "");
  dynamics_proc::DynamicsProc node(config, &lcm);
  DynamicCollisionProgram recorded(config);
  recorded.Inject(wire::ParseMalfunction("joint 1 stuck"));
  recorded.Inject(wire::ParseMalfunction("camera 2 lost"));
  dcp_state_t m{};
  m.reason = dcp_state_t::MALFUNCTION;
  m.next_frame = 7;
  wire::Checkpoint c;
  c.dcp = recorded.SaveState();
  m.checkpoint = wire::CheckpointText(c);
  node.ApplyState(m, false);
  auto texts = [&] {
    std::vector<std::string> t;
    for (const auto& f : node.program().malfunctions().active())
      t.push_back(wire::MalfunctionText(f));
    return t;
  };
  EXPECT_EQ(texts(), (std::vector<std::string>{"joint 1 stuck", "camera 2 lost"}));
  EXPECT_EQ(node.last_frame(), 6);
  // The next state: the joint repaired, a delay added; the camera kept.
  recorded.Repair(wire::ParseRepair("joint 1"));
  recorded.Inject(wire::ParseMalfunction("inputs delayed 100"));
  c.dcp = recorded.SaveState();
  m.checkpoint = wire::CheckpointText(c);
  node.ApplyState(m, false);
  EXPECT_EQ(texts(), (std::vector<std::string>{"camera 2 lost", "inputs delayed 100"}));
}

}  // namespace
}  // namespace dcp_model

namespace operator_station {
namespace {

dcp_telemetry_t Following() {
  dcp_telemetry_t t{};
  t.mode = 1;
  for (int i = 0; i < 6; ++i) t.master_angles_deg[i] = t.slave_angles_deg[i] = 10.0 * i;
  t.master_finger = t.slave_finger = 0.2;
  return t;
}

TEST(FollowWatch, AJointOffItsCommandForHalfASecondIsReportedOnceAndItsRecovery) {
  FollowWatch w(30.0);
  dcp_telemetry_t t = Following();
  t.master_angles_deg[1] += 2.0;  // the slave's joint 2 stays behind
  int reports = 0;
  for (int k = 0; k < 14; ++k) reports += static_cast<int>(w.Observe(t).size());
  EXPECT_EQ(reports, 0) << "under half a second: not yet";
  auto c = w.Observe(t);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_TRUE(c[0].failing);
  EXPECT_EQ(c[0].part, 1);
  EXPECT_NE(c[0].text.find("joint 2 (shoulder pitch) is NOT FOLLOWING"), std::string::npos);
  for (int k = 0; k < 30; ++k) EXPECT_TRUE(w.Observe(t).empty()) << "said once";
  EXPECT_EQ(w.failing(), 1u << 1);
  // Held by a collision: neither failing nor recovered meanwhile.
  t.held = true;
  t.master_angles_deg[1] = t.slave_angles_deg[1];
  EXPECT_TRUE(w.Observe(t).empty());
  t.held = false;
  c = w.Observe(t);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_FALSE(c[0].failing);
  EXPECT_EQ(w.failing(), 0u);
}

TEST(FollowWatch, HeldThoughCommandedWhereItIsIsAFailureOfTheArm) {
  // A drifting joint pushing the arm into a collision: the DCP holds it
  // where the command is; nothing the operator does explains it.
  FollowWatch w(30.0);
  dcp_telemetry_t t = Following();
  t.held = true;
  bool seen = false;
  for (int k = 0; k < 20; ++k) {
    for (const auto& c : w.Observe(t)) seen = seen || (c.part == FollowWatch::kArm && c.failing);
  }
  EXPECT_TRUE(seen);
  t.held = false;
  const auto c = w.Observe(t);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_FALSE(c[0].failing);
  // Held while the command is elsewhere is an ordinary collision: no failure.
  t = Following();
  t.held = true;
  t.master_angles_deg[0] += 3.0;
  for (int k = 0; k < 60; ++k) EXPECT_TRUE(w.Observe(t).empty());
  // Held where it is commanded while the operator flies into the contact
  // (the hand controllers carry on from the held pose each frame): the
  // operator's own collision, never "something moves it on its own".
  t = Following();
  t.held = true;
  for (int k = 0; k < 60; ++k) EXPECT_TRUE(w.Observe(t, /*commanding=*/true).empty());
}

TEST(FollowWatch, CollisionHoldsTheDockAndTheFingerOnTheBarAreNoFailure) {
  FollowWatch w(30.0);
  dcp_telemetry_t t = Following();
  t.master_angles_deg[0] += 5.0;
  t.held = true;
  for (int k = 0; k < 60; ++k) EXPECT_TRUE(w.Observe(t).empty());
  t.held = false;
  t.mode = 3;
  t.docked = true;  // captured at the port: the arm stays
  for (int k = 0; k < 60; ++k) EXPECT_TRUE(w.Observe(t).empty());
  t = Following();
  t.master_finger = 1.0;
  t.finger_held = true;  // closing onto the bar
  for (int k = 0; k < 60; ++k) EXPECT_TRUE(w.Observe(t).empty());
  t.finger_held = false;  // free and not closing: jammed
  bool seen = false;
  for (int k = 0; k < 20; ++k) {
    for (const auto& c : w.Observe(t)) seen = seen || (c.part == FollowWatch::kFinger && c.failing);
  }
  EXPECT_TRUE(seen);
}

}  // namespace
}  // namespace operator_station
}  // namespace rms
