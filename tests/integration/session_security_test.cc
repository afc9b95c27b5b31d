// Attacks on a running session and the lab's bad luck, as issue 13 found
// them (docs/security.md "Attacks and the tests that cover them",
// docs/sessions.md "Faults"): `scripts/lab demo` runs as a user
// starts it while another program on its network -- a stranger, or an
// insider who knows the session's id and pids -- sends control commands
// that reach for the filesystem, forged telemetry and status, a frame number
// from the far future; two sessions start on one address; the launcher is
// killed; a process fails at start; the disk is too small or fills up; the
// tools write to a full device. Each is refused, survived or reported.
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <set>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <thread>

#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/sender_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
#include "rms/wire/control_word.h"
#include "rms/wire/frame_numbers.h"
#include "rms/wire/message_auth.h"
#include "rms/wire/message_io.h"

#include "live_session.h"
#include "session_files.h"
#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::Counter;
using testing::LiveSession;
using testing::ReadFile;
using testing::ReadJson;
using testing::Script;
using testing::SourcePath;

std::int64_t Reason(const nlohmann::json& summary, const std::string& reason) {
  return summary["ignored"]["by_reason"].value(reason, 0L);
}
std::size_t FilesIn(const std::string& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.is_regular_file() ? 1 : 0;
  return n;
}
bool ProcessAlive(int pid) { return pid > 0 && (kill(pid, 0) == 0 || errno == EPERM); }
void Sleep(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

// The frame number of a logged message, if its sender is `pid` of session
// `id`; -1 otherwise or when it does not decode.
template <typename Message>
std::int64_t FrameFrom(const lcm::LogEvent& ev, std::int64_t id, int pid) {
  Message m;  // the session's messages end in their tag
  if (wire::SafeDecode(ev.data, ev.datalen - wire::kMacBytes, &m) != wire::DecodeError::kNone)
    return -1;
  return m.sender.session_id == id && m.sender.pid == pid ? m.frame : -1;
}

// Per channel, the distinct frame numbers the log holds from the session's
// own publisher, below the forgeries' far-ahead numbers (500000 and 2^47).
// Forgeries sent as the process itself repeat numbers it has sent.
std::map<std::string, long> GenuineFramesLogged(
    const std::string& log, std::int64_t id, const std::pair<const char*, int> (&publishers)[4]) {
  std::map<std::string, std::set<std::int64_t>> frames;
  lcm::LogFile f(log, "r");
  while (const lcm::LogEvent* ev = f.readNextEvent()) {
    for (const auto& [channel, pid] : publishers) {
      if (ev->channel != channel) continue;
      std::int64_t n = -1;
      if (ev->channel == wire::channels::kOperatorInput)
        n = FrameFrom<operator_input_t>(*ev, id, pid);
      else if (ev->channel == wire::channels::kDcpFrame)
        n = FrameFrom<dcp_frame_t>(*ev, id, pid);
      else if (ev->channel == wire::channels::kDcpTelemetry)
        n = FrameFrom<dcp_telemetry_t>(*ev, id, pid);
      else
        n = FrameFrom<esg_frame_t>(*ev, id, pid);
      if (n >= 0 && n < 500000) frames[channel].insert(n);
    }
  }
  std::map<std::string, long> counts;
  for (const auto& [channel, pid] : publishers)
    counts[channel] = static_cast<long>(frames[channel].size());
  return counts;
}

// The ESG frames the log holds from scene_proc (`pid` of session `id`), as
// messages: a number sent twice counted twice.
long GenuineMessagesLogged(const std::string& log, std::int64_t id, int pid) {
  long n = 0;
  lcm::LogFile f(log, "r");
  while (const lcm::LogEvent* ev = f.readNextEvent())
    if (ev->channel == wire::channels::kEsgFrame) n += FrameFrom<esg_frame_t>(*ev, id, pid) >= 0;
  return n;
}

// A program on the session's network: it sees every message (session id 0
// takes all) and publishes whatever it likes, with whatever sender; with
// the session's key (an insider: docs/security.md "Authenticated
// messages") its messages carry the key's tag, without it none.
class Peer {
 public:
  explicit Peer(const std::string& url, std::optional<wire::SessionKey> key = std::nullopt)
      : lcm_(transport::LcmOptions{url, "", 1000}), key_(key) {
    lcm_.Subscribe(wire::channels::kDcpFrame, [this](const void* d, int n, std::int64_t) {
      dcp_frame_t m;
      n -= wire::kMacBytes;  // the session's messages end in their tag
      if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone && m.frame > dcp_frame_) {
        dcp_frame_ = m.frame;
        last_dcp_ = m;
      }
    });
  }
  // Listens for `s` seconds; the latest DCP frame number seen.
  std::int64_t Listen(double s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(s);
    while (std::chrono::steady_clock::now() < end) lcm_.HandleSubscriptions(20);
    return dcp_frame_;
  }
  // Listens until the DCP has gone past `frame` or `max_s` seconds have
  // passed; the latest DCP frame number seen. A frozen session stays frozen
  // (nothing here sends RUN), so a generous wait tells a freeze from a
  // stall of a loaded machine without slowing the test when it is idle.
  std::int64_t ListenUntilPast(std::int64_t frame, double max_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(max_s);
    while (dcp_frame_ <= frame && std::chrono::steady_clock::now() < end)
      lcm_.HandleSubscriptions(20);
    return dcp_frame_;
  }
  const dcp_frame_t& last_dcp() const { return last_dcp_; }
  template <class Msg>
  void Send(const char* channel, Msg m, const transport::Sender& as) {
    m.sender.session_id = as.session_id;
    m.sender.process = as.process;
    m.sender.pid = as.pid;
    auto bytes = wire::EncodeMessage(m);
    ASSERT_FALSE(bytes.empty());
    if (key_) {
      const auto tag =
          wire::MessageMac(*key_, channel, bytes.data(), static_cast<int>(bytes.size()));
      bytes.insert(bytes.end(), tag.begin(), tag.end());
    }
    lcm_.Publish(channel, bytes.data(), static_cast<int>(bytes.size()));
  }
  void Control(std::int8_t command, const std::string& name, const transport::Sender& as) {
    session_control_t c{};
    c.send_time_us = transport::WallTimeUs();
    c.sequence = sequence_++;
    c.command = command;
    c.name = name;
    Send(wire::channels::kControl, c, as);
  }
  // Telemetry that says docked at 0.01 ft, its mode cycling (every message
  // a "mode change").
  void ForgeTelemetry(std::int64_t frame, const transport::Sender& as) {
    dcp_telemetry_t t{};
    t.frame = frame;
    t.input_frame = frame;
    t.send_time_us = t.input_send_time_us = transport::WallTimeUs();
    t.mode = static_cast<std::int8_t>(1 + frame % 3);
    t.acquired = t.docked = true;
    t.dock_distance_ft = 0.01;
    for (int i = 0; i < 9; i += 4) t.R_RS2[i] = t.R_RP[i] = 1;
    Send(wire::channels::kDcpTelemetry, t, as);
  }
  void ForgeStatus(const std::string& process, int pid, const transport::Sender& as) {
    process_status_t st{};
    st.send_time_us = transport::WallTimeUs();
    st.process = process;
    st.host = "forger";
    st.pid = pid;
    st.frame = 1000000000000;
    st.counter_names = {"published", "rendered", "received"};
    st.counter_values = {1000000000000, -999220, 1000000000000};
    st.num_counters = 3;
    Send(wire::channels::kStatus, st, as);
  }

 private:
  transport::UdpLcm lcm_;
  std::optional<wire::SessionKey> key_;
  std::int64_t dcp_frame_ = 0;
  dcp_frame_t last_dcp_{};
  std::int64_t sequence_ = 0;
};

// What each process counted of the attack of
// ForgedControlTelemetryStatusAndFramesChangeNothingAndAreReported: `files`
// the checkpoints folder's regular files after it.
void ExpectEveryProcessCountedWhatItRefused(const std::string& out, std::size_t files) {
  EXPECT_GE(Counter(out, "dynamics_proc", "control.rate_limited"), 250);
  EXPECT_GE(Counter(out, "dynamics_proc", "control.refused"),
            5);  // the paths, the link, the file, the device
  EXPECT_GE(Counter(out, "operator_station", "control.refused"), 3);
  EXPECT_GE(Counter(out, "dynamics_proc", "dropped.other_session"), 2);
  EXPECT_GE(Counter(out, "dynamics_proc", "dropped.far_ahead"), 1);
  // The outsider's: every one counted and dropped, by the process it was for.
  EXPECT_GE(Counter(out, "dynamics_proc", "dropped.bad_mac"), 2 * 5 + 1);
  EXPECT_GE(Counter(out, "operator_station", "dropped.bad_mac"), 2 * 5 + 2 * 30);
  EXPECT_EQ(Counter(out, "dynamics_proc", "control.malfunctions"), 0);
  EXPECT_EQ(Counter(out, "operator_station", "control.freezes"), 0) << "a forged FREEZE was taken";
  // The telemetry from a pid not the DCP's, while the DCP sends: an impostor.
  EXPECT_GE(Counter(out, "operator_station", "dropped.other_sender"), 85);
  EXPECT_EQ(Counter(out, "dynamics_proc", "control.checkpoints"), static_cast<long>(files) - 1);
}

struct SessionPids {
  int op = 0, dcp = 0, scene = 0;
};

// The summary after that attack: the real flight, and what it left out.
void ExpectTheSummaryTellsTheRealFlight(const std::string& out, std::int64_t id,
                                        std::int64_t stranger_id, SessionPids pids) {
  const nlohmann::json sum = ReadJson(out + "/summary.json");
  ASSERT_TRUE(sum.contains("docked")) << out;
  std::printf("ignored: %s\ndocking: %s\n", sum["ignored"].dump().c_str(),
              sum["docking"].dump().c_str());
  EXPECT_TRUE(sum["docked"].get<bool>());
  EXPECT_GT(sum["docking"]["distance_ft"].get<double>(), 0.05)
      << "the forged docking distance was believed";
  EXPECT_FALSE(sum["docking"]["after_restore"].get<bool>()) << "every restore was refused";
  EXPECT_EQ(sum["mode_changes"].size(), 2u) << sum["mode_changes"].dump();
  EXPECT_GE(Reason(sum, "other_session"), 90 + 1);
  EXPECT_GE(Reason(sum, "not_the_sessions_process"), 90 + 1);
  EXPECT_GE(Reason(sum, "telemetry_contradicts_its_dcp_frame") + Reason(sum, "repeated_frame"), 90);
  EXPECT_GE(Reason(sum, "implausible_status"), 1);
  EXPECT_GE(Reason(sum, "bad_mac"), 2 * 5 + 1 + 2 * 30);
  EXPECT_TRUE(sum["ignored"]["macs_checked"].get<bool>());
  // No outsider's command is in the summary's list of those sent.
  for (const auto& c : sum["control"]) {
    EXPECT_NE(c.value("name", ""), "joint 2 stuck") << sum["control"].dump();
    EXPECT_NE(c.value("name", ""), "outsider.json") << sum["control"].dump();
  }
  EXPECT_GE(Reason(sum, "disputed_dcp_frame"), 25);
  EXPECT_GE(Reason(sum, "dcp_frame_out_of_sequence"), 3);
  // The record's losses are the recorder's own, neither made up nor hidden
  // by the forgeries: each channel's loss is its publisher's count less the
  // distinct frames the log holds from the real process (a loaded machine's
  // recorder may lose a few; each is reported).
  const int op_pid = pids.op, dcp_pid = pids.dcp, scene_pid = pids.scene;
  const std::pair<const char*, int> publishers[] = {{wire::channels::kOperatorInput, op_pid},
                                                    {wire::channels::kDcpFrame, dcp_pid},
                                                    {wire::channels::kDcpTelemetry, dcp_pid},
                                                    {wire::channels::kEsgFrame, scene_pid}};
  const auto genuine = GenuineFramesLogged(out + "/lcmlog", id, publishers);
  for (const auto& [ch, r] : sum["record"]["by_channel"].items()) {
    ASSERT_TRUE(genuine.count(ch)) << ch;
    const long expected = std::max<long>(0, r["published"].get<long>() - genuine.at(ch));
    EXPECT_EQ(r["lost"].get<long>(), expected) << ch << ": " << r.dump();
  }
  bool listed = false;
  for (const auto& o : sum["ignored"]["other_sessions"])
    listed |= o.get<std::string>() == wire::FormatSessionId(stranger_id);
  EXPECT_TRUE(listed) << "the stranger's session is not listed";
  const auto& fr = sum["frames"];
  EXPECT_GE(fr["rendered"].get<long>(), 0);
  EXPECT_LE(fr["rendered"].get<long>(), fr["esg_published"].get<long>());
  EXPECT_LT(fr["dcp_published"].get<long>(), 100000);
  EXPECT_GE(fr["refused"]["far_ahead"].get<long>(), 1);
  EXPECT_GE(fr["refused"]["other_sender"].get<long>(), 85);
  // Forged telemetry and frames in the record do not stop it re-simulating:
  // the re-simulation takes, as the summary believes, the DCP's own
  // (docs/sessions.md "Re-simulation"), and the record lost nothing.
  EXPECT_EQ(sum["record"]["lost"], 0) << sum["record"].dump();
  EXPECT_GE(Counter(out, "scene_proc", "resyncs"), 1) << "scene_proc never followed back";
  const auto esg_messages = GenuineMessagesLogged(out + "/lcmlog", id, scene_pid);
  EXPECT_GT(esg_messages, genuine.at(wire::channels::kEsgFrame))
      << "no ESG frame number was sent twice: the case the record counts once is not tried";
  EXPECT_EQ(sum["resimulation"]["verdict"], "identical") << sum["resimulation"].dump();
}

// Control commands reach for the filesystem, forged telemetry and status
// try to rewrite the summary, and an input from the far future tries to
// lock the DCP, all while the autopilot flies: the session docks, nothing
// outside its checkpoints folder is touched, and the summary tells the
// real flight and lists what it left out.
TEST(SessionSecurity, ForgedControlTelemetryStatusAndFramesChangeNothingAndAreReported) {
  const std::string tmp = testing::MakeTempDir("security");
  LiveSession s(tmp, testing::UniqueLcmUrl(8600), {"--speed", "2"});
  ASSERT_TRUE(s.WaitRunning(60)) << ReadFile(s.log());
  const std::int64_t id = s.session_id();
  const std::int64_t stranger_id = id ^ 0x5a5a5a5a5a5a5a5aLL;
  const int dcp_pid = s.pid("dynamics_proc"), op_pid = s.pid("operator_station");
  ASSERT_GT(dcp_pid, 0);
  ASSERT_GT(op_pid, 0);
  std::printf("session %s, dynamics_proc pid %d, attacker's stranger id %s\n",
              wire::FormatSessionId(id).c_str(), dcp_pid,
              wire::FormatSessionId(stranger_id).c_str());
  const std::string cps = s.out() + "/checkpoints";
  // An insider: the session's key (SESSION/run/session.key) and id.
  Peer peer(s.url(), wire::ReadSessionKeyFile(s.out() + "/run/session.key"));
  // An outsider who hears every packet: the session's id and its processes'
  // pids, and no key (no tag, or another key's).
  Peer outsider(s.url());
  wire::SessionKey guess;
  guess.bytes.fill(0x5a);
  Peer guesser(s.url(), guess);
  const transport::Sender stranger{stranger_id, sender_t::PROCESS_CONTROL, 4242};
  const transport::Sender insider{id, sender_t::PROCESS_CONTROL,
                                  static_cast<std::int32_t>(getpid())};

  // A stranger's freeze is ignored: the DCP's frames go on.
  const std::int64_t before = peer.Listen(0.5);
  ASSERT_GT(before, 0) << "no DCP frames seen on " << s.url();
  peer.Control(session_control_t::FREEZE, "", stranger);
  peer.Control(session_control_t::CHECKPOINT, "stranger.json", stranger);
  peer.Listen(0.3);  // the commands' time to arrive
  EXPECT_GT(peer.ListenUntilPast(before + 10, 20), before + 10)
      << "a stranger's FREEZE froze the session";
  EXPECT_FALSE(fs::exists(cps + "/stranger.json"));

  // An outsider with the session's id and the operator's real pid: its
  // freeze, its malfunctions and a step are dropped (dropped.bad_mac), and
  // the DCP's frames go on.
  const transport::Sender as_operator{id, sender_t::PROCESS_OPERATOR_STATION, op_pid};
  const transport::Sender as_control{id, sender_t::PROCESS_CONTROL, 4343};
  for (Peer* p : {&outsider, &guesser}) {
    p->Control(session_control_t::FREEZE, "", as_operator);
    p->Control(session_control_t::FREEZE, "", as_control);
    p->Control(session_control_t::MALFUNCTION, "joint 2 stuck", as_control);
    p->Control(session_control_t::MALFUNCTION, "finger jammed open", as_control);
    p->Control(session_control_t::CHECKPOINT, "outsider.json", as_control);
  }
  const std::int64_t at_outsider = peer.Listen(0.2);
  EXPECT_GT(peer.ListenUntilPast(at_outsider + 10, 20), at_outsider + 10)
      << "an outsider's FREEZE froze the session";
  EXPECT_FALSE(fs::exists(cps + "/outsider.json"));

  // An insider's names that are paths, a link, a huge file, a FIFO, a
  // device: refused, nothing written or read outside the folder.
  fs::create_symlink(tmp + "/via_link.json", cps + "/link.json");
  {
    std::ofstream big(cps + "/big.json");
    big << std::string(2 << 20, ' ');
  }
  ASSERT_EQ(mkfifo((cps + "/fifo.json").c_str(), 0644), 0);
  for (const char* name :
       {"../../escaped.json", "../escaped.json", "/tmp/escaped.json", "link.json", "big.json"}) {
    peer.Control(session_control_t::CHECKPOINT, name, insider);
  }
  peer.Listen(1.0);  // the rate limit's burst
  for (const char* name :
       {"/dev/zero", "../run/dcp_state.json", "link.json", "big.json", "fifo.json"}) {
    peer.Control(session_control_t::RESTORE, name, insider);
    peer.Listen(0.6);
  }
  EXPECT_FALSE(fs::exists(tmp + "/escaped.json"));
  EXPECT_FALSE(fs::exists(s.out() + "/escaped.json"));
  EXPECT_FALSE(fs::exists("/tmp/escaped.json"));
  EXPECT_FALSE(fs::exists(tmp + "/via_link.json")) << "a checkpoint was written through a link";
  EXPECT_EQ(fs::file_size(cps + "/big.json"), std::uintmax_t{2} << 20)
      << "a checkpoint was written over a file";

  // A flood: at most a few a second are acted on.
  for (int i = 0; i < 300; ++i) {
    peer.Control(session_control_t::CHECKPOINT, "flood_" + std::to_string(i) + ".json", insider);
    if (i % 50 == 0) peer.Listen(0.1);
  }
  peer.Listen(2.5);
  // ... and a good one, afterwards, is.
  peer.Control(session_control_t::CHECKPOINT, "good.json", insider);

  // Forged telemetry: from a stranger, from a pid none of the session's
  // processes has, and as the DCP itself (its id and pid) for frames it has
  // already sent. A forged status with absurd counts, as the ESG.
  // (Past DCP frame 400, whatever the machine's load made of the steps
  // above: the forgeries below take frames 300 and 200 before it.)
  std::int64_t now = peer.Listen(0.2);
  for (int i = 0; i < 300 && now < 400; ++i) now = peer.Listen(0.1);
  ASSERT_GE(now, 400) << "the session did not reach DCP frame 400 in 30 s";
  const transport::Sender as_stranger_dcp{stranger_id, sender_t::PROCESS_DYNAMICS, dcp_pid};
  const transport::Sender as_fake_pid{id, sender_t::PROCESS_DYNAMICS, 1};
  const transport::Sender as_dcp{id, sender_t::PROCESS_DYNAMICS, dcp_pid};
  for (int i = 0; i < 90; ++i) {
    peer.ForgeTelemetry(now + 2 + i, as_stranger_dcp);
    peer.ForgeTelemetry(now + 2 + i, as_fake_pid);
    peer.ForgeTelemetry(now - 200 + i, as_dcp);
    peer.Listen(
        0.003);  // paced: a burst would overrun the recorder's socket, and the test would test that
  }
  // DCP frames as the DCP itself, for numbers it has sent, saying otherwise:
  // the numbers are disputed, and neither version is believed. Thirty in a
  // row, each above the one before, with the DCP stopped (as a loaded
  // machine stalls it): scene_proc follows the numbering back (`resyncs`,
  // docs/protocol.md "Frame numbers") and sends an ESG frame number a
  // second time, which the record counts once (docs/sessions.md "The
  // record": `frames_by_channel`), as the log's reader does.
  ASSERT_EQ(kill(dcp_pid, SIGSTOP), 0);
  peer.Listen(0.1);  // what the DCP sent before it stopped
  for (int i = 0; i < wire::SequenceTracker::kResyncAfter; ++i) {
    dcp_frame_t d = peer.last_dcp();  // well-formed words, as the DCP sends them
    d.frame = std::max<std::int64_t>(1, now - 300) + i;
    d.input_frame = d.frame + 7;
    d.send_time_us = d.input_send_time_us = transport::WallTimeUs();
    peer.Send(wire::channels::kDcpFrame, d, as_dcp);
    peer.Listen(0.003);
  }
  peer.Listen(0.2);  // scene_proc's time to take them
  ASSERT_EQ(kill(dcp_pid, SIGCONT), 0);
  // A docked DCP frame and its telemetry far ahead (frame 500000), as the
  // DCP itself: off the DCP's increasing run, neither believed.
  for (int i = 0; i < 3; ++i) {
    dcp_frame_t d = peer.last_dcp();
    wire::ControlWord w = wire::UnpackControlWord(d.control_word);
    w.mode = 3;
    w.acquired = w.docked = true;
    d.control_word = static_cast<std::int32_t>(wire::PackControlWord(w));
    d.frame = 500000 + i;
    d.input_frame = d.frame;
    d.send_time_us = d.input_send_time_us = transport::WallTimeUs();
    peer.Send(wire::channels::kDcpFrame, d, as_dcp);
    dcp_telemetry_t t{};
    t.frame = t.input_frame = d.frame;
    t.send_time_us = t.input_send_time_us = transport::WallTimeUs();
    t.mode = 3;
    t.acquired = t.docked = true;
    t.dock_distance_ft = 0.01;
    for (int k = 0; k < 9; k += 4) t.R_RS2[k] = t.R_RP[k] = 1;
    peer.Send(wire::channels::kDcpTelemetry, t, as_dcp);
    peer.Listen(0.003);
  }
  const int esg_pid = s.pid("esg_renderer");
  peer.ForgeStatus("esg_renderer", 999999, {id, sender_t::PROCESS_ESG, 999999});
  peer.ForgeStatus("esg_renderer", esg_pid, {stranger_id, sender_t::PROCESS_ESG, esg_pid});
  peer.ForgeStatus("esg_renderer", 999998, {id, sender_t::PROCESS_ESG, esg_pid});

  // One operator input from the far future (2^47), as the station itself.
  operator_input_t far{};
  far.frame = std::int64_t{1} << 47;
  far.send_time_us = transport::WallTimeUs();
  peer.Send(wire::channels::kOperatorInput, far, {id, sender_t::PROCESS_OPERATOR_STATION, op_pid});
  // ... and as an outsider, inside the clock's limit: dropped before the DCP
  // numbers anything by it.
  operator_input_t near = far;
  near.frame = peer.Listen(0.05) + 60;
  outsider.Send(wire::channels::kOperatorInput, near, as_operator);
  for (int i = 0; i < 30; ++i) {
    outsider.ForgeTelemetry(now + 2 + i, {id, sender_t::PROCESS_DYNAMICS, dcp_pid});
    guesser.ForgeTelemetry(now + 2 + i, {id, sender_t::PROCESS_DYNAMICS, dcp_pid});
    peer.Listen(0.003);
  }

  ASSERT_TRUE(testing::WaitForFile(cps + "/good.json", 10))
      << "a valid checkpoint after the flood was not written";
  // rms_control says so when it cannot: an existing name.
  const auto again =
      Script({testing::BuildPath("tools/rms_control"), "--session", s.out(), "checkpoint", "good"},
             tmp + "/control.log", 30);
  EXPECT_EQ(again.rc, 1) << again.out;
  EXPECT_NE(again.out.find("exists already"), std::string::npos) << again.out;
  ASSERT_EQ(s.Wait(240), 0) << ReadFile(s.log());

  // The checkpoints folder's regular files: the test's big.json, the good
  // one, and at most what the rate limit lets through of the flood.
  const std::size_t files = FilesIn(cps);
  std::printf("checkpoints folder: %zu files after 300 requests in a flood\n", files);
  EXPECT_LE(files, 2u + 8u);
  const std::string out = s.out();
  ExpectEveryProcessCountedWhatItRefused(out, files);
  ExpectTheSummaryTellsTheRealFlight(out, id, stranger_id, {op_pid, dcp_pid, s.pid("scene_proc")});
  if (::testing::Test::HasFailure())
    std::printf("kept for a look: %s\n", tmp.c_str());
  else
    fs::remove_all(tmp);
}

// Two stations on one address: the second is refused at start, naming the
// first and the way round it; with --share-network both fly their own arms
// beside each other and each summary is its own session's.
TEST(SessionSecurity, ASecondSessionOnTheAddressIsRefusedOrWithShareNetworkBothDock) {
  const std::string tmp = testing::MakeTempDir("two_sessions");
  const std::string url = testing::UniqueLcmUrl(8620);
  fs::create_directories(tmp + "/a");
  LiveSession first(tmp + "/a", url, {"--speed", "2"});
  ASSERT_TRUE(first.WaitRunning(60)) << ReadFile(first.log());

  fs::create_directories(tmp + "/b");
  const auto refused =
      Script({SourcePath("scripts/lab"), "demo", "--no-build", "--out", tmp + "/b/session",
              "--lcm-url", url, "--png-every", "0", "--no-video"},
             tmp + "/b/lab.log", 60);
  EXPECT_NE(refused.rc, 0) << refused.out;
  EXPECT_NE(refused.out.find("another session is"), std::string::npos) << refused.out;
  EXPECT_NE(refused.out.find(wire::FormatSessionId(first.session_id())), std::string::npos)
      << refused.out;
  EXPECT_NE(refused.out.find("--channel-suffix"), std::string::npos) << refused.out;
  EXPECT_FALSE(fs::exists(tmp + "/b/session/lcmlog"));

  fs::create_directories(tmp + "/c");
  LiveSession second(tmp + "/c", url, {"--speed", "2", "--share-network"});
  ASSERT_TRUE(second.WaitRunning(60)) << ReadFile(second.log());
  EXPECT_NE(ReadFile(second.log()).find("--share-network"), std::string::npos);
  ASSERT_EQ(first.Wait(240), 0) << ReadFile(first.log());
  ASSERT_EQ(second.Wait(240), 0) << ReadFile(second.log());
  for (const LiveSession* x : {&first, &second}) {
    const nlohmann::json sum = ReadJson(x->out() + "/summary.json");
    std::printf("%s: docked %s at %s; ignored %s\n", x->out().c_str(),
                sum.value("docked", false) ? "yes" : "no", sum["docking"].dump().c_str(),
                sum["ignored"].dump().c_str());
    EXPECT_TRUE(sum.value("docked", false));
    EXPECT_EQ(sum["mode_changes"].size(), 2u);
    EXPECT_EQ(sum["session_id"].get<std::string>(), wire::FormatSessionId(x->session_id()));
    EXPECT_GT(Counter(x->out(), "dynamics_proc", "dropped.other_session"), 0);
    // Its record is its own, whole, and re-simulates; another design of it
    // can be flown (docs/sessions.md "Re-simulation").
    EXPECT_EQ(sum["record"]["lost"], 0) << sum["record"].dump();
    EXPECT_EQ(sum["resimulation"]["verdict"], "identical") << sum["resimulation"].dump();
    const auto other = Script({testing::SourcePath("scripts/lab"), "resim", x->out(), "--no-build",
                               "--set", "dcp.tpob_ft=0.4"},
                              x->out() + "-resim-set.log");
    EXPECT_EQ(other.rc, 0) << other.out;
  }
  // The second's traffic is in the first's record, and left out by its
  // summary (the first was running all the while the second flew).
  EXPECT_GT(Reason(ReadJson(first.out() + "/summary.json"), "other_session"), 100);
  fs::remove_all(tmp);
}

// kill -9 of the launcher: the reaper stops every process of the session
// (nothing is left running) and writes the summary.
TEST(SessionSecurity, KillingTheLauncherLeavesNoProcessAndASummary) {
  const std::string tmp = testing::MakeTempDir("kill_launcher");
  LiveSession s(tmp, testing::UniqueLcmUrl(8640));
  ASSERT_TRUE(s.WaitRunning(60)) << ReadFile(s.log());
  Sleep(2);
  const std::vector<int> kids = s.children();
  ASSERT_GE(kids.size(), 5u) << ReadFile(s.out() +
                                         "/run/children");  // four processes and the recorder
  for (int p : kids) ASSERT_TRUE(ProcessAlive(p)) << p;
  // The reaper killed first: the launcher starts it again.
  const auto reaper =
      Script({"/usr/bin/pgrep", "-f", "rmslab_launcher.reaper --session " + s.out()},
             tmp + "/pgrep.log", 10);
  ASSERT_EQ(reaper.rc, 0) << "no reaper running";
  kill(std::stoi(reaper.out), SIGKILL);
  const auto end_r = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (ReadFile(s.log()).find("the reaper") == std::string::npos &&
         std::chrono::steady_clock::now() < end_r)
    Sleep(0.1);
  ASSERT_NE(ReadFile(s.log()).find("starting it again"), std::string::npos) << ReadFile(s.log());
  Sleep(0.5);
  // A pid in run/children that is no longer the session's (reused by another
  // program): never signalled.
  testing::Subprocess bystander({"/usr/bin/sleep", "120"}, tmp + "/bystander.log");
  {
    std::ofstream children(s.out() + "/run/children", std::ios::app);
    children << "esg_renderer " << bystander.pid() << " localhost 0 -\n";
  }
  s.Signal(SIGKILL);
  EXPECT_EQ(s.Wait(10), 128 + SIGKILL);
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  std::vector<int> left = kids;
  while (!left.empty() && std::chrono::steady_clock::now() < end) {
    std::erase_if(left, [](int p) { return !ProcessAlive(p); });
    Sleep(0.1);
  }
  EXPECT_TRUE(left.empty()) << left.size() << " of the session's processes still run, e.g. pid "
                            << left.front();
  EXPECT_TRUE(bystander.Running()) << "the reaper signalled a process that is not the session's";
  ASSERT_TRUE(testing::WaitForFile(s.out() + "/summary.json", 30))
      << ReadFile(s.out() + "/logs/reaper.log");
  const nlohmann::json sum = ReadJson(s.out() + "/summary.json");
  EXPECT_GT(sum["log"]["dcp_frames"].get<long>(), 0);
  EXPECT_NE(ReadFile(s.out() + "/run/exit_codes").find("launcher 137"), std::string::npos);
  fs::remove_all(tmp);
}

// Bad input is refused before anything starts, with the reason shown:
// a bad config key, a width of 0, a channel suffix with a pattern in it.
// docs/security.md "Locks and temporary files": the address lock lives in
// the user's own 0700 folder; a link or another user's folder in its place
// is refused at start, said, and nothing is written through it.
TEST(SessionSecurity, LocksLiveInTheUsersOwnFolder) {
  const std::string tmp = testing::MakeTempDir("locks");
  const std::string xdg = tmp + "/xdg";
  fs::create_directories(xdg);
  fs::create_directories(tmp + "/elsewhere");
  auto demo = [&](const std::string& name) {
    return Script({"/usr/bin/env", "XDG_RUNTIME_DIR=" + xdg, SourcePath("scripts/lab"), "demo",
                   "--no-build", "--out", tmp + "/" + name, "--lcm-url",
                   testing::UniqueLcmUrl(8680), "--png-every", "0", "--no-video"},
                  tmp + "/" + name + ".log", 120);
  };
  fs::create_directory_symlink(tmp + "/elsewhere", xdg + "/rmslab");
  const auto linked = demo("linked");
  EXPECT_EQ(linked.rc, 2) << linked.out;
  EXPECT_NE(linked.out.find("is a link"), std::string::npos) << linked.out;
  EXPECT_TRUE(fs::is_empty(tmp + "/elsewhere"));
  fs::remove(xdg + "/rmslab");
  if (geteuid() == 0) {  // another user's folder (root can make one for the test)
    fs::create_directory(xdg + "/rmslab");
    ASSERT_EQ(chown((xdg + "/rmslab").c_str(), 65534, 65534), 0);
    const auto theirs = demo("theirs");
    EXPECT_EQ(theirs.rc, 2) << theirs.out;
    EXPECT_NE(theirs.out.find("not to you"), std::string::npos) << theirs.out;
    EXPECT_TRUE(fs::is_empty(xdg + "/rmslab"));
    fs::remove(xdg + "/rmslab");
  } else {
    std::printf("not root: another user's folder not tried\n");
  }
  // A folder open to others is closed; the lock is made there, 0600, and
  // removed at the launcher's exit.
  fs::create_directory(xdg + "/rmslab");
  fs::permissions(xdg + "/rmslab", fs::perms::all);
  testing::Subprocess lab(
      {"/usr/bin/env", "XDG_RUNTIME_DIR=" + xdg, SourcePath("scripts/lab"), "demo", "--no-build",
       "--out", tmp + "/ours", "--lcm-url", testing::UniqueLcmUrl(8690), "--png-every", "0",
       "--no-video", "--speed", "4"},
      tmp + "/ours.log");
  ASSERT_TRUE(testing::WaitForFile(tmp + "/ours/run/operator_station.ready", 90))
      << ReadFile(tmp + "/ours.log");
  EXPECT_EQ(fs::status(xdg + "/rmslab").permissions() & fs::perms::all, fs::perms::owner_all);
  int locks = 0;
  for (const auto& e : fs::directory_iterator(xdg + "/rmslab")) {
    if (e.path().filename().string().rfind("address-", 0) != 0) continue;
    ++locks;
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(e.path())));
    EXPECT_EQ(fs::status(e.path()).permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write);
  }
  EXPECT_EQ(locks, 1);
  EXPECT_EQ(lab.Wait(240), 0) << ReadFile(tmp + "/ours.log");
  EXPECT_TRUE(fs::is_empty(xdg + "/rmslab"));
}

TEST(SessionSecurity, BadInputIsRefusedBeforeAnythingStartsWithTheReasonShown) {
  const std::string tmp = testing::MakeTempDir("bad_input");
  {
    std::ofstream cfg(tmp + "/bad.toml");
    std::string text = ReadFile(SourcePath("config/rmslab.toml"));
    text.replace(text.find("[arm]\n"), 6, "[arm]\nboom_lenght_ft = 3\n");
    cfg << text;
  }
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  {
    std::ofstream latin1(tmp + "/latin1.toml");
    latin1 << "\xff\xfe[session]\n";
    std::ofstream(tmp + "/a_file") << "x";
  }
  const std::vector<Case> cases = {
      {{"--config", tmp + "/bad.toml"}, "boom_lenght_ft"},
      {{"--width", "0"}, "width"},
      {{"--channel-suffix", "X.*"}, "--channel-suffix"},
      {{"--config", tmp + "/latin1.toml"}, "not TOML"},
      {{"--lcm-url", "garbage"}, "--lcm-url 'garbage'"},
      {{"--lcm-url", "udpm://10.1.2.3:7667?ttl=0"}, "not an IPv4 multicast group"},
      {{"--out", tmp + "/a_file/session"}, "cannot make the session's folder"}};
  int n = 0;
  for (const auto& c : cases) {
    const std::string out = tmp + "/s" + std::to_string(n++);
    std::vector<std::string> argv = {
        SourcePath("scripts/lab"),  "demo", "--no-build", "--out", out, "--lcm-url",
        testing::UniqueLcmUrl(8660)};
    argv.insert(argv.end(), c.args.begin(), c.args.end());  // a later --out or --lcm-url wins
    const auto r = Script(argv, out + ".log", 60);
    EXPECT_EQ(r.rc, 2) << r.out;
    EXPECT_NE(r.out.find(c.says), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("Traceback"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out + "/lcmlog")) << "something started: " << r.out;
    EXPECT_FALSE(fs::exists(out + "/run/pids")) << r.out;
  }
  fs::remove_all(tmp);
}

// Removed at the end of the test, after the disk on it is unmounted.
struct RemovedAfter {
  std::string path;
  ~RemovedAfter() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// A disk of its own for a test (a tmpfs; skipped where mounting is not allowed).
class SmallDisk {
 public:
  SmallDisk(const std::string& dir, int megabytes) : dir_(dir) {
    fs::create_directories(dir);
    const std::string opts = "size=" + std::to_string(megabytes) + "m";
    mounted_ = mount("tmpfs", dir.c_str(), "tmpfs", 0, opts.c_str()) == 0;
  }
  ~SmallDisk() {
    if (mounted_) umount2(dir_.c_str(), MNT_DETACH);
  }
  bool mounted() const { return mounted_; }

 private:
  std::string dir_;
  bool mounted_ = false;
};

// A disk that cannot hold the session is refused at start, saying how
// much it has and needs.
TEST(SessionSecurity, ADiskTooSmallForTheSessionIsRefusedAtStart) {
  const std::string tmp = testing::MakeTempDir("small_disk");
  const RemovedAfter cleanup{tmp};
  SmallDisk disk(tmp + "/disk", 8);
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here (not root?)";
  std::printf("a tmpfs of 8 MB at %s/disk\n", tmp.c_str());
  const auto r =
      Script({SourcePath("scripts/lab"), "demo", "--no-build", "--out", tmp + "/disk/session",
              "--lcm-url", testing::UniqueLcmUrl(8680), "--png-every", "0", "--no-video"},
             tmp + "/lab.log", 60);
  EXPECT_NE(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("not enough free space"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("MB free"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(tmp + "/disk/session/lcmlog"));
}

// A disk that fills while the session flies: the session says so at
// once, stops cleanly, and its summary goes elsewhere when its own folder
// cannot take it, the loss stated.
TEST(SessionSecurity, ADiskThatFillsStopsTheSessionAndTheSummaryIsWrittenElsewhere) {
  const std::string tmp = testing::MakeTempDir("full_disk");
  const RemovedAfter cleanup{tmp};
  // The session's folder is the tmpfs; the launcher's own output is not on it.
  SmallDisk disk(tmp + "/session", 48);  // room at start for the log three times over
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here (not root?)";
  LiveSession s(tmp, testing::UniqueLcmUrl(8690));
  ASSERT_TRUE(s.WaitRunning(60)) << ReadFile(s.log());
  Sleep(3);
  // Fill it to the last byte.
  {
    const int fd = open((tmp + "/session/filler").c_str(), O_WRONLY | O_CREAT, 0644);
    ASSERT_GE(fd, 0);
    const std::string block(1 << 16, 'x');
    while (write(fd, block.data(), block.size()) > 0) {
    }
    const std::string small(512, 'x');
    while (write(fd, small.data(), small.size()) > 0) {
    }
    close(fd);
  }
  const int rc = s.Wait(60);
  const std::string said = ReadFile(s.log());
  std::printf("%s\n", said.c_str());
  EXPECT_NE(rc, 0);
  EXPECT_TRUE(said.find("nearly full") != std::string::npos ||
              said.find("is full") != std::string::npos)
      << said;
  const auto at = said.find("written to ");
  ASSERT_NE(at, std::string::npos) << "no summary written elsewhere: " << said;
  const std::string where = said.substr(at + 11, said.find(" instead", at) - at - 11);
  const nlohmann::json sum = ReadJson(where);
  EXPECT_GT(sum["log"]["dcp_frames"].get<long>(), 0) << where;
  fs::remove(where);
}

// Every tool exits non-zero when it cannot write its output whole; an
// export cut by a full disk keeps none of its files (docs/sessions.md
// "Export"), and the last export's stand as they were.
TEST(SessionSecurity, ToolsExitNonZeroWhenTheirOutputCannotBeWritten) {
  const std::string tmp = testing::MakeTempDir("dev_full");
  LiveSession s(tmp, testing::UniqueLcmUrl(8700),
                {"--timeline", SourcePath("scripts/timelines/short.tl")});
  ASSERT_EQ(s.Wait(120), 0) << ReadFile(s.log());
  const std::string tool = testing::BuildPath("tools/rms_session");
  const auto sum = Script({tool, "summary", s.out(), "--out", "/dev/full"}, tmp + "/t1.log", 60);
  EXPECT_NE(sum.rc, 0) << sum.out;
  EXPECT_NE(sum.out.find("/dev/full"), std::string::npos) << sum.out;
  {
    SmallDisk disk(tmp + "/small", 1);
    if (!disk.mounted()) {
      std::printf("not root: the export onto a full disk not tried\n");
    } else {
      // Room for about 100 KiB more: less than this export needs.
      std::ofstream(tmp + "/small/pad") << std::string(900 * 1024, 'x');
      std::ofstream(tmp + "/small/dcp_telemetry.csv") << "the last export's\n";
      const auto exp =
          Script({tool, "export", s.out(), "--out", tmp + "/small"}, tmp + "/t2.log", 60);
      EXPECT_NE(exp.rc, 0) << exp.out;
      EXPECT_NE(exp.out.find(".csv"), std::string::npos) << exp.out;
      EXPECT_NE(exp.out.find("none of this export's files were kept"), std::string::npos)
          << exp.out;
      std::set<std::string> left;
      for (const auto& e : fs::directory_iterator(tmp + "/small"))
        left.insert(e.path().filename().string());
      EXPECT_EQ(left, (std::set<std::string>{"dcp_telemetry.csv", "pad"})) << "a part left";
      EXPECT_EQ(ReadFile(tmp + "/small/dcp_telemetry.csv"), "the last export's\n");
    }
  }
  fs::remove_all(tmp);
}

// docs/security.md "Session folders are untrusted": links, FIFOs and
// devices planted in a session's folder are refused by every tool that
// reads it, promptly and saying which file; outputs are never written
// through a link planted at their names; nothing is written outside.
TEST(SessionSecurity, ToolsTreatASessionFolderAsUntrusted) {
  const std::string tmp = testing::MakeTempDir("untrusted");
  LiveSession s(tmp, testing::UniqueLcmUrl(8710),
                {"--timeline", SourcePath("scripts/timelines/short.tl")});
  ASSERT_EQ(s.Wait(120), 0) << ReadFile(s.log());
  const std::string tool = testing::BuildPath("tools/rms_session");
  const std::string secret = tmp + "/secret";
  std::ofstream(secret) << "SECRET-CONTENT\n";
  fs::create_directories(tmp + "/elsewhere");
  auto copy = [&](const std::string& name) {
    std::string d = tmp + "/" + name;
    fs::copy(s.out(), d, fs::copy_options::recursive);
    return d;
  };
  // Outputs at planted links: replaced, not written through.
  {
    const std::string d = copy("links");
    for (const char* f : {"/report.html", "/summary.json", "/csv"}) fs::remove_all(d + f);
    fs::create_symlink(secret, d + "/report.html");
    fs::create_symlink(secret, d + "/summary.json");
    fs::create_directory_symlink(tmp + "/elsewhere", d + "/csv");
    fs::create_directories(d + "/frames");
    fs::create_symlink(secret, d + "/frames/frame_000001.png");  // a frame linked to a secret
    const auto rep =
        Script({SourcePath("scripts/lab"), "report", d, "--no-build"}, tmp + "/report.log", 120);
    EXPECT_EQ(rep.rc, 0) << rep.out;
    EXPECT_FALSE(fs::is_symlink(d + "/report.html"));
    EXPECT_EQ(ReadFile(d + "/report.html").find("U0VDUkVU"), std::string::npos)
        << "the secret, base64, in the report";
    EXPECT_NE(ReadFile(d + "/report.html").find("a link, not followed"), std::string::npos);
    const auto sum = Script({tool, "summary", d}, tmp + "/summary.log", 60);
    EXPECT_EQ(sum.rc, 0) << sum.out;
    EXPECT_FALSE(fs::is_symlink(d + "/summary.json"));
    const auto exp = Script({tool, "export", d}, tmp + "/export.log", 60);
    EXPECT_NE(exp.rc, 0) << exp.out;
    EXPECT_NE(exp.out.find("a link or a file, not a folder"), std::string::npos) << exp.out;
    EXPECT_EQ(ReadFile(secret), "SECRET-CONTENT\n");
    EXPECT_TRUE(fs::is_empty(tmp + "/elsewhere"));
    // The sweep's own files in an --out folder with links planted in it.
    fs::create_directories(tmp + "/sweep-out");
    for (const char* f : {"sweep.json", "cells.tsv", "sweep.csv"})
      fs::create_symlink(secret, tmp + "/sweep-out/" + f);
    const auto sw =
        Script({SourcePath("scripts/lab"), "sweep", s.out(), "--vary", "dcp.tpob_ft=0.2,0.3",
                "--out", tmp + "/sweep-out", "--cache", tmp + "/sweep-cache", "--no-build"},
               tmp + "/sweep.log", 240);
    EXPECT_EQ(sw.rc, 0) << sw.out;
    EXPECT_EQ(ReadFile(secret), "SECRET-CONTENT\n") << "written through a planted link";
    EXPECT_FALSE(fs::is_symlink(tmp + "/sweep-out/sweep.json"));
  }
  // An --out the user names outside the folder is theirs: a link to their
  // standard output is followed, never replaced (as root, the MCAP export
  // once replaced /dev/stdout itself).
  {
    const std::string mine = tmp + "/my-stdout";
    fs::create_symlink("/proc/self/fd/1", mine);
    const auto sum = Script({tool, "summary", s.out(), "--out", mine}, tmp + "/mine1.log", 60);
    EXPECT_EQ(sum.rc, 0) << sum.out;
    const auto rep = Script({testing::BuildPath("tools/rms_report"), s.out(), "--out", mine},
                            tmp + "/mine2.log", 120);
    EXPECT_EQ(rep.rc, 0) << rep.out.substr(0, 500);
    EXPECT_NE(rep.out.find("window.RMS_REPORT"), std::string::npos) << "the report not on stdout";
    const auto mcap = Script(
        {SourcePath("scripts/lab"), "export", s.out(), "--mcap", "--out", mine, "--no-build"},
        tmp + "/mine3.log", 120);
    EXPECT_EQ(mcap.rc, 0) << mcap.out.substr(0, 500);
    EXPECT_NE(mcap.out.find("\x89MCAP"), std::string::npos) << "the MCAP not on stdout";
    EXPECT_TRUE(fs::is_symlink(mine)) << "the user's link replaced by a file";
    // A FIFO the user names that nothing reads: refused at once, not waited on.
    ASSERT_EQ(mkfifo((tmp + "/no-reader").c_str(), 0600), 0);
    const auto t0 = std::chrono::steady_clock::now();
    const auto fifo = Script({SourcePath("scripts/lab"), "export", s.out(), "--mcap", "--out",
                              tmp + "/no-reader", "--no-build"},
                             tmp + "/mine4.log", 60);
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(30)) << "it waited";
    EXPECT_NE(fifo.rc, 0) << fifo.out;
    EXPECT_NE(fifo.out.find("a FIFO that nothing reads"), std::string::npos) << fifo.out;
  }
  // The session's folder named with a trailing slash, or through a link to
  // it, is still the folder: a link planted at an output's name there is
  // replaced; a device node planted there (an archive unpacked as root
  // keeps them) is replaced, not written into.
  {
    const std::string d = copy("slash");
    fs::create_directory_symlink(d, tmp + "/alias");
    fs::remove(d + "/summary.json");
    fs::create_symlink(secret, d + "/summary.json");
    fs::create_symlink(secret, d + "/report.html");
    EXPECT_EQ(Script({tool, "summary", d + "/"}, tmp + "/slash1.log", 60).rc, 0);
    EXPECT_EQ(
        Script({testing::BuildPath("tools/rms_report"), d + "/"}, tmp + "/slash2.log", 120).rc, 0);
    fs::remove(d + "/summary.json");
    fs::create_symlink(secret, d + "/summary.json");
    EXPECT_EQ(Script({tool, "summary", tmp + "/alias", "--out", tmp + "/alias/summary.json"},
                     tmp + "/slash3.log", 60)
                  .rc,
              0);
    EXPECT_EQ(ReadFile(secret), "SECRET-CONTENT\n") << "written through a planted link";
    EXPECT_FALSE(fs::is_symlink(d + "/summary.json"));
    EXPECT_FALSE(fs::is_symlink(d + "/report.html"));
    if (geteuid() == 0) {
      fs::remove(d + "/summary.json");
      ASSERT_EQ(mknod((d + "/summary.json").c_str(), S_IFCHR | 0600, makedev(1, 3)), 0);
      EXPECT_EQ(Script({tool, "summary", d}, tmp + "/dev.log", 60).rc, 0);
      EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(d + "/summary.json")))
          << "a device node in the folder written into, not replaced";
    }
  }
  // Inputs that are not regular files: refused at once, naming the file.
  struct Case {
    std::string file, kind;
  };
  for (const Case& c :
       {Case{"config.toml", "fifo"}, Case{"config.toml", "zero"}, Case{"lcmlog", "fifo"},
        Case{"manifest.json", "link"}, Case{"run/pids", "fifo"}}) {
    SCOPED_TRACE(c.file + " as a " + c.kind);
    const std::string d = copy("in-" + c.kind + "-" + fs::path(c.file).filename().string());
    fs::remove(d + "/" + c.file);
    if (c.kind == "fifo") {
      ASSERT_EQ(mkfifo((d + "/" + c.file).c_str(), 0600), 0);
    }
    if (c.kind == "zero") fs::create_symlink("/dev/zero", d + "/" + c.file);
    if (c.kind == "link") fs::create_symlink(s.out() + "/" + c.file, d + "/" + c.file);
    const auto t0 = std::chrono::steady_clock::now();
    const auto sum = Script({tool, "summary", d, "--out", tmp + "/x.json"}, tmp + "/in.log", 60);
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(30)) << "it waited";
    EXPECT_NE(sum.rc, 0) << sum.out;
    EXPECT_NE(sum.out.find(c.file), std::string::npos) << sum.out;
    if (c.file == "config.toml" || c.file == "manifest.json") {  // once hung on a FIFO config
      const auto t1 = std::chrono::steady_clock::now();
      const auto rs =
          Script({testing::BuildPath("tools/rms_resim"), d, "--quiet"}, tmp + "/resim.log", 60);
      EXPECT_LT(std::chrono::steady_clock::now() - t1, std::chrono::seconds(30)) << "it waited";
      EXPECT_EQ(rs.rc, 2) << rs.out;
      EXPECT_NE(rs.out.find(c.file), std::string::npos) << rs.out;
    }
    if (c.file == "config.toml") {  // a replay once copied /dev/zero without end
      const auto rep = Script({SourcePath("scripts/lab"), "replay", d, "--no-build", "--out",
                               d + "-replay", "--no-video", "--png-every", "0"},
                              tmp + "/replay.log", 60);
      EXPECT_EQ(rep.rc, 2) << rep.out;
      EXPECT_NE(rep.out.find("config.toml"), std::string::npos) << rep.out;
      std::error_code ec;
      EXPECT_LT(
          fs::exists(d + "-replay/config.toml") ? fs::file_size(d + "-replay/config.toml", ec) : 0,
          1u << 20);
    }
  }
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace rms
