// Sessions as data (docs/sessions.md), the way a user runs them: a recorded
// session re-simulates bit for bit and with another arm fares otherwise,
// explained; it replays through the scene and the renderer to the same ESG
// frames; it exports to CSV and reports to HTML that a browser draws; the
// monitor shows its traffic; a frozen session holds, steps and resumes with
// nothing lost; a checkpoint restores the DCP and a session can start from
// one.
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <sys/stat.h>
#include <thread>

#include "rms/base/config.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/sender_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/message_auth.h"
#include "rms/wire/message_io.h"

#include "lab_processes.h"
#include "session_files.h"
#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::SourcePath;
using testing::Subprocess;

using testing::Script;
using testing::ScriptRun;

// One recorded session (the autopilot, at 4x, small frames, on suffixed
// channels as a station beside others records), shared by the tests that
// only read it.
class RecordedSession : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new std::string(testing::MakeTempDir("recorded"));
    dir_ = new std::string(*tmp_ + "/session");
    const ScriptRun r =
        Script({SourcePath("scripts/lab"), "demo", "--no-build", "--out", *dir_, "--speed", "4",
                "--lcm-url", testing::UniqueLcmUrl(9100), "--channel-suffix", "_BAY2",
                "--png-every", "200", "--width", "160", "--height", "120"},
               *tmp_ + "/lab.log");
    ASSERT_EQ(r.rc, 0) << r.out;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*tmp_);
    delete tmp_;
    delete dir_;
  }
  static std::string* tmp_;
  static std::string* dir_;
};
std::string* RecordedSession::tmp_ = nullptr;
std::string* RecordedSession::dir_ = nullptr;

TEST_F(RecordedSession, TheManifestSaysWhatRanWhereAndWhen) {
  const auto m = nlohmann::json::parse(ReadFile(*dir_ + "/manifest.json"));
  EXPECT_EQ(m["format"], "rmslab-session-1");
  EXPECT_EQ(m["pilot"], "autopilot");
  EXPECT_EQ(m["config"]["file"], "config.toml");
  EXPECT_EQ(m["config"]["sha256"].get<std::string>().size(), 64u);
  EXPECT_NE(m["software"]["version"].get<std::string>().find("rmslab"), std::string::npos);
  // The commit the build was made from: git's HEAD in a git checkout,
  // "unknown" in a tree of files without git (a container's copy).
  std::string head;
  if (FILE* git =
          popen(("git -C '" + SourcePath("") + "' rev-parse HEAD 2>/dev/null").c_str(), "r")) {
    char line[128] = {};
    if (std::fgets(line, sizeof line, git)) head = line;
    if (pclose(git) != 0) head.clear();
  }
  while (!head.empty() && std::isspace(static_cast<unsigned char>(head.back()))) head.pop_back();
  EXPECT_EQ(m["software"]["commit"], head.empty() ? "unknown" : head);
  for (const char* p :
       {"operator_station", "dynamics_proc", "scene_proc", "esg_renderer", "lcm-logger"}) {
    EXPECT_EQ(m["hosts"][p], "localhost") << p;
  }
  EXPECT_GT(m["started_us"].get<std::int64_t>(), 1700000000000000);
  EXPECT_EQ(m["lcm"]["url"].get<std::string>().find("udpm://"), 0u);
}

TEST_F(RecordedSession, ItReSimulatesBitForBit) {
  const ScriptRun r =
      Script({SourcePath("scripts/lab"), "resim", *dir_, "--no-build"}, *tmp_ + "/resim.log");
  EXPECT_EQ(r.rc, 0) << r.out;
  const auto s = nlohmann::json::parse(ReadFile(*dir_ + "/summary.json"));
  const std::string want = std::to_string(s["frames"]["dcp_published"].get<int>()) + " of " +
                           std::to_string(s["frames"]["dcp_published"].get<int>()) +
                           " recorded frames identical, word for word";
  EXPECT_NE(r.out.find(want), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("resim: "), std::string::npos)
      << "progress lines with no terminal to show them";
}

// A session whose manifest is another log's, or whose config.toml is a
// folder: refused, saying why.
TEST_F(RecordedSession, AManifestOfAnotherLogOrAConfigurationThatIsAFolderIsRefusedSayingWhy) {
  const std::string copy = *tmp_ + "/foreign";
  fs::copy(*dir_, copy, fs::copy_options::recursive);
  auto m = nlohmann::json::parse(ReadFile(copy + "/manifest.json"));
  const std::string id = m["session_id"].get<std::string>();
  m["session_id"] = id == "0x0123456789abcdef" ? "0x0123456789abcdee" : "0x0123456789abcdef";
  std::ofstream(copy + "/manifest.json") << m.dump(2);
  ScriptRun r = Script({testing::BuildPath("tools/rms_resim"), copy, "--quiet"}, copy + ".log");
  EXPECT_EQ(r.rc, 2) << r.out;
  EXPECT_NE(r.out.find("no RMS_DCP_FRAME recorded"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("sent by session " + id + ", not the manifest's"), std::string::npos)
      << r.out;
  fs::remove_all(copy);
  fs::copy(*dir_, copy, fs::copy_options::recursive);
  fs::remove(copy + "/config.toml");
  fs::create_directory(copy + "/config.toml");
  r = Script({testing::BuildPath("tools/rms_resim"), copy, "--quiet"}, copy + ".log");
  EXPECT_EQ(r.rc, 2) << r.out;
  EXPECT_NE(r.out.find("config.toml': a folder, not a regular file"), std::string::npos) << r.out;
  fs::remove_all(copy);
}

// rms_resim SESSION with --threads N: its output but the timing line (and the
// wall times: the first line's, the log lines'), the timing line apart.
struct ResimRun {
  int rc = -1;
  std::string result, timing;
};
ResimRun ResimWithThreads(const std::string& session, const std::string& threads,
                          const std::string& log) {
  const ScriptRun r = Script(
      {testing::BuildPath("tools/rms_resim"), session, "--quiet", "--threads", threads}, log);
  ResimRun out{r.rc, "", ""};
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("timing:", 0) == 0)
      out.timing = line;
    else if (line.rfind("re-simulated ", 0) == 0)  // its first line has the wall time
      out.result += line.substr(line.find(';')) + "\n";
    else if (line.rfind("[20", 0) == 0 && line.find("] ") != std::string::npos)
      out.result += line.substr(line.find("] ") + 2) + "\n";  // a log line, its time left out
    else
      out.result += line + "\n";
  }
  return out;
}

// The session copied to `to`, each event of its log passed through `edit`
// (its index among the log's events, the event, whose bytes it may change).
void CopyEditingLog(const std::string& from, const std::string& to,
                    const std::function<void(std::size_t, lcm::LogEvent*)>& edit) {
  fs::copy(from, to, fs::copy_options::recursive);
  lcm::LogFile in(from + "/lcmlog", "r"), out(to + "/lcmlog", "w");
  // The edit sees the message without its tag, and the edited message is
  // tagged again: an insider's edit, which the readers take.
  const int tag = testing::SessionTagsMessages(from) ? wire::kMacBytes : 0;
  std::vector<std::uint8_t> data, tagged;
  std::size_t i = 0;
  while (const lcm::LogEvent* ev = in.readNextEvent()) {
    lcm::LogEvent copy = *ev;
    const auto* d = static_cast<const std::uint8_t*>(ev->data);
    data.assign(d, d + ev->datalen - tag);
    copy.data = data.data();
    copy.datalen = ev->datalen - tag;
    edit(i++, &copy);
    const auto* e = static_cast<const std::uint8_t*>(copy.data);
    tagged.assign(e, e + copy.datalen);
    if (tag) testing::TagAsTheSession(from, copy.channel, &tagged);
    copy.data = tagged.data();
    copy.datalen = static_cast<std::int32_t>(tagged.size());
    out.writeEvent(&copy);
  }
}

// The indices of the log's events on a channel (its base name) that `take`
// takes.
std::vector<std::size_t> EventsOn(
    const std::string& session, const std::string& channel,
    const std::function<bool(const lcm::LogEvent&)>& take = [](const lcm::LogEvent&) {
      return true;
    }) {
  std::vector<std::size_t> at;
  lcm::LogFile in(session + "/lcmlog", "r");
  std::size_t i = 0;
  for (const lcm::LogEvent* ev; (ev = in.readNextEvent()); ++i)
    if (ev->channel.rfind(channel, 0) == 0 && take(*ev)) at.push_back(i);
  return at;
}

// Copies the LCM log FROM to TO without the events `drop` says yes to
// (given the channel and the frame number the message carries, -1 if none).
void CopyLogDropping(const std::string& from, const std::string& to,
                     const std::function<bool(const std::string&, std::int64_t)>& drop) {
  lcm::LogFile in(from, "r"), out(to, "w");
  while (const lcm::LogEvent* ev = in.readNextEvent()) {
    std::int64_t frame = -1;
    wire::ReadFrameNumber(ev->data, static_cast<int>(ev->datalen), &frame);
    if (!drop(ev->channel, frame)) out.writeEvent(const_cast<lcm::LogEvent*>(ev));
  }
}

// The DCP frame each periodic RMS_DCP_STATE of a log was logged for (its
// next_frame), in log order.
std::vector<std::int64_t> PeriodicStateFrames(const std::string& log) {
  std::vector<std::int64_t> frames;
  lcm::LogFile in(log, "r");
  while (const lcm::LogEvent* ev = in.readNextEvent()) {
    dcp_state_t m;
    if (ev->channel.rfind("RMS_DCP_STATE", 0) == 0 &&
        m.decode(ev->data, 0, static_cast<int>(ev->datalen)) > 0 &&
        m.reason == dcp_state_t::PERIODIC)
      frames.push_back(m.next_frame);
  }
  return frames;
}

bool IsDcpFrameOrTelemetry(const std::string& channel) {
  return channel.rfind("RMS_DCP_FRAME", 0) == 0 || channel.rfind("RMS_DCP_TELEMETRY", 0) == 0;
}

// The first of the log's periodic states, from the third on, around which
// the recording is whole for `margin` DCP frames either side: every DCP
// frame there, each answering the operator frame of its number (less one
// constant), and every one of those operator frames logged. (The recording
// was made on a loaded machine: a frame the session itself lost, or an
// input the DCP dropped as too late, next to a stretch the test cuts would
// change what the stretch is.) -1 when none is.
std::int64_t WholePeriodicState(const std::string& dir, std::int64_t margin) {
  const int tag = testing::SessionTagsMessages(dir) ? wire::kMacBytes : 0;
  std::map<std::int64_t, std::int64_t> answered;  // DCP frame -> the operator frame it answered
  std::set<std::int64_t> inputs;
  {
    lcm::LogFile in(dir + "/lcmlog", "r");
    while (const lcm::LogEvent* ev = in.readNextEvent()) {
      dcp_frame_t d;
      std::int64_t f = -1;
      if (ev->channel.rfind("RMS_DCP_FRAME", 0) == 0 &&
          wire::SafeDecode(ev->data, static_cast<int>(ev->datalen) - tag, &d) ==
              wire::DecodeError::kNone)
        answered[d.frame] = d.input_frame;
      else if (ev->channel.rfind("RMS_OPERATOR_INPUT", 0) == 0 &&
               wire::ReadFrameNumber(ev->data, static_cast<int>(ev->datalen), &f))
        inputs.insert(f);
    }
  }
  const std::vector<std::int64_t> periodic = PeriodicStateFrames(dir + "/lcmlog");
  for (std::size_t k = 2; k < periodic.size(); ++k) {
    const std::int64_t n = periodic[k];
    const auto at_n = answered.find(n);
    bool whole = at_n != answered.end();
    const std::int64_t offset = whole ? at_n->second - n : 0;
    for (std::int64_t f = n - margin; f <= n + margin && whole; ++f) {
      const auto it = answered.find(f);
      whole = it != answered.end() && it->second - f == offset && inputs.count(it->second) > 0;
    }
    if (whole) return n;
  }
  return -1;
}

// docs/sessions.md "Through what is lost": DCP frames 400..429 gone from the
// log, and ten of the operator frames they answered: which inputs the DCP
// answered there cannot be told. The re-simulation goes on from the next
// logged state, names the frames it could not check, and is exact for the
// rest.
TEST_F(RecordedSession, FramesLostFromEverySourceAreNamedAndTheRestCheckedWordForWord) {
  const std::string cut = *tmp_ + "/lost_frames";
  fs::copy(*dir_, cut, fs::copy_options::recursive);
  CopyLogDropping(*dir_ + "/lcmlog", cut + "/lcmlog", [](const std::string& ch, std::int64_t f) {
    const bool input = ch.rfind("RMS_OPERATOR_INPUT", 0) == 0;
    return (IsDcpFrameOrTelemetry(ch) && f >= 400 && f < 430) || (input && f >= 410 && f < 420);
  });
  const std::string verdict = *tmp_ + "/lost_frames.json";
  const ScriptRun r =
      Script({testing::BuildPath("tools/rms_resim"), cut, "--verdict-json", verdict},
             *tmp_ + "/lost_frames.log");
  EXPECT_EQ(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("not checked: before them, DCP frames 400..429"), std::string::npos)
      << r.out;
  const auto v = nlohmann::json::parse(ReadFile(verdict));
  EXPECT_EQ(v["verdict"], "identical") << v.dump(2);
  EXPECT_FALSE(v["exact"].get<bool>());
  ASSERT_EQ(v["unchecked"].size(), 1u) << v.dump(2);
  const auto& u = v["unchecked"][0];
  EXPECT_EQ(u["lost_from"], 400);
  EXPECT_EQ(u["lost_to"], 429);
  EXPECT_EQ(u["unchecked_from"], 430);
  // Up to the next periodic state (every 5 s of frames: 150 at 30 Hz).
  EXPECT_GT(u["unchecked_frames"].get<long>(), 0);
  EXPECT_LE(u["unchecked_frames"].get<long>(), 150);
  EXPECT_EQ(u["resumed_at"].get<long>(), 430 + u["unchecked_frames"].get<long>());
  const long recorded =
      nlohmann::json::parse(ReadFile(*dir_ + "/summary.json"))["log"]["dcp_frames"];
  EXPECT_EQ(v["frames_compared"].get<long>() + v["frames_unchecked"].get<long>() + 30, recorded)
      << v.dump(2);
  EXPECT_EQ(v["frames_identical"], v["frames_compared"]);
}

// 200 DCP frames lost from every source around a periodic state, which the
// log still holds: the stretch before the state cannot be told, the one
// after it is made again from the logged inputs (no recorded frame left
// unchecked), or, where inputs after the state are lost too, is one
// stretch from the first lost frame on -- never two that overlap.
TEST_F(RecordedSession, AStateLoggedAmongLostFramesIsGoneOnFromAndTheStretchIsOne) {
  const std::int64_t n = WholePeriodicState(*dir_, 120);
  ASSERT_GT(n, 0) << "no periodic state with 120 whole DCP frames either side in the recording";
  const std::int64_t lost_from = n - 100, lost_to = n + 100;
  for (const bool after_too : {false, true}) {
    const std::string cut = *tmp_ + "/lost_around_state" + (after_too ? "_after" : "");
    fs::copy(*dir_, cut, fs::copy_options::recursive);
    CopyLogDropping(*dir_ + "/lcmlog", cut + "/lcmlog", [&](const std::string& ch, std::int64_t f) {
      const bool input = ch.rfind("RMS_OPERATOR_INPUT", 0) == 0;
      return (IsDcpFrameOrTelemetry(ch) && f >= lost_from && f <= lost_to) ||
             (input && f >= n - 50 && f < n - 40) ||
             (input && after_too && f >= n + 50 && f < n + 55);
    });
    const std::string verdict = cut + ".json";
    const ScriptRun r = Script(
        {testing::BuildPath("tools/rms_resim"), cut, "--verdict-json", verdict}, cut + ".log");
    EXPECT_EQ(r.rc, 0) << r.out;
    const auto v = nlohmann::json::parse(ReadFile(verdict));
    EXPECT_EQ(v["verdict"], "identical") << v.dump(2);
    ASSERT_EQ(v["unchecked"].size(), 1u) << "state for DCP frame " << n << ": " << v.dump(2);
    const auto& u = v["unchecked"][0];
    EXPECT_EQ(u["lost_from"], lost_from) << u.dump();
    EXPECT_EQ(u["lost_to"], lost_to) << u.dump();
    // The DCP's own receive warning does not say the gap again, otherwise.
    EXPECT_EQ(r.out.find("gap:"), std::string::npos) << r.out;
    if (!after_too) {
      // Made again from the logged inputs, with nothing to check them
      // against: said, and not exact.
      EXPECT_EQ(v["frames_filled_in"], lost_to - n + 1) << v.dump(2);
      EXPECT_FALSE(v["exact"].get<bool>());
      EXPECT_NE(r.out.find("made again from the logged inputs they answered"), std::string::npos)
          << r.out;
      EXPECT_FALSE(u.contains("unchecked_frames")) << u.dump();
      EXPECT_EQ(u["resumed_from_state"], n) << u.dump();
      EXPECT_EQ(u["resumed_at"], lost_to + 1) << u.dump();
      EXPECT_NE(r.out.find("no recorded frame left unchecked: re-simulated again from the state "
                           "logged for DCP frame " +
                           std::to_string(n)),
                std::string::npos)
          << r.out;
    } else {
      EXPECT_EQ(u["unchecked_from"], lost_to + 1) << u.dump();
      EXPECT_GT(u["resumed_from_state"].get<std::int64_t>(), lost_to) << u.dump();
      EXPECT_EQ(u["resumed_at"], u["resumed_from_state"]) << u.dump();
    }
    EXPECT_EQ(r.out.find("note: before them"), std::string::npos) << r.out;
  }
  // Two stretches, the state in the second: the run goes on from the state
  // and still cannot follow on, so both are one stretch from the first
  // lost frame, not two that overlap or leave frames between them unnamed.
  const std::string two = *tmp_ + "/lost_twice_around_state";
  fs::copy(*dir_, two, fs::copy_options::recursive);
  CopyLogDropping(*dir_ + "/lcmlog", two + "/lcmlog", [&](const std::string& ch, std::int64_t f) {
    const bool lost = (f >= n - 70 && f <= n - 40) || (f >= n - 30 && f <= n + 40);
    return (IsDcpFrameOrTelemetry(ch) || ch.rfind("RMS_OPERATOR_INPUT", 0) == 0) && lost;
  });
  const ScriptRun r2 = Script(
      {testing::BuildPath("tools/rms_resim"), two, "--verdict-json", two + ".json"}, two + ".log");
  EXPECT_EQ(r2.rc, 0) << r2.out;
  const auto v2 = nlohmann::json::parse(ReadFile(two + ".json"));
  ASSERT_EQ(v2["unchecked"].size(), 1u) << v2.dump(2);
  const auto& u2 = v2["unchecked"][0];
  EXPECT_EQ(u2["lost_from"], n - 70) << u2.dump();
  EXPECT_EQ(u2["lost_to"], n + 40) << u2.dump();
  EXPECT_EQ(u2["unchecked_from"], n - 39) << u2.dump();
  EXPECT_GT(u2["resumed_at"].get<std::int64_t>(), n + 40) << u2.dump();
  EXPECT_EQ(u2["resumed_at"], u2["resumed_from_state"]) << u2.dump();
}

// The DCP frame just before each periodic state lost from every source:
// one input fits each gap, so each is filled in, and each state is checked
// after the frame filled in before it, not before it (that read as "the
// DCP's state before DCP frame 1050 differs"): word for word, no frame
// left unchecked.
TEST_F(RecordedSession, AFrameLostJustBeforeAPeriodicStateIsFilledInBeforeTheCheck) {
  const std::string cut = *tmp_ + "/lost_before_states";
  fs::copy(*dir_, cut, fs::copy_options::recursive);
  std::set<std::int64_t> before_states;
  for (const std::int64_t next : PeriodicStateFrames(*dir_ + "/lcmlog"))
    before_states.insert(next - 1);
  ASSERT_GE(before_states.size(), 5u);
  CopyLogDropping(*dir_ + "/lcmlog", cut + "/lcmlog", [&](const std::string& ch, std::int64_t f) {
    return IsDcpFrameOrTelemetry(ch) && before_states.count(f) > 0;
  });
  const std::string verdict = *tmp_ + "/lost_before_states.json";
  const ScriptRun r =
      Script({testing::BuildPath("tools/rms_resim"), cut, "--verdict-json", verdict},
             *tmp_ + "/lost_before_states.log");
  EXPECT_EQ(r.rc, 0) << r.out;
  const auto v = nlohmann::json::parse(ReadFile(verdict));
  EXPECT_EQ(v["verdict"], "identical") << v.dump(2);
  EXPECT_EQ(v["unchecked"].size(), 0u) << v.dump(2);
  EXPECT_EQ(v["frames_identical"], v["frames_compared"]);
}

// A log damaged inside (docs/sessions.md "A damaged log"): an event's sync
// word overwritten half way, and 4 KiB of garbage put in a third of the
// way. Every tool reads past both: the summary still sees the docking at
// the end, counts the bytes it skipped, says so, and exits 3 (written, not
// to be stood behind); the re-simulation is identical where the log is
// whole but not exact, and the brief says NOT EXACT.
TEST_F(RecordedSession, ALogDamagedInsideIsReadPastSaidAndNotExact) {
  const std::string cut = *tmp_ + "/damaged_inside";
  fs::copy(*dir_, cut, fs::copy_options::recursive);
  std::size_t garbage_at = 0;
  {
    std::string bytes = ReadFile(cut + "/lcmlog");
    const std::string sync("\xED\xA1\xDA\x01", 4);
    const auto at = bytes.find(sync, bytes.size() / 2);
    ASSERT_NE(at, std::string::npos);
    bytes[at] = 0;
    garbage_at = bytes.find(sync, bytes.size() / 3);
    ASSERT_NE(garbage_at, std::string::npos);
    std::mt19937 rng(34);  // seed 34: the garbage's bytes
    std::printf("garbage seed 34, at byte %zu\n", garbage_at);
    std::string garbage(4096, '\0');
    for (char& c : garbage) c = static_cast<char>(rng() & 0xff);
    bytes.insert(garbage_at, garbage);
    std::ofstream(cut + "/lcmlog", std::ios::binary) << bytes;
  }
  const ScriptRun sum = Script({testing::BuildPath("tools/rms_session"), "summary", cut, "--brief"},
                               *tmp_ + "/damaged_inside_summary.log");
  EXPECT_EQ(sum.rc, 3) << sum.out;
  EXPECT_NE(sum.out.find("THE LOG IS DAMAGED"), std::string::npos) << sum.out;
  const auto whole = nlohmann::json::parse(ReadFile(*dir_ + "/summary.json"));
  const auto j = nlohmann::json::parse(ReadFile(cut + "/summary.json"));
  EXPECT_TRUE(j["docked"].get<bool>()) << "the docking after the damage is read";
  EXPECT_GE(j["log"]["skipped_bytes"].get<std::int64_t>(), 4096);
  EXPECT_EQ(j["log"]["skipped_places"], 2) << j["log"].dump();
  EXPECT_EQ(j["log"]["skipped_stretches"][0]["from_byte"].get<std::size_t>(), garbage_at);
  EXPECT_EQ(j["log"]["unread_bytes"], 0);
  // Only the event whose sync word was overwritten is lost.
  EXPECT_EQ(j["log"]["events"].get<std::int64_t>(), whole["log"]["events"].get<std::int64_t>() - 1);
  const ScriptRun r = Script(
      {testing::BuildPath("tools/rms_resim"), cut, "--verdict-json", cut + "/resimulation.json"},
      *tmp_ + "/damaged_inside.log");
  const auto v = nlohmann::json::parse(ReadFile(cut + "/resimulation.json"));
  EXPECT_FALSE(v["exact"].get<bool>()) << v.dump(2);
  EXPECT_NE(v["log_note"].get<std::string>().find("the log is damaged"), std::string::npos)
      << v.dump(2);
  const ScriptRun brief =
      Script({testing::BuildPath("tools/rms_session"), "summary", cut, "--brief"},
             *tmp_ + "/damaged_inside_brief.log");
  EXPECT_NE(brief.out.find("NOT EXACT: the log is damaged"), std::string::npos) << brief.out;
  // Bytes written over in place (the log's size unchanged): the verdict on
  // file judged the log before, and says so.
  {
    std::string bytes = ReadFile(cut + "/lcmlog");
    for (std::size_t i = bytes.size() / 4; i < bytes.size() / 4 + 64; ++i) bytes[i] ^= 0x5a;
    std::ofstream(cut + "/lcmlog", std::ios::binary) << bytes;
  }
  const ScriptRun over =
      Script({testing::BuildPath("tools/rms_session"), "summary", cut, "--brief"},
             *tmp_ + "/damaged_over_brief.log");
  EXPECT_NE(over.out.find("re-simulates: NOT KNOWN -- the verdict on file is of another log"),
            std::string::npos)
      << over.out;
  // Nothing but garbage: no event at all, said, exit 3.
  {
    std::mt19937 rng(35);  // seed 35
    std::string garbage(200000, '\0');
    for (char& c : garbage) c = static_cast<char>(rng() & 0xff);
    std::ofstream(cut + "/lcmlog", std::ios::binary) << garbage;
  }
  const ScriptRun none =
      Script({testing::BuildPath("tools/rms_session"), "summary", cut, "--brief"},
             *tmp_ + "/damaged_all_brief.log");
  EXPECT_EQ(none.rc, 3) << none.out;
  EXPECT_NE(none.out.find("no event at all"), std::string::npos) << none.out;
  // The verdict on file judged the log before: not shown as this one's.
  EXPECT_NE(none.out.find("re-simulates: NOT KNOWN -- the verdict on file is of another log"),
            std::string::npos)
      << none.out;
  EXPECT_EQ(none.out.find("re-simulates: identical"), std::string::npos) << none.out;
}

// The record remade from journals one of which is damaged half way (the
// DCP's: a sync word overwritten) and a network's record that missed the
// DCP's frames from 1000 on: what neither holds is a loss of the record,
// held against the DCP's own count, not none; the journal is named.
TEST_F(RecordedSession, ADamagedJournalIsALossOfTheRecordNotNone) {
  const std::string s = *tmp_ + "/damaged_journal";
  fs::copy(*dir_, s, fs::copy_options::recursive);
  fs::create_directories(s + "/journal");
  {
    lcm::LogFile in(*dir_ + "/lcmlog", "r");
    lcm::LogFile op(s + "/journal/operator_station.0.lcmlog", "w"),
        dcp(s + "/journal/dynamics_proc.0.lcmlog", "w"),
        scene(s + "/journal/scene_proc.0.lcmlog", "w");
    while (const lcm::LogEvent* ev = in.readNextEvent()) {
      auto* e = const_cast<lcm::LogEvent*>(ev);
      if (ev->channel.rfind("RMS_OPERATOR_INPUT", 0) == 0) op.writeEvent(e);
      if (ev->channel.rfind("RMS_DCP_", 0) == 0) dcp.writeEvent(e);
      if (ev->channel.rfind("RMS_ESG_FRAME", 0) == 0) scene.writeEvent(e);
    }
  }
  {
    // A DCP frame's event three quarters of the way: past frame 1000, which
    // the network's recorder missed (its channel follows the sync word and
    // the 24 bytes of the event's header).
    const std::string path = s + "/journal/dynamics_proc.0.lcmlog";
    std::string bytes = ReadFile(path);
    const std::string sync("\xED\xA1\xDA\x01", 4);
    auto at = bytes.find(sync, bytes.size() * 3 / 4);
    while (at != std::string::npos && bytes.compare(at + 28, 13, "RMS_DCP_FRAME") != 0)
      at = bytes.find(sync, at + 1);
    ASSERT_NE(at, std::string::npos);
    bytes[at] = 0;
    std::ofstream(path, std::ios::binary) << bytes;
  }
  // The network's recorder missed the DCP's frames from 1000 on.
  CopyLogDropping(*dir_ + "/lcmlog", s + "/wire.lcmlog", [](const std::string& ch, std::int64_t f) {
    return ch.rfind("RMS_DCP_FRAME", 0) == 0 && f >= 1000;
  });
  fs::remove(s + "/lcmlog");
  fs::remove(s + "/record.json");
  const std::string tools = testing::BuildPath("tools/rms_session");
  ASSERT_EQ(Script({tools, "record", s}, *tmp_ + "/damaged_journal_record.log").rc, 0);
  ASSERT_EQ(Script({tools, "summary", s}, *tmp_ + "/damaged_journal_summary.log").rc, 0);
  const auto r = nlohmann::json::parse(ReadFile(s + "/summary.json"))["record"];
  const auto stats = nlohmann::json::parse(ReadFile(s + "/stats/dynamics_proc.json"));
  EXPECT_EQ(r["journals_damaged"].size(), 1u) << r.dump(2);
  EXPECT_EQ(r["by_channel"]["RMS_DCP_FRAME"]["published"], stats["counters"]["published"])
      << r.dump(2);
  // The damaged DCP frame, read past, and its telemetry with it (believed only
  // with its frame: docs/security.md "What the summary trusts").
  EXPECT_EQ(r["lost"].get<long>(), 2) << r.dump(2);
  // The brief says what the record lacks, and that the re-simulation's
  // "identical" is of what it holds: not exact.
  // (A verdict of this record, not the session's original log: that one
  // would be shown as another log's.)
  Script({testing::BuildPath("tools/rms_resim"), s, "--quiet", "--verdict-json",
          s + "/resimulation.json"},
         *tmp_ + "/damaged_journal_resim.log");
  const ScriptRun brief =
      Script({tools, "summary", s, "--brief"}, *tmp_ + "/damaged_journal_brief.log");
  EXPECT_NE(brief.out.find("the record lacks " + std::to_string(r["lost"].get<long>())),
            std::string::npos)
      << brief.out;
  EXPECT_NE(brief.out.find("NOT EXACT: the record lacks"), std::string::npos) << brief.out;
  EXPECT_NE(brief.out.find("the record has what the network's recorder heard"), std::string::npos)
      << brief.out;
  // Without the network's recording, nothing is said to come from it.
  fs::remove(s + "/wire.lcmlog");
  fs::remove(s + "/lcmlog");
  fs::remove(s + "/record.json");
  ASSERT_EQ(Script({tools, "record", s}, *tmp_ + "/damaged_journal_record2.log").rc, 0);
  const ScriptRun alone =
      Script({tools, "summary", s, "--brief"}, *tmp_ + "/damaged_journal_brief2.log");
  const auto r2 = nlohmann::json::parse(ReadFile(s + "/summary.json"))["record"];
  EXPECT_FALSE(r2["network"]["present"].get<bool>()) << r2.dump(2);
  EXPECT_EQ(r2["network"]["missed"], 0) << r2.dump(2);
  EXPECT_NE(alone.out.find("no network recording (wire.lcmlog)"), std::string::npos) << alone.out;
  EXPECT_NE(alone.out.find("what the damage held is in no record"), std::string::npos) << alone.out;
  EXPECT_EQ(alone.out.find("the network's recorder missed"), std::string::npos) << alone.out;
}

// A log made from the wire alone, where the network delivered each logged
// state twice, its second copy heard after three more DCP frames, and the
// DCP frame before each state twice, its second copy heard after the state:
// each copy is the first one's, not a message logged there, and it
// re-simulates word for word (docs/sessions.md "The record").
TEST_F(RecordedSession, AMessageTheWireDeliveredTwiceLaterIsTheFirstOnes) {
  const std::string twice = *tmp_ + "/states_twice";
  fs::copy(*dir_, twice, fs::copy_options::recursive);
  int copies = 0;
  {
    lcm::LogFile in(*dir_ + "/lcmlog", "r"), out(twice + "/lcmlog", "w");
    struct Held {
      lcm::LogEvent ev;
      std::vector<std::uint8_t> data;
      std::string channel;
      int frames_to_go = 3;
    };
    std::vector<Held> held;
    std::optional<Held> last_frame;
    while (const lcm::LogEvent* ev = in.readNextEvent()) {
      out.writeEvent(const_cast<lcm::LogEvent*>(ev));
      const auto* d = static_cast<const std::uint8_t*>(ev->data);
      if (ev->channel.rfind("RMS_DCP_STATE", 0) == 0) {
        held.push_back({*ev, {d, d + ev->datalen}, ev->channel, 3});
        if (last_frame) {
          last_frame->ev.data = last_frame->data.data();
          last_frame->ev.channel = last_frame->channel;
          last_frame->ev.timestamp = ev->timestamp;
          out.writeEvent(&last_frame->ev);
          last_frame.reset();
        }
      } else if (ev->channel.rfind("RMS_DCP_FRAME", 0) == 0) {
        last_frame = Held{*ev, {d, d + ev->datalen}, ev->channel, 0};
        for (Held& h : held) {
          if (--h.frames_to_go != 0) continue;
          h.ev.data = h.data.data();
          h.ev.channel = h.channel;
          h.ev.timestamp = ev->timestamp;
          out.writeEvent(&h.ev);
          ++copies;
        }
        std::erase_if(held, [](const Held& h) { return h.frames_to_go <= 0; });
      }
    }
  }
  ASSERT_GT(copies, 3);
  const ResimRun one = ResimWithThreads(twice, "1", twice + "-1.log");
  EXPECT_EQ(one.rc, 0) << one.result;
  EXPECT_NE(one.result.find("identical, word for word"), std::string::npos) << one.result;
  const ResimRun two = ResimWithThreads(twice, "2", twice + "-2.log");
  EXPECT_EQ(two.result, one.result);
}

// Re-simulated on two cores (the log read in two parts, the DCP run in two
// halves at once: docs/sessions.md "Re-simulation") it says what it says on
// one, to the word.
TEST_F(RecordedSession, ReSimulatesTheSameOnTwoCoresAsOnOne) {
  const ResimRun one = ResimWithThreads(*dir_, "1", *tmp_ + "/resim1.log");
  const ResimRun two = ResimWithThreads(*dir_, "2", *tmp_ + "/resim2.log");
  EXPECT_EQ(one.rc, 0) << one.result;
  EXPECT_EQ(two.rc, 0) << two.result;
  EXPECT_EQ(two.result, one.result);
  EXPECT_NE(one.result.find("identical, word for word"), std::string::npos) << one.result;
  EXPECT_NE(two.timing.find("reading the log in two parts at once"), std::string::npos)
      << two.timing;
  EXPECT_NE(two.timing.find("running the DCP in two halves at once"), std::string::npos)
      << two.timing;
  EXPECT_EQ(one.timing.find("at once"), std::string::npos) << one.timing;
}

// A recorded output changed in either half, or a logged state changed, is
// found where one thread finds it; a send time changed everywhere is no
// difference (compared byte for byte but the sender and the send time).
TEST_F(RecordedSession, ADifferenceInEitherHalfIsFoundWhereOneThreadFindsIt) {
  const std::vector<std::size_t> frames = EventsOn(*dir_, "RMS_DCP_FRAME");
  const std::vector<std::size_t> telemetry = EventsOn(*dir_, "RMS_DCP_TELEMETRY");
  const std::vector<std::size_t> states =
      EventsOn(*dir_, "RMS_DCP_STATE", [](const lcm::LogEvent& ev) {
        dcp_state_t m;
        return m.decode(ev.data, 0, ev.datalen) > 0 && m.reason == dcp_state_t::PERIODIC;
      });
  ASSERT_GT(frames.size(), 1000u);
  ASSERT_GT(states.size(), 4u);  // periodic ones, every 5 s of the mission's minute
  const std::size_t early_frame = frames[frames.size() / 4];
  const std::size_t late_telemetry = telemetry[telemetry.size() * 3 / 4];
  const std::size_t middle_state = states[states.size() / 2];
  // The first operator frame after each periodic state: where the second
  // half may begin.
  std::vector<std::int64_t> after_states;
  {
    lcm::LogFile in(*dir_ + "/lcmlog", "r");
    std::size_t i = 0;
    for (const lcm::LogEvent* ev; (ev = in.readNextEvent()); ++i) {
      dcp_state_t m;
      if (std::binary_search(states.begin(), states.end(), i) &&
          m.decode(ev->data, 0, ev->datalen) > 0)
        after_states.push_back(m.input_frame + 1);
    }
  }
  ASSERT_EQ(after_states.size(), states.size());
  struct Case {
    std::string name;
    std::function<void(std::size_t, lcm::LogEvent*)> edit;
    std::string says;  // "" for identical
  };
  auto byte_at = [](lcm::LogEvent* ev, int at) -> std::uint8_t& {
    return static_cast<std::uint8_t*>(ev->data)[at];
  };
  std::vector<Case> cases = {
      {"an arm word early",
       [&](std::size_t i, lcm::LogEvent* ev) {
         if (i == early_frame) byte_at(ev, wire::kDcpFrameInputFrameAt + 16 + 3) ^= 1;
       },
       ": arm_words[0]"},
      {"telemetry late",
       [&](std::size_t i, lcm::LogEvent* ev) {
         if (i == late_telemetry) byte_at(ev, ev->datalen - 1) ^= 1;
       },
       ": telemetry"},
      {"the middle state",
       [&](std::size_t i, lcm::LogEvent* ev) {
         if (i != middle_state) return;
         dcp_state_t m;
         ASSERT_GT(m.decode(ev->data, 0, ev->datalen), 0);
         const std::size_t dcp = m.checkpoint.find("\"dcp\"");
         const std::size_t digit = m.checkpoint.find_first_of("123456789", dcp);
         ASSERT_NE(digit, std::string::npos);
         m.checkpoint[digit] = m.checkpoint[digit] == '9' ? '1' : m.checkpoint[digit] + 1;
         static std::vector<std::uint8_t> encoded;
         encoded = wire::EncodeMessage(m);
         ev->data = encoded.data();
         ev->datalen = static_cast<std::int32_t>(encoded.size());
       },
       "differs from the state it logged there"},
      {"every send time",
       [&](std::size_t, lcm::LogEvent* ev) {
         if (ev->channel.rfind("RMS_DCP_FRAME", 0) == 0 ||
             ev->channel.rfind("RMS_DCP_TELEMETRY", 0) == 0)
           byte_at(ev, wire::kSendTimeAt + 7) ^= 0x55;
       },
       ""},
  };
  // Operator frames numbered 2^21 further on from one periodic state on (the
  // DCP frames' and the telemetry's input_frame with them), a copy for each
  // state: one run refuses them as far ahead of the last, so a second half
  // started there must not take them (it begins with no last).
  for (const std::int64_t from : after_states) {
    cases.push_back({"inputs far ahead from operator frame " + std::to_string(from),
                     [&, from](std::size_t, lcm::LogEvent* ev) {
                       const bool input = ev->channel.rfind("RMS_OPERATOR_INPUT", 0) == 0;
                       if (!input && ev->channel.rfind("RMS_DCP_FRAME", 0) != 0 &&
                           ev->channel.rfind("RMS_DCP_TELEMETRY", 0) != 0)
                         return;
                       // Both outputs carry input_frame where RMS_DCP_FRAME does.
                       const int at = input ? wire::kFrameAt : wire::kDcpFrameInputFrameAt;
                       std::int64_t f = 0;
                       ASSERT_TRUE(wire::ReadInt64At(ev->data, ev->datalen, at, &f));
                       if (f < from) return;
                       const auto moved = static_cast<std::uint64_t>(f + (std::int64_t{1} << 21));
                       for (int b = 0; b < 8; ++b)
                         byte_at(ev, at + b) = static_cast<std::uint8_t>(moved >> (56 - 8 * b));
                     },
                     "first difference: DCP frame"});
  }
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string copy = *tmp_ + "/edited-" + std::to_string(&c - cases.data());
    CopyEditingLog(*dir_, copy, c.edit);
    const ResimRun one = ResimWithThreads(copy, "1", copy + "-1.log");
    const ResimRun two = ResimWithThreads(copy, "2", copy + "-2.log");
    EXPECT_EQ(two.result, one.result);
    EXPECT_EQ(two.rc, one.rc);
    if (c.says.empty()) {
      EXPECT_EQ(one.rc, 0) << one.result;
      EXPECT_NE(one.result.find("identical, word for word"), std::string::npos) << one.result;
    } else {
      EXPECT_EQ(one.rc, 1) << one.result;
      EXPECT_NE(one.result.find("first difference: "), std::string::npos) << one.result;
      EXPECT_NE(one.result.find(c.says), std::string::npos) << one.result;
    }
  }
}

TEST_F(RecordedSession, ALongerArmFaresOtherwiseAndTheComparisonSaysWhy) {
  // The same operator inputs with the upper boom a foot longer: the end
  // effector arrives elsewhere, the grasp fails, nothing docks.
  std::string cfg = ReadFile(*dir_ + "/config.toml");
  const std::string from = "upper_boom_ft = 20.9";
  ASSERT_NE(cfg.find(from), std::string::npos);
  cfg.replace(cfg.find(from), from.size(), "upper_boom_ft = 21.9");
  const std::string long_arm = *tmp_ + "/long_arm.toml";
  std::ofstream(long_arm) << cfg;
  const std::string out = *tmp_ + "/long_arm_session";
  const ScriptRun r = Script(
      {SourcePath("scripts/lab"), "resim", *dir_, "--no-build", "--config", long_arm, "--out", out},
      *tmp_ + "/resim_long.log");
  ASSERT_EQ(r.rc, 0) << r.out;
  const auto summary = nlohmann::json::parse(ReadFile(out + "/summary.json"));
  EXPECT_FALSE(summary["docked"].get<bool>());
  EXPECT_FALSE(summary["acquired"].get<bool>());
  const auto c = nlohmann::json::parse(ReadFile(out + "/comparison.json"));
  ASSERT_EQ(c["config_changes"].size(), 1u) << c["config_changes"].dump();
  EXPECT_EQ(c["config_changes"][0]["key"], "arm.upper_boom_ft");
  EXPECT_FALSE(c["recorded"]["docked"].is_null());
  EXPECT_TRUE(c["resimulated"]["docked"].is_null());
  EXPECT_GT(c["point_A"]["max_apart_ft"].get<double>(), 0.5);
  std::string why;
  for (const auto& line : c["explanation"]) why += line.get<std::string>() + "\n";
  EXPECT_NE(why.find("No acquisition"), std::string::npos) << why;
  EXPECT_NE(why.find("TPOB"), std::string::npos) << why;  // the palm did not come down onto the bar
  EXPECT_NE(why.find("No docking"), std::string::npos) << why;
  EXPECT_NE(ReadFile(out + "/comparison.md").find("arm.upper_boom_ft"), std::string::npos);
}

// docs/sessions.md "Re-simulation": --set as the README gives it, on a
// suffixed session and on its own re-simulation; a design out of bounds is
// refused naming the key; a re-simulation that fails leaves nothing behind.
TEST_F(RecordedSession, ResimSetWorksOnItAndOnItsReSimulationAndAFailureLeavesNothing) {
  const std::string lab = SourcePath("scripts/lab");
  const std::string first = *tmp_ + "/tpob", second = *tmp_ + "/tpob_boom";
  const ScriptRun a =
      Script({lab, "resim", *dir_, "--no-build", "--set", "dcp.tpob_ft=0.4", "--out", first},
             *tmp_ + "/set.log");
  ASSERT_EQ(a.rc, 0) << a.out;
  const auto s = nlohmann::json::parse(ReadFile(first + "/summary.json"));
  EXPECT_TRUE(s["docked"].get<bool>()) << "a slacker TPOB changes nothing the autopilot did";
  EXPECT_EQ(s["result_attempt"], 1) << s.dump(2);
  const auto m = nlohmann::json::parse(ReadFile(first + "/manifest.json"));
  EXPECT_EQ(m["lcm"]["channel_suffix"], "_BAY2");
  EXPECT_EQ(m["pilot"], "re-simulation");
  {  // its config.toml's SHA-256, as a live session's manifest has it
    const ScriptRun sum =
        Script({"/usr/bin/sha256sum", first + "/config.toml"}, *tmp_ + "/sha.log");
    EXPECT_EQ(sum.out.substr(0, 64), m["config"]["sha256"].get<std::string>()) << m.dump(2);
  }
  // The new session says whether it re-simulates, as every session does,
  // and its wall times count from its own log's start, not from 1970.
  EXPECT_EQ(s["resimulation"]["verdict"], "identical") << s["resimulation"].dump();
  EXPECT_TRUE(s["resimulation"]["exact"].get<bool>()) << s["resimulation"].dump();
  EXPECT_NE(a.out.find("the new session re-simulates: identical"), std::string::npos) << a.out;
  EXPECT_LT(s["wall_duration_s"].get<double>(), 3600) << s.dump(2);
  // A re-simulation of the re-simulation, with another key set.
  const ScriptRun b = Script(
      {lab, "resim", first, "--no-build", "--set", "arm.upper_boom_ft=21.5", "--out", second},
      *tmp_ + "/set2.log");
  ASSERT_EQ(b.rc, 0) << b.out;
  const auto c = nlohmann::json::parse(ReadFile(second + "/comparison.json"));
  EXPECT_EQ(c["config_changes"].size(), 1u) << c["config_changes"].dump();
  EXPECT_EQ(Script({lab, "resim", first, "--no-build"}, *tmp_ + "/own.log").rc, 0);
  // A folder that holds a session -- the first re-simulation, or the
  // recorded session itself -- is refused, and keeps every file it had.
  for (const std::string& held : {first, *dir_}) {
    std::vector<std::string> had;
    for (const auto& e : fs::recursive_directory_iterator(held)) had.push_back(e.path().string());
    std::sort(had.begin(), had.end());
    const ScriptRun again =
        Script({lab, "resim", *dir_, "--no-build", "--set", "dcp.tpob_ft=0.5", "--out", held},
               *tmp_ + "/again.log");
    EXPECT_EQ(again.rc, 2) << again.out;
    EXPECT_NE(again.out.find("already holds a session"), std::string::npos) << again.out;
    std::vector<std::string> has;
    for (const auto& e : fs::recursive_directory_iterator(held)) has.push_back(e.path().string());
    std::sort(has.begin(), has.end());
    EXPECT_EQ(has, had) << "a refused re-simulation removed files of " << held;
  }
  // Out of bounds: refused before anything is made.
  const ScriptRun far = Script({lab, "resim", *dir_, "--no-build", "--set",
                                "arm.upper_boom_ft=9000", "--out", *tmp_ + "/far"},
                               *tmp_ + "/far.log");
  EXPECT_EQ(far.rc, 2) << far.out;
  EXPECT_NE(far.out.find("arm.upper_boom_ft"), std::string::npos) << far.out;
  EXPECT_NE(far.out.find("<= 100"), std::string::npos) << far.out;
  EXPECT_FALSE(fs::exists(*tmp_ + "/far"));
  // A run that fails part way (its files cannot be written: a file-size
  // limit, as a full disk) leaves no folder to refuse the next try.
  const std::string cut = *tmp_ + "/cut";
  const ScriptRun fail =
      Script({"/bin/bash", "-c",
              "trap '' XFSZ; ulimit -f 64; exec " + testing::BuildPath("tools/rms_resim") + " " +
                  *dir_ + " --set dcp.tpob_ft=0.4 --out " + cut},
             *tmp_ + "/cut.log");
  EXPECT_NE(fail.rc, 0) << fail.out;
  EXPECT_FALSE(fs::exists(cut)) << fail.out;
  // The same into a folder that was there, holding a file of the user's:
  // it is left as it was, with no empty session folders in it.
  const std::string there = *tmp_ + "/there";
  fs::create_directories(there);
  std::ofstream(there + "/notes.txt") << "mine\n";
  const ScriptRun fail_there =
      Script({"/bin/bash", "-c",
              "trap '' XFSZ; ulimit -f 64; exec " + testing::BuildPath("tools/rms_resim") + " " +
                  *dir_ + " --set dcp.tpob_ft=0.4 --out " + there},
             *tmp_ + "/there.log");
  EXPECT_NE(fail_there.rc, 0) << fail_there.out;
  std::vector<std::string> left;
  for (const auto& e : fs::recursive_directory_iterator(there))
    left.push_back(e.path().lexically_relative(there).string());
  EXPECT_EQ(left, std::vector<std::string>{"notes.txt"}) << fail_there.out;
  EXPECT_EQ(Script({lab, "resim", *dir_, "--no-build", "--set", "dcp.tpob_ft=0.4", "--out", cut},
                   *tmp_ + "/cut2.log")
                .rc,
            0);
}

TEST_F(RecordedSession, ItReplaysThroughTheSceneAndTheRendererToTheSameFrames) {
  const std::string out = *tmp_ + "/replay";
  const ScriptRun r =
      Script({SourcePath("scripts/lab"), "replay", *dir_, "--no-build", "--out", out, "--speed",
              "4", "--width", "160", "--height", "120", "--lcm-url", testing::UniqueLcmUrl(9200)},
             *tmp_ + "/replay.log");
  ASSERT_EQ(r.rc, 0) << r.out;
  const auto c = nlohmann::json::parse(ReadFile(out + "/replay_comparison.json"));
  EXPECT_GT(c["recorded"].get<int>(), 1000);
  // Every frame replayed is identical; a frame missing from the replay's
  // log is one its recorder lost and reported (on a loaded machine at 4x),
  // never one replayed differently or lost silently.
  const auto replay_summary = nlohmann::json::parse(ReadFile(out + "/summary.json"));
  const int lost = replay_summary["record"]["by_channel"].contains("RMS_ESG_FRAME")
                       ? replay_summary["record"]["by_channel"]["RMS_ESG_FRAME"]["lost"].get<int>()
                       : 0;
  // DCP frames that never reached scene_proc (UDP at 4x on a loaded
  // machine), or came too late to act on (a stalled scene_proc), make no
  // ESG frame, and are counted.
  const auto scene = nlohmann::json::parse(ReadFile(out + "/stats/scene_proc.json"));
  const int missed = scene["counters"].value("dcp.missing", 0);
  const int late = scene["counters"].value("dropped.late", 0);
  if (lost > 0 || missed > 0 || late > 0)
    std::printf(
        "the replay's recorder lost %d ESG frames, scene_proc missed %d DCP frames and dropped %d "
        "as late (reported)\n",
        lost, missed, late);
  EXPECT_EQ(c["identical"].get<int>() + c["missing"].get<int>(), c["recorded"].get<int>());
  EXPECT_LE(c["missing"].get<int>(), lost + missed + late) << c.dump();
  if (c["missing"].get<int>() > 0) {
    EXPECT_NE(r.out.find("each a reported loss"), std::string::npos) << r.out;
  }
  // The replay's video: one frame per frame number.
  Subprocess probe(
      {"/usr/bin/ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
       "-show_entries", "stream=nb_read_frames", "-of", "csv=p=0", out + "/session.mp4"},
      *tmp_ + "/ffprobe.log");
  ASSERT_EQ(probe.Wait(60), 0);
  // A loaded machine may drop a video frame; if so it is counted, and the
  // replay said so (docs/esg.md "Video").
  const auto esg = nlohmann::json::parse(ReadFile(out + "/stats/esg_renderer.json"));
  const int dropped = esg["counters"].value("video.dropped", 0);
  EXPECT_EQ(std::stoi(ReadFile(*tmp_ + "/ffprobe.log")) + dropped + missed + late,
            c["recorded"].get<int>());
  if (dropped > 0) {
    EXPECT_NE(r.out.find("frames dropped"), std::string::npos) << r.out;
  }
}

TEST_F(RecordedSession, ItExportsEveryChannelToCsvWithUnits) {
  const ScriptRun r = Script({SourcePath("scripts/lab"), "export", *dir_, "--out", *tmp_ + "/csv"},
                             *tmp_ + "/export.log");
  ASSERT_EQ(r.rc, 0) << r.out;
  const auto s = nlohmann::json::parse(ReadFile(*dir_ + "/summary.json"));
  auto lines = [](const std::string& path) {
    std::ifstream f(path);
    std::string header, line;
    std::getline(f, header);
    long n = 0;
    while (std::getline(f, line)) ++n;
    return std::make_pair(header, n);
  };
  const auto [in_header, in_rows] = lines(*tmp_ + "/csv/operator_input.csv");
  EXPECT_NE(in_header.find("shoulder_yaw [deg]"), std::string::npos);
  EXPECT_NE(in_header.find("shoulder_height [ft]"), std::string::npos);
  EXPECT_EQ(in_rows, s["log"]["operator_frames"].get<long>());
  const auto [tm_header, tm_rows] = lines(*tmp_ + "/csv/dcp_telemetry.csv");
  EXPECT_NE(tm_header.find("dock_distance [ft]"), std::string::npos);
  EXPECT_EQ(tm_rows, s["telemetry_frames"].get<long>());
  const auto [esg_header, esg_rows] = lines(*tmp_ + "/csv/esg_frame.csv");
  EXPECT_NE(esg_header.find("fov [deg]"), std::string::npos);
  EXPECT_EQ(esg_rows, s["log"]["esg_frames"].get<long>());
  EXPECT_GT(lines(*tmp_ + "/csv/status.csv").second, 50);
  EXPECT_NE(r.out.find("skipped (malformed): 0 rows"), std::string::npos) << r.out;
  // The last telemetry row says docked, in the column the header names.
  std::ifstream f(*tmp_ + "/csv/dcp_telemetry.csv");
  std::string header, line, last;
  std::getline(f, header);
  while (std::getline(f, line)) last = line;
  auto column = [](const std::string& row, int k) {
    std::stringstream ss(row);
    std::string cell;
    for (int i = 0; i <= k; ++i) std::getline(ss, cell, ',');
    return cell;
  };
  int docked_col = -1;
  {
    std::stringstream ss(header);
    std::string cell;
    for (int i = 0; std::getline(ss, cell, ','); ++i) {
      if (cell == "docked") docked_col = i;
    }
  }
  ASSERT_GE(docked_col, 0);
  EXPECT_EQ(column(last, docked_col), "1");
}

// A log cut short is exported up to the cut, saying so; a log with nothing
// of the session in it exports nothing and fails; an --out that names one
// of the session's own record files is refused and the file kept.
TEST_F(RecordedSession, AnExportSaysWhatItCouldNotReadAndKeepsTheRecord) {
  const std::string lab = SourcePath("scripts/lab");
  const std::string cut = *tmp_ + "/cut_export";
  fs::create_directories(cut);
  for (const char* f : {"config.toml", "manifest.json", "summary.json"})
    fs::copy_file(*dir_ + "/" + f, cut + "/" + f);
  const std::string whole = ReadFile(*dir_ + "/lcmlog");
  std::ofstream(cut + "/lcmlog", std::ios::binary) << whole.substr(0, whole.size() / 2);
  const ScriptRun half = Script({lab, "export", cut, "--no-build"}, *tmp_ + "/cut_export.log");
  EXPECT_EQ(half.rc, 0) << half.out;
  EXPECT_NE(half.out.find("bytes that are no whole event (it was cut short or damaged there): "
                          "exported up to them"),
            std::string::npos)
      << half.out;
  std::ofstream(cut + "/lcmlog", std::ios::binary | std::ios::trunc) << "";
  const ScriptRun none = Script({lab, "export", cut, "--no-build"}, *tmp_ + "/none_export.log");
  EXPECT_EQ(none.rc, 1) << none.out;
  EXPECT_NE(none.out.find("holds no message of this session"), std::string::npos) << none.out;
  for (const std::vector<std::string>& over :
       {std::vector<std::string>{lab, "report", *dir_, "--no-build", "--out", *dir_ + "/lcmlog"},
        std::vector<std::string>{lab, "export", *dir_, "--no-build", "--mcap", "--out",
                                 *dir_ + "/summary.json"}}) {
    const ScriptRun r = Script(over, *tmp_ + "/over.log");
    EXPECT_EQ(r.rc, 2) << r.out;
    EXPECT_NE(r.out.find("that is the session's own"), std::string::npos) << r.out;
  }
  EXPECT_EQ(ReadFile(*dir_ + "/lcmlog"), whole);
  EXPECT_TRUE(nlohmann::json::accept(ReadFile(*dir_ + "/summary.json")));
}

TEST_F(RecordedSession, ItsReportOpensInABrowserWithPlots) {
  const ScriptRun r =
      Script({SourcePath("scripts/lab"), "report", *dir_, "--out", *tmp_ + "/report.html"},
             *tmp_ + "/report.log");
  ASSERT_EQ(r.rc, 0) << r.out;
  const std::string html = ReadFile(*tmp_ + "/report.html");
  for (const char* want :
       {"<h2>Attempts</h2>", "The operator's scorecard", "docked at, ft", "Losses",
        "lost by the record: RMS_DCP_FRAME", "refused by the processes: late",
        "Frame times and latency", "The configuration's tolerances", "Chart.js v3",
        "data:image/png;base64,"}) {
    EXPECT_NE(html.find(want), std::string::npos) << want;
  }
  EXPECT_EQ(html.find("<script src="), std::string::npos) << "not self-contained";
  // Times shown rounded carry the exact session time (docs/sessions.md
  // "Session time"): the session's length, each attempt's start and length.
  const auto summary = nlohmann::json::parse(ReadFile(*dir_ + "/summary.json"));
  auto exact = [](const nlohmann::json& t) {
    return "data-s=\"" + nlohmann::json(t.get<double>()).dump() + "\"";
  };
  EXPECT_NE(html.find(exact(summary["duration_s"])), std::string::npos)
      << exact(summary["duration_s"]);
  ASSERT_FALSE(summary["attempts"].empty());
  for (const auto& a : summary["attempts"])
    for (const char* k : {"start_s", "duration_s"})
      EXPECT_NE(html.find(exact(a[k])), std::string::npos) << k << " " << exact(a[k]);
  EXPECT_EQ(html.find("<pre>"), std::string::npos) << "raw JSON in the report";
  // A real browser: headless Chromium draws the charts (path top and side,
  // joints, distance to goal, timeline; no inputs plot for the autopilot).
  Subprocess chrome(
      {"/usr/bin/chromium", "--headless=new", "--no-sandbox", "--disable-gpu",
       "--virtual-time-budget=5000", "--dump-dom", "file://" + *tmp_ + "/report.html"},
      *tmp_ + "/dom.html");
  ASSERT_EQ(chrome.Wait(120), 0) << ReadFile(*tmp_ + "/dom.html").substr(0, 2000);
  const std::string dom = ReadFile(*tmp_ + "/dom.html");
  EXPECT_NE(dom.find("data-charts-rendered=\"5\""), std::string::npos)
      << "charts not drawn: " << dom.substr(dom.find("<body"), 200);
}

// docs/security.md "Text from messages and folders": a session folder whose
// manifest's note and subject, and a stats file's name, are markup that
// once hid the report's sections and charts (`<!--<script>` inside the
// page's inline script). The report and the comparison show them as text,
// draw every chart, run no script of theirs, and the CSV keeps a formula a
// text.
TEST_F(RecordedSession, AReportAndAComparisonOfAHostileFolderShowTextNotMarkup) {
  const std::string hostile = *tmp_ + "/hostile";
  fs::copy(*dir_, hostile, fs::copy_options::recursive);
  const std::string note = "<!--<script>";
  const std::string subject = "\"><img src=x onerror=\"document.title='pwned'\">";
  {
    auto m = nlohmann::json::parse(ReadFile(hostile + "/manifest.json"));
    m["note"] = note;
    m["subject"] = subject;
    std::ofstream(hostile + "/manifest.json") << m.dump(2);
  }
  fs::copy_file(hostile + "/stats/esg_renderer.json", hostile + "/stats/" + note + ".json");
  auto dom_of = [&](const std::string& page, const std::string& out) {
    Subprocess chrome({"/usr/bin/chromium", "--headless=new", "--no-sandbox", "--disable-gpu",
                       "--virtual-time-budget=5000", "--dump-dom", "file://" + page},
                      out);
    EXPECT_EQ(chrome.Wait(120), 0);
    return ReadFile(out);
  };
  const ScriptRun r = Script(
      {SourcePath("scripts/lab"), "report", hostile, "--out", *tmp_ + "/hostile-report.html"},
      *tmp_ + "/hostile-report.log");
  ASSERT_EQ(r.rc, 0) << r.out;
  const std::string html = ReadFile(*tmp_ + "/hostile-report.html");
  EXPECT_EQ(html.find(note), std::string::npos) << "raw in the page";
  const std::string dom = dom_of(*tmp_ + "/hostile-report.html", *tmp_ + "/hostile-dom.html");
  EXPECT_NE(dom.find("data-charts-rendered=\"5\""), std::string::npos)
      << dom.substr(0, std::min<std::size_t>(dom.size(), 3000));
  for (const char* section : {"Losses", "Frame times and latency", "&lt;!--&lt;script&gt;"})
    EXPECT_NE(dom.find(section), std::string::npos) << section;
  auto title = [](const std::string& d) {
    const auto a = d.find("<title>");
    return a == std::string::npos ? std::string() : d.substr(a, d.find("</title>", a) - a);
  };
  EXPECT_EQ(title(dom).find("pwned"), std::string::npos) << "the subject's script ran";
  EXPECT_EQ(dom.find("<img src=\"x\""), std::string::npos) << "the subject is markup";
  const ScriptRun c = Script({SourcePath("scripts/lab"), "compare", hostile, *dir_, "--no-build",
                              "--out", *tmp_ + "/hostile-compare"},
                             *tmp_ + "/hostile-compare.log", 120);
  ASSERT_EQ(c.rc, 0) << c.out;
  const std::string cdom =
      dom_of(*tmp_ + "/hostile-compare/compare.html", *tmp_ + "/hostile-compare-dom.html");
  EXPECT_EQ(ReadFile(*tmp_ + "/hostile-compare/compare.html").find(note), std::string::npos);
  const auto at = cdom.find("data-charts-rendered=\"");
  ASSERT_NE(at, std::string::npos) << "no charts: " << cdom.substr(0, 3000);
  EXPECT_GT(std::atoi(cdom.c_str() + at + 22), 0);
  EXPECT_NE(cdom.find("&lt;!--&lt;script&gt;"), std::string::npos);
  EXPECT_EQ(title(cdom).find("pwned"), std::string::npos) << "the subject's script ran";
  EXPECT_EQ(cdom.find("<img src=\"x\""), std::string::npos) << "the subject is markup";
}

// A short timeline run live (3 s), listening on LCM.
struct Listener {
  explicit Listener(const std::string& url) {
    transport::LcmOptions o;
    o.url = url;
    lcm = std::make_unique<transport::UdpLcm>(o);
    lcm->Subscribe(wire::channels::kDcpFrame, [this](const void* d, int n, std::int64_t) {
      dcp_frame_t m;
      if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) dcp.push_back(m);
    });
    lcm->Subscribe(wire::channels::kEsgFrame, [this](const void* d, int n, std::int64_t) {
      esg_frame_t m;
      if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) esg.push_back(m.frame);
    });
    lcm->Subscribe(wire::channels::kDcpTelemetry, [this](const void* d, int n, std::int64_t) {
      dcp_telemetry_t m{};
      if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) telemetry = m;
    });
  }
  void Pump(double seconds) {
    const std::int64_t until = lcm->NowUs() + static_cast<std::int64_t>(seconds * 1e6);
    while (lcm->NowUs() < until) lcm->HandleSubscriptions(20);
  }
  std::unique_ptr<transport::UdpLcm> lcm;
  std::vector<dcp_frame_t> dcp;
  std::vector<std::int64_t> esg;
  std::optional<dcp_telemetry_t> telemetry;
};

std::vector<dcp_frame_t> FlyShortTimeline(const std::string& dir, const std::string& url,
                                          bool freeze) {
  testing::LabProcesses lab(dir, url);
  std::string error;
  EXPECT_TRUE(lab.Start(&error)) << error;
  Listener l(url);
  Subprocess op({testing::BuildPath("operator_station/operator_station"), "--lcm-url", url,
                 "--timeline", SourcePath("scripts/timelines/short.tl")},
                dir + "/op.log");
  auto control = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {testing::BuildPath("tools/rms_control"), "--lcm-url", url});
    Subprocess c(args, dir + "/control.log");
    EXPECT_EQ(c.Wait(10), 0) << ReadFile(dir + "/control.log");
  };
  if (freeze) {
    l.Pump(1.0);
    control({"freeze"});
    l.Pump(0.5);  // frames in flight arrive
    const std::size_t frozen_at = l.dcp.size();
    l.Pump(1.5);
    EXPECT_EQ(l.dcp.size(), frozen_at) << "frames flowed while frozen";
    control({"step", "3"});
    l.Pump(1.0);
    EXPECT_EQ(l.dcp.size(), frozen_at + 3) << "step 3 did not make exactly three frames";
    control({"run"});
  }
  while (op.Running()) l.Pump(0.05);
  l.Pump(0.5);
  EXPECT_EQ(op.Wait(1), 0) << ReadFile(dir + "/op.log");
  EXPECT_TRUE(lab.Stop(&error)) << error;
  // Nothing lost: every frame, in order, through to the ESG.
  for (std::size_t i = 0; i < l.dcp.size(); ++i)
    EXPECT_EQ(l.dcp[i].frame, static_cast<std::int64_t>(i));
  for (std::size_t i = 0; i < l.esg.size(); ++i) EXPECT_EQ(l.esg[i], static_cast<std::int64_t>(i));
  EXPECT_EQ(l.esg.size(), l.dcp.size());
  return l.dcp;
}

TEST(SessionControl, AFrozenSessionHoldsStepsAndResumesWithNothingLost) {
  const std::string dir = testing::MakeTempDir("freeze");
  fs::create_directories(dir + "/plain");
  fs::create_directories(dir + "/frozen");
  const auto plain = FlyShortTimeline(dir + "/plain", testing::UniqueLcmUrl(9300), false);
  const auto frozen = FlyShortTimeline(dir + "/frozen", testing::UniqueLcmUrl(9400), true);
  // The same frames, word for word, as a session never frozen: the operator
  // station's clock stopped with everything else.
  ASSERT_EQ(plain.size(), 91u);
  ASSERT_EQ(frozen.size(), plain.size());
  for (std::size_t i = 0; i < plain.size(); ++i) {
    ASSERT_EQ(frozen[i].input_frame, plain[i].input_frame) << i;
    for (int k = 0; k < 12; ++k)
      ASSERT_EQ(frozen[i].arm_words[k], plain[i].arm_words[k]) << "frame " << i;
    ASSERT_EQ(frozen[i].control_word, plain[i].control_word) << i;
    for (int k = 0; k < 17; ++k) ASSERT_EQ(frozen[i].state_words[k], plain[i].state_words[k]) << i;
  }
  fs::remove_all(dir);
}

TEST(SessionControl, ACheckpointRestoresTheDcpAndASessionStartsFromOne) {
  const std::string dir = testing::MakeTempDir("checkpoint");
  const std::string url = testing::UniqueLcmUrl(9500);
  const std::string cp = dir + "/checkpoints/before_docking.json";
  {
    testing::LabProcesses lab(dir, url);
    std::string error;
    ASSERT_TRUE(lab.Start(&error)) << error;
    Listener l(url);
    Subprocess op(
        {testing::BuildPath("operator_station/operator_station"), "--lcm-url", url, "--autopilot",
         "--rate", "150", "--hold", "--checkpoint-dir", dir + "/checkpoints"},
        dir + "/op.log");
    auto control = [&](std::vector<std::string> args) {
      args.insert(args.begin(), {testing::BuildPath("tools/rms_control"), "--lcm-url", url});
      Subprocess c(args, dir + "/control.log");
      EXPECT_EQ(c.Wait(10), 0) << ReadFile(dir + "/control.log");
    };
    // In Mode 3, under way to the port: a checkpoint.
    for (int i = 0; i < 600 && !(l.telemetry && l.telemetry->mode == wire::DcpMode::kManoeuvring);
         ++i)
      l.Pump(0.05);
    ASSERT_TRUE(l.telemetry && l.telemetry->mode == wire::DcpMode::kManoeuvring)
        << ReadFile(dir + "/op.log");
    control({"checkpoint", "before_docking"});  // a name: saved in the session's checkpoints folder
    l.Pump(0.5);
    ASSERT_TRUE(fs::exists(cp)) << ReadFile(dir + "/dynamics_proc.log");
    const auto saved = nlohmann::json::parse(ReadFile(cp));
    EXPECT_EQ(saved["dcp"]["mode"], 3);
    EXPECT_FALSE(saved["dcp"]["docked"].get<bool>());
    for (int i = 0; i < 600 && !l.telemetry->docked; ++i) l.Pump(0.05);
    ASSERT_TRUE(l.telemetry->docked);
    // Restore: back to Mode 3, not docked; the autopilot picks the task up
    // where the DCP now is and docks again.
    control({"restore", "before_docking.json", "--run"});
    bool undocked = false;
    for (int i = 0; i < 100 && !undocked; ++i) {
      l.Pump(0.05);
      undocked =
          l.telemetry && !l.telemetry->docked && l.telemetry->mode == wire::DcpMode::kManoeuvring;
    }
    EXPECT_TRUE(undocked) << "the restore did not take the DCP back to before docking";
    for (int i = 0; i < 600 && !l.telemetry->docked; ++i) l.Pump(0.05);
    EXPECT_TRUE(l.telemetry->docked) << ReadFile(dir + "/op.log");
    op.Signal(SIGINT);
    op.Wait(10);
    ASSERT_TRUE(lab.Stop(&error)) << error;
    EXPECT_NE(ReadFile(dir + "/dynamics_proc.log").find("restored the DCP's state"),
              std::string::npos);
  }
  // A new session from the checkpoint: it starts in Mode 3 and docks without
  // ever acquiring.
  const ScriptRun r =
      Script({SourcePath("scripts/lab"), "demo", "--no-build", "--out", dir + "/from_checkpoint",
              "--restore", cp, "--speed", "4", "--lcm-url", testing::UniqueLcmUrl(9600),
              "--png-every", "0", "--no-video", "--width", "160", "--height", "120"},
             dir + "/lab.log");
  ASSERT_EQ(r.rc, 0) << r.out;
  const auto s = nlohmann::json::parse(ReadFile(dir + "/from_checkpoint/summary.json"));
  EXPECT_TRUE(s["docked"].get<bool>());
  EXPECT_EQ(s["modes_seen"], nlohmann::json::array({3}));
  // Session time: the whole task from the start takes about 61 s.
  EXPECT_LT(s["docking"]["time_s"].get<double>(), 45.0);
  ASSERT_EQ(s["attempts"].size(), 1u);
  EXPECT_EQ(s["attempts"][0]["started_in_mode"], 3);
  EXPECT_TRUE(s["attempts"][0]["phase_durations_s"]["acquisition"].is_null());
  fs::remove_all(dir);
}

TEST(Monitor, ShowsEveryChannelsTrafficWithRates) {
  const std::string dir = testing::MakeTempDir("monitor");
  const std::string url = testing::UniqueLcmUrl(9700);
  testing::LabProcesses lab(dir, url);
  std::string error;
  ASSERT_TRUE(lab.Start(&error)) << error;
  // A timeline longer than the monitor listens, however late either starts
  // on a loaded machine; stopped once the monitor is done.
  Subprocess op({testing::BuildPath("operator_station/operator_station"), "--lcm-url", url,
                 "--timeline", SourcePath("scripts/timelines/mission.tl")},
                dir + "/op.log");
  const ScriptRun m =
      Script({SourcePath("scripts/lab"), "monitor", "--lcm-url", url, "--for", "2.5"},
             dir + "/monitor.log", 30);
  op.Signal(SIGINT);
  const int op_rc = op.Wait(10);
  EXPECT_TRUE(op_rc == 0 || op_rc == 130) << op_rc;  // done, or stopped by the SIGINT
  ASSERT_TRUE(lab.Stop(&error)) << error;
  ASSERT_EQ(m.rc, 0) << m.out;
  for (const char* ch :
       {"RMS_OPERATOR_INPUT", "RMS_DCP_FRAME", "RMS_DCP_TELEMETRY", "RMS_ESG_FRAME"}) {
    const std::regex row(std::string(ch) + R"(\s+(\d+)\s+([\d.]+)\s+[\d.]+\s+(\d+)\s+0\s)");
    std::smatch mm;
    ASSERT_TRUE(std::regex_search(m.out, mm, row)) << ch << " not shown:\n" << m.out;
    EXPECT_GT(std::stoi(mm[1]), 40) << ch;
    EXPECT_NEAR(std::stod(mm[2]), 30.0, 3.0) << ch << " rate";
    EXPECT_EQ(mm[3], "0") << ch << " gaps";
  }
  EXPECT_NE(m.out.find("dynamics_proc"), std::string::npos) << m.out;
  fs::remove_all(dir);
}

// A forged process name with terminal escapes (clear the screen, set the
// window's title, a C1 control): the monitor prints them as text
// (docs/security.md "Text from messages and folders").
TEST(Monitor, ShowsAForgedNamesControlCharactersAsText) {
  const std::string dir = testing::MakeTempDir("monitor_escapes");
  const std::string url = testing::UniqueLcmUrl(9750);
  std::atomic<bool> done{false};
  std::thread forger([&] {
    transport::LcmOptions o;
    o.url = url;
    transport::UdpLcm lcm(o);
    lcm.SetSender({0, sender_t::PROCESS_TOOL, 4242});
    process_status_t m{};
    m.process = "\x1b]0;owned\x07\x1b[2Jforged";
    m.host =
        "host\xC2\x9B"
        "31m";
    m.pid = 4242;
    while (!done) {
      transport::PublishMessage(lcm, wire::channels::kStatus, m);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  const ScriptRun m =
      Script({SourcePath("scripts/lab"), "monitor", "--lcm-url", url, "--for", "2.5"},
             dir + "/monitor.log", 30);
  done = true;
  forger.join();
  ASSERT_EQ(m.rc, 0) << m.out;
  EXPECT_NE(m.out.find("\\x1b]0;owned\\x07\\x1b[2Jforged"), std::string::npos) << m.out;
  EXPECT_NE(m.out.find("host\\u009b31m"), std::string::npos) << m.out;
  EXPECT_EQ(m.out.find('\x1b'), std::string::npos) << "an escape reached the terminal";
  EXPECT_EQ(m.out.find("\xC2\x9B"), std::string::npos) << "a C1 control reached the terminal";
  fs::remove_all(dir);
}

// A session's messages carry tags (docs/security.md "Authenticated
// messages"): without the session the monitor decodes them, tags unchecked;
// with --session it shows only the session's own, their tags checked, and
// a stranger's message with the session's id is not among them.
TEST(Monitor, ShowsASessionsTaggedMessagesAndWithItsFolderOnlyItsOwn) {
  const std::string dir = testing::MakeTempDir("monitor_tags");
  const std::string url = testing::UniqueLcmUrl(9720);
  const std::int64_t id = 0x1234abcd5678ef01;
  wire::SessionKey key;
  key.bytes.fill(0x42);
  fs::create_directories(dir + "/session/run");
  {  // the key, 0x42 32 times, as the launcher writes one
    std::string hex;
    for (int i = 0; i < 32; ++i) hex += "42";
    std::ofstream(dir + "/session/run/session.key") << hex << "\n";
  }
  chmod((dir + "/session/run/session.key").c_str(), 0600);
  std::ofstream(dir + "/session/manifest.json") << nlohmann::json{
      {"session_id", wire::FormatSessionId(id)},
      {"message_auth", wire::kMessageAuthName},
      {"lcm", {{"url", url}, {"channel_suffix", ""}}}}.dump();
  transport::LcmOptions o;
  o.url = url;
  transport::UdpLcm member(o), stranger(o);
  member.SetSender({id, sender_t::PROCESS_DYNAMICS, 100});
  member.SetKey(key);
  stranger.SetSender({id, sender_t::PROCESS_SCENE, 200});  // the id, not the key
  std::atomic<bool> done{false};
  std::thread t([&] {
    while (!done) {
      process_status_t st{};
      st.process = "dynamics_proc";
      st.host = "here";
      transport::PublishMessage(member, wire::channels::kStatus, st);
      st.process = "impostor";
      transport::PublishMessage(stranger, wire::channels::kStatus, st);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  const ScriptRun open =
      Script({SourcePath("scripts/lab"), "monitor", "--lcm-url", url, "--for", "2"},
             dir + "/open.log", 30);
  const ScriptRun own =
      Script({SourcePath("scripts/lab"), "monitor", "--session", dir + "/session", "--for", "2"},
             dir + "/own.log", 30);
  done = true;
  t.join();
  ASSERT_EQ(open.rc, 0) << open.out;
  ASSERT_EQ(own.rc, 0) << own.out;
  EXPECT_NE(open.out.find("2 processes reporting"), std::string::npos) << open.out;
  EXPECT_NE(open.out.find("dynamics_proc    on here"), std::string::npos) << open.out;
  EXPECT_NE(own.out.find("1 processes reporting"), std::string::npos) << own.out;
  EXPECT_NE(own.out.find("dynamics_proc    on here"), std::string::npos) << own.out;
  EXPECT_EQ(own.out.find("impostor"), std::string::npos) << own.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rms
