// The instructor's station as an instructor runs it (docs/instructor.md):
// `scripts/lab demo --instructor` prints the page's URL; the page, driven in
// the system's Chromium by puppeteer-core (tests/browser/instructor_page.mjs),
// shows live views that change as the arm moves, freezes, runs and resets
// the session, and shows a late viewer the events from the start; it injects
// a stuck joint and a lost camera station, which the DCP honours and the
// autopilot reports, and repairs them; the commands are in the session's log
// (summary.json "control" and "malfunctions") and re-simulate word for word. Requests without the
// token, or with bad parameters, are refused and counted; a second station
// cannot take the port. A station that hears forgeries and idle
// connections stays bounded (docs/instructor.md "Bounds").
#include <httplib.h>
#include <poll.h>
#include <unistd.h>

#include <arpa/inet.h>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <nlohmann/json.hpp>
#include <sys/socket.h>
#include <thread>

#include "rms/dcp_telemetry_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/sender_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_auth.h"

#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::BuildPath;
using testing::ReadFile;
using testing::SourcePath;
using testing::Subprocess;

// "http://127.0.0.1:PORT/?token=T" -> port and token.
void SplitUrl(const std::string& url, int* port, std::string* token) {
  const auto colon = url.rfind(':');
  *port = std::stoi(url.substr(colon + 1));
  *token = url.substr(url.find("token=") + 6);
  while (!token->empty() && std::isspace(static_cast<unsigned char>(token->back())))
    token->pop_back();
}

TEST(InstructorStation,
     ItsPageShowsLiveViewsFreezesAndResetsTheSessionAndALateViewerSeesTheEvents) {
  const std::string tmp = testing::MakeTempDir("instructor");
  const std::string out = tmp + "/session";
  const std::string lcm_url = testing::UniqueLcmUrl(8600);
  Subprocess lab(
      {SourcePath("scripts/lab"), "demo", "--no-build", "--out", out, "--lcm-url", lcm_url,
       "--instructor", "0", "--no-video", "--png-every", "0", "--width", "320", "--height", "240"},
      tmp + "/lab.log", {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
  ASSERT_TRUE(testing::WaitForFile(out + "/run/instructor.url", 90)) << ReadFile(tmp + "/lab.log");
  const std::string url = ReadFile(out + "/run/instructor.url");
  testing::WaitForFile(out + "/run/operator_station.ready", 30);
  EXPECT_NE(ReadFile(tmp + "/lab.log").find("instructor's page: http://127.0.0.1:"),
            std::string::npos);

  // A forged status report whose process name is markup, and whose host is
  // not UTF-8: anyone with the session's key can send one.
  {
    const auto manifest = nlohmann::json::parse(ReadFile(out + "/manifest.json"));
    transport::LcmOptions lo;
    lo.url = lcm_url;
    transport::UdpLcm forger(lo);
    forger.SetSender({transport::ParseSessionId(manifest["session_id"], "session_id"),
                      sender_t::PROCESS_TOOL, 4242});
    forger.SetKey(wire::ReadSessionKeyFile(out + "/run/session.key"));
    process_status_t m{};
    m.process = "<img id=forged src=x onerror=\"document.title='pwned'\">";
    m.host = "\xff\xfe";
    m.pid = 4242;
    transport::PublishMessage(forger, wire::channels::kStatus, m);
  }

  // The page in a real browser.
  Subprocess browser(
      {"/usr/bin/env", "node", SourcePath("tests/browser/instructor_page.mjs"), url, "1"},
      tmp + "/browser.log");
  EXPECT_EQ(browser.Wait(240), 0) << ReadFile(tmp + "/browser.log");
  EXPECT_NE(ReadFile(tmp + "/browser.log").find("ok a forged process name is shown as text"),
            std::string::npos)
      << ReadFile(tmp + "/browser.log");

  // Without the token, or with bad parameters: refused, said, nothing sent.
  int port = 0;
  std::string token;
  SplitUrl(url, &port, &token);
  httplib::Client web("127.0.0.1", port);
  const auto no_token =
      web.Post("/api/control", "command=freeze", "application/x-www-form-urlencoded");
  ASSERT_TRUE(no_token);
  EXPECT_EQ(no_token->status, 403);
  const auto wrong = web.Post("/api/control?token=" + std::string(token.size(), 'a'),
                              "command=freeze", "application/x-www-form-urlencoded");
  ASSERT_TRUE(wrong);
  EXPECT_EQ(wrong->status, 403);
  const auto path = web.Post("/api/control?token=" + token, "command=checkpoint&name=../../x",
                             "application/x-www-form-urlencoded");
  ASSERT_TRUE(path);
  EXPECT_EQ(path->status, 400);
  EXPECT_NE(path->body.find("not a path"), std::string::npos) << path->body;
  const auto bad = web.Post("/api/control?token=" + token, "command=malfunction&name=joint+9+stuck",
                            "application/x-www-form-urlencoded");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  EXPECT_NE(bad->body.find("joint '9' is not 1..6"), std::string::npos) << bad->body;
  const auto view = web.Get("/api/view?v=9&token=" + token);
  ASSERT_TRUE(view);
  EXPECT_EQ(view->status, 400);
  EXPECT_NE(view->body.find("parameter v='9'"), std::string::npos) << view->body;
  const auto read = web.Get("/api/status");  // reading needs the token too
  ASSERT_TRUE(read);
  EXPECT_EQ(read->status, 403);
  // A second station on the same port is refused (no SO_REUSEPORT sharing).
  Subprocess second({BuildPath("instructor_station/instructor_station"), "--lcm-url",
                     testing::UniqueLcmUrl(8650), "--port", std::to_string(port)},
                    tmp + "/second.log");
  EXPECT_EQ(second.Wait(30), 2) << ReadFile(tmp + "/second.log");
  EXPECT_NE(ReadFile(tmp + "/second.log").find("cannot serve the page"), std::string::npos)
      << ReadFile(tmp + "/second.log");

  ASSERT_EQ(lab.Wait(240), 0) << ReadFile(tmp + "/lab.log");
  // The commands are in the session's log, from the instructor's station.
  const auto summary = nlohmann::json::parse(ReadFile(out + "/summary.json"));
  EXPECT_TRUE(summary["docked"].get<bool>());
  int freezes = 0, runs = 0, resets = 0, malfunctions = 0, repairs = 0;
  for (const auto& c : summary["control"]) {
    EXPECT_EQ(c["process"], "instructor_station") << c.dump();
    freezes += c["command"] == "freeze";
    runs += c["command"] == "run";
    resets += c["command"] == "reset";
    malfunctions += c["command"] == "malfunction";
    repairs += c["command"] == "repair";
  }
  EXPECT_EQ(freezes, 1) << summary["control"].dump();
  EXPECT_EQ(runs, 1) << summary["control"].dump();
  EXPECT_EQ(resets, 1) << summary["control"].dump();
  EXPECT_EQ(malfunctions, 4) << summary["control"].dump();  // the page's 2, the lesson's 2
  EXPECT_EQ(repairs, 1) << summary["control"].dump();
  // Every command answered; the page's second checkpoint of one name
  // refused by the DCP, with the reason.
  int refused_checkpoints = 0;
  for (const auto& c : summary["control"]) {
    EXPECT_FALSE(c["answers"].empty()) << c.dump();
    if (c["command"] == "checkpoint" && !c["answers"].empty() &&
        c["answers"][0]["outcome"] == "refused" &&
        c["answers"][0]["text"].get<std::string>().find("exists already") != std::string::npos)
      ++refused_checkpoints;
  }
  EXPECT_EQ(refused_checkpoints, 1) << summary["control"].dump();
  // The malfunctions as the DCP took them, with their times and frames: the
  // joint stuck, the camera lost, both repaired at once; then the page's
  // lesson's camera 7, and its camera 6 at its condition.
  const auto& mf = summary["malfunctions"];
  ASSERT_EQ(mf.size(), 5u) << mf.dump();
  EXPECT_EQ(mf[3]["injected"][0], "camera 7 lost") << mf.dump();
  EXPECT_EQ(mf[4]["injected"][0], "camera 6 lost") << mf.dump();
  EXPECT_NE(mf[0]["injected"][0].get<std::string>().find(" stuck"), std::string::npos) << mf.dump();
  EXPECT_EQ(mf[1]["injected"][0], "camera 1 lost") << mf.dump();
  EXPECT_EQ(mf[2]["repaired"].size(), 2u) << mf.dump();
  EXPECT_TRUE(mf[2]["in_force"].empty()) << mf.dump();
  for (std::size_t i = 1; i < mf.size(); ++i) {
    EXPECT_GE(mf[i]["time_s"].get<double>(), mf[i - 1]["time_s"].get<double>());
    EXPECT_GT(mf[i]["dcp_frame"].get<std::int64_t>(), mf[i - 1]["dcp_frame"].get<std::int64_t>());
  }
  const auto dcp = nlohmann::json::parse(ReadFile(out + "/stats/dynamics_proc.json"));
  EXPECT_EQ(dcp["counters"].value("control.malfunctions", 0), 4);
  EXPECT_EQ(dcp["counters"].value("control.repairs", 0), 1);
  // The reset began a second attempt, and the autopilot flew it to the dock.
  EXPECT_EQ(summary["attempts"].size(), 2u) << summary["attempts"].dump();
  const auto stats = nlohmann::json::parse(ReadFile(out + "/stats/instructor_station.json"));
  EXPECT_GT(stats["counters"].value("views.rendered", 0), 10);
  EXPECT_EQ(stats["counters"].value("http.refused", 0), 7);  // 6 here, the page's bad lesson
  EXPECT_EQ(stats["counters"].value("control.sent", 0), 8);  // with the two checkpoints
  EXPECT_EQ(stats["counters"].value("lesson.events", 0), 2);
  const auto op = nlohmann::json::parse(ReadFile(out + "/stats/operator_station.json"));
  EXPECT_EQ(op["counters"].value("control.resets", 0), 1);
  EXPECT_GE(op["counters"].value("arm.not_following", 0), 1);
  // The report lists them.
  const testing::ScriptRun report = testing::Script(
      {SourcePath("scripts/lab"), "report", out, "--no-build"}, tmp + "/report.log");
  EXPECT_EQ(report.rc, 0) << report.out;
  const std::string html = ReadFile(out + "/report.html");
  EXPECT_NE(html.find("<h2>Malfunctions</h2>"), std::string::npos);
  EXPECT_NE(html.find("camera 1 lost"), std::string::npos);
  // What the page did re-simulates word for word.
  const testing::ScriptRun resim = testing::Script(
      {SourcePath("scripts/lab"), "resim", out, "--no-build", "--out", tmp + "/resim"},
      tmp + "/resim.log");
  EXPECT_EQ(resim.rc, 0) << resim.out;
  EXPECT_NE(resim.out.find("identical, word for word"), std::string::npos) << resim.out;
}

// The PNG's width and height, from its IHDR (0, 0: not a PNG).
std::pair<int, int> PngSize(const std::string& path) {
  const std::string b = ReadFile(path);
  if (b.size() < 24 || b.compare(1, 3, "PNG") != 0) return {0, 0};
  auto be32 = [&](std::size_t i) {
    return (static_cast<unsigned char>(b[i]) << 24) | (static_cast<unsigned char>(b[i + 1]) << 16) |
           (static_cast<unsigned char>(b[i + 2]) << 8) | static_cast<unsigned char>(b[i + 3]);
  };
  return {static_cast<int>(be32(16)), static_cast<int>(be32(20))};
}

// The page's URL `scripts/lab debrief` printed to its log ("debrief of
// SESSION: URL"), once the line is whole; "" before.
std::string DebriefUrl(const std::string& log_path) {
  const std::string log = ReadFile(log_path);
  const auto at = log.find("debrief of ");
  const auto http = log.find("http://", at == std::string::npos ? log.size() : at);
  const auto end = http == std::string::npos ? http : log.find('\n', http);
  return end == std::string::npos ? "" : log.substr(http, end - http);
}

// Whether `ok` holds within `seconds` (asked every 0.2 s).
bool Until(const std::function<bool()>& ok, double seconds) {
  return testing::WaitUntil(ok, seconds, 200);
}

// docs/instructor.md "The banner", "Commands and their answers", "A
// restarted station", "Debrief": `scripts/lab control` freezes, restores
// and resets the session, each confirmed by the process that acted (a
// restore of a missing checkpoint refused with the reason); the page's
// state follows (FROZEN, RUNNING); the station killed mid-session is
// restarted by the launcher and reads its history back from the session's
// log; after the session, `scripts/lab debrief` serves the page over the
// record, which a browser scrubs through and marks (tests/browser/
// instructor_debrief.mjs: layout at 1280x800 and 390 px, axe-core); the
// mark is kept in the session's folder and shown in the report, and the
// summary and the report give every command's answers.
TEST(InstructorStation, ARestartedStationRecoversItsHistoryAndADebriefScrubsAndMarksTheSession) {
  const std::string tmp = testing::MakeTempDir("instructor-debrief");
  const std::string out = tmp + "/session";
  Subprocess lab({SourcePath("scripts/lab"), "demo", "--no-build", "--out", out, "--lcm-url",
                  testing::UniqueLcmUrl(8700), "--instructor", "0", "--no-video", "--png-every",
                  "0", "--width", "320", "--height", "240"},
                 tmp + "/lab.log", {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
  ASSERT_TRUE(testing::WaitForFile(out + "/run/instructor.url", 90)) << ReadFile(tmp + "/lab.log");
  ASSERT_TRUE(testing::WaitForFile(out + "/run/operator_station.ready", 30));
  int port = 0;
  std::string token;
  SplitUrl(ReadFile(out + "/run/instructor.url"), &port, &token);
  httplib::Client web("127.0.0.1", port);
  web.set_read_timeout(5);
  auto status = [&] {
    const auto r = web.Get("/api/status?token=" + token);
    return r && r->status == 200 ? nlohmann::json::parse(r->body) : nlohmann::json::object();
  };
  auto state = [&] {
    const auto s = status();
    return s.contains("session") ? s["session"].value("state", "") : std::string();
  };
  ASSERT_TRUE(Until([&] { return state() == "RUNNING"; }, 30)) << status().dump();
  auto control = [&](std::vector<std::string> words) {
    std::vector<std::string> argv = {SourcePath("scripts/lab"), "control", "--session", out};
    argv.insert(argv.end(), words.begin(), words.end());
    return testing::Script(argv, tmp + "/control.log", 60);
  };
  // Each command confirmed by the process that acted on it, or refused with the reason.
  const auto freeze = control({"freeze"});
  EXPECT_EQ(freeze.rc, 0) << freeze.out;
  EXPECT_NE(freeze.out.find("freeze: frozen at operator frame"), std::string::npos) << freeze.out;
  EXPECT_TRUE(Until([&] { return state() == "FROZEN"; }, 10)) << status().dump();
  // Steps: one command and one answer however many frames.
  const auto steps = control({"step", "30"});
  EXPECT_EQ(steps.rc, 0) << steps.out;
  EXPECT_NE(steps.out.find("step: 30 frames, operator frames "), std::string::npos) << steps.out;
  const auto missing = control({"restore", "nothere"});
  EXPECT_EQ(missing.rc, 1) << missing.out;
  EXPECT_NE(missing.out.find("restore refused by dynamics_proc: cannot read checkpoint"),
            std::string::npos)
      << missing.out;
  const auto saved = control({"checkpoint", "here"});
  EXPECT_EQ(saved.rc, 0) << saved.out;
  const auto restored = control({"restore", "here"});
  EXPECT_EQ(restored.rc, 0) << restored.out;
  EXPECT_NE(restored.out.find("frozen after one frame from the inputs of here.json"),
            std::string::npos)
      << restored.out;
  EXPECT_EQ(state(), "FROZEN");
  // A checkpoint the operator station can read but the DCP refuses (docked
  // in Mode 1), its finger closed: refused by both, nothing taken.
  auto bad = nlohmann::json::parse(ReadFile(out + "/checkpoints/here.json"));
  bad["dcp"]["docked"] = true;
  bad["operator_inputs"]["finger"] = 1.0;
  std::ofstream(out + "/checkpoints/bad.json") << bad.dump();
  const double finger_before = status()["dcp"].value("master_finger", -1.0);
  const auto refused_restore = control({"restore", "bad"});
  EXPECT_EQ(refused_restore.rc, 1) << refused_restore.out;
  for (const char* said :
       {"refused by dynamics_proc: checkpoint '", "bad.json': checkpoint: 'docked' needs Mode 3",
        "refused by operator_station: dynamics_proc refused it"})
    EXPECT_NE(refused_restore.out.find(said), std::string::npos) << said << refused_restore.out;
  // ... and one whose arm is beyond a joint's limits (shoulder pitch -40 deg, its limit -2).
  auto far = nlohmann::json::parse(ReadFile(out + "/checkpoints/here.json"));
  far["dcp"]["master"]["angles_deg"][1] = -40.0;
  far["dcp"]["slave"]["angles_deg"][1] = -40.0;
  std::ofstream(out + "/checkpoints/far.json") << far.dump();
  const auto unreachable = control({"restore", "far"});
  EXPECT_EQ(unreachable.rc, 1) << unreachable.out;
  EXPECT_NE(unreachable.out.find("joint 2 (shoulder pitch) at -40.000 deg, beyond its limits"),
            std::string::npos)
      << unreachable.out;
  EXPECT_EQ(control({"step", "3"}).rc, 0);
  EXPECT_TRUE(Until([&] { return state() == "FROZEN"; }, 10)) << status().dump();
  EXPECT_EQ(status()["dcp"].value("master_finger", -2.0), finger_before) << "inputs taken";
  const auto run = control({"run"});
  EXPECT_EQ(run.rc, 0) << run.out;
  EXPECT_TRUE(Until([&] { return state() == "RUNNING"; }, 10)) << status().dump();
  const auto running_step = control({"step"});
  EXPECT_EQ(running_step.rc, 1) << running_step.out;
  EXPECT_NE(running_step.out.find("refused by operator_station: not frozen"), std::string::npos)
      << running_step.out;
  const auto reset = control({"reset"});
  EXPECT_EQ(reset.rc, 0) << reset.out;
  EXPECT_NE(reset.out.find("reset: the reset button pressed for one frame"), std::string::npos)
      << reset.out;

  // A command from the page: its id still means it after the restart below.
  auto page_command = [&](const std::string& form) {
    const auto r =
        web.Post("/api/control?token=" + token, form, "application/x-www-form-urlencoded");
    return r && r->status == 200 ? nlohmann::json::parse(r->body).value("id", -1) : -1;
  };
  auto command_state = [&](long id) {
    const auto r = web.Get("/api/command?token=" + token + "&id=" + std::to_string(id));
    const auto j = r && r->status == 200 ? nlohmann::json::parse(r->body) : nlohmann::json();
    return j.is_object() ? j : nlohmann::json::object();  // null: not yet sent
  };
  const long early_id = page_command("command=checkpoint&name=early");
  ASSERT_GE(early_id, 0);
  EXPECT_TRUE(Until([&] { return command_state(early_id).value("state", "") == "done"; }, 10));
  // The station killed: the launcher restarts it, and it reads its history
  // back from the session's log.
  const std::string before = status().value("instance", "");
  const int pid = std::stoi(ReadFile(out + "/run/instructor_station.pid"));
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  ASSERT_TRUE(Until(
      [&] {
        const auto s = status();
        return s.contains("instance") && s["instance"] != before;
      },
      30))
      << ReadFile(tmp + "/lab.log");
  const auto s = status();
  EXPECT_TRUE(s["session"]["restarted"].get<bool>()) << s.dump();
  const nlohmann::json early = command_state(early_id);
  EXPECT_EQ(early.value("name", ""), "early.json") << early.dump();
  EXPECT_EQ(early.value("state", ""), "done") << early.dump();
  EXPECT_GT(page_command("command=checkpoint&name=later"), early_id) << "an id used again";
  // ... and the page, in a browser, says so.
  std::string page_url = ReadFile(out + "/run/instructor.url");
  while (!page_url.empty() && std::isspace(static_cast<unsigned char>(page_url.back())))
    page_url.pop_back();
  Subprocess banner({"/usr/bin/env", "node", SourcePath("tests/browser/instructor_banner.mjs"),
                     page_url, "^RUNNING \\| STATION RESTARTED: its history recovered", "30"},
                    tmp + "/banner.log");
  EXPECT_EQ(banner.Wait(60), 0) << ReadFile(tmp + "/banner.log");
  const auto events = web.Get("/api/events?token=" + token);
  ASSERT_TRUE(events && events->status == 200);
  for (const char* said :
       {"freeze (from rms_control)", "REFUSED, cannot read checkpoint 'nothere.json'",
        "reset (from rms_control)", "STATION RESTARTED: its history recovered"})
    EXPECT_NE(events->body.find(said), std::string::npos) << said << "\n" << events->body;
  ASSERT_EQ(lab.Wait(240), 0) << ReadFile(tmp + "/lab.log");

  // Every command in the summary with its answers.
  const auto summary = nlohmann::json::parse(ReadFile(out + "/summary.json"));
  int refused = 0;
  for (const auto& c : summary["control"]) {
    EXPECT_FALSE(c["answers"].empty()) << c.dump();
    for (const auto& a : c["answers"]) refused += a["outcome"] == "refused";
  }
  // The missing, the bad and the unreachable checkpoint by both, a step.
  EXPECT_EQ(refused, 7) << summary["control"].dump();
  EXPECT_EQ(summary["control_answers_unmatched"], 0);

  // The debrief, in a browser.
  Subprocess debrief(
      {SourcePath("scripts/lab"), "debrief", out, "--no-build", "--port", "0", "--for", "200"},
      tmp + "/debrief.log");
  std::string url;
  ASSERT_TRUE(Until(
      [&] {
        url = DebriefUrl(tmp + "/debrief.log");
        return !url.empty();
      },
      60))
      << ReadFile(tmp + "/debrief.log");
  Subprocess browser(
      {"/usr/bin/env", "node", SourcePath("tests/browser/instructor_debrief.mjs"), url, tmp},
      tmp + "/browser.log");
  EXPECT_EQ(browser.Wait(180), 0) << ReadFile(tmp + "/browser.log");
  EXPECT_EQ(PngSize(tmp + "/instructor-1280x800.png"), std::make_pair(1280, 800));
  EXPECT_EQ(PngSize(tmp + "/instructor-390x844.png").first, 390);
  const std::string marks = ReadFile(out + "/instructor_marks.jsonl");
  EXPECT_NE(marks.find("debrief mark"), std::string::npos) << marks;
  debrief.Signal(SIGINT);
  EXPECT_EQ(debrief.Wait(30), 0) << ReadFile(tmp + "/debrief.log");
  const testing::ScriptRun report = testing::Script(
      {SourcePath("scripts/lab"), "report", out, "--no-build"}, tmp + "/report.log");
  EXPECT_EQ(report.rc, 0) << report.out;
  const std::string html = ReadFile(out + "/report.html");
  EXPECT_NE(html.find("<h2>The instructor's marks</h2>"), std::string::npos);
  EXPECT_NE(html.find("debrief mark"), std::string::npos);
  EXPECT_NE(html.find("<h2>Session control</h2>"), std::string::npos);
  EXPECT_NE(html.find("cannot read checkpoint"), std::string::npos);
}

// docs/lessons.md "From the instructor's station": a lesson given at start
// (--instructor-lesson) fires from the instructor's station -- a camera
// lost at 3 s, repaired on entering Mode 2 -- and one loaded on the page
// afterwards (POST /api/lesson) fires when its condition holds; a bad one
// is refused naming its key and changes nothing. The DCP takes each, the
// summary lists them as the instructor's, and the session re-simulates
// word for word.
TEST(InstructorStation, ALessonAtStartAndOneLoadedOnThePageFireAndReSimulate) {
  const std::string tmp = testing::MakeTempDir("instructor_lesson");
  const std::string out = tmp + "/session";
  std::ofstream(tmp + "/a.toml") << "[[events]]\nat_s = 3\ndo = \"malfunction camera 4 lost\"\n"
                                    "[[events]]\non_mode = 2\ndo = \"repair camera 4\"\n";
  // Refused at start: a lesson without --instructor, and a bad one.
  const auto alone =
      testing::Script({SourcePath("scripts/lab"), "demo", "--no-build", "--instructor-lesson",
                       tmp + "/a.toml", "--out", tmp + "/alone"},
                      tmp + "/alone.log", 60);
  EXPECT_EQ(alone.rc, 2) << alone.out;
  EXPECT_NE(alone.out.find("give --instructor too"), std::string::npos) << alone.out;
  std::ofstream(tmp + "/bad.toml") << "[[events]]\nat_s = 3\ndo = \"malfunction joint 9 stuck\"\n";
  const auto bad_file = testing::Script(
      {SourcePath("scripts/lab"), "demo", "--no-build", "--instructor", "0", "--instructor-lesson",
       tmp + "/bad.toml", "--out", tmp + "/bad", "--lcm-url", testing::UniqueLcmUrl(8670)},
      tmp + "/bad.log", 90);
  EXPECT_NE(bad_file.rc, 0) << bad_file.out;
  EXPECT_NE(bad_file.out.find("'events[0].do'"), std::string::npos) << bad_file.out;
  EXPECT_FALSE(fs::exists(tmp + "/bad/lcmlog")) << "a bad lesson's session ran";

  Subprocess lab({SourcePath("scripts/lab"),
                  "demo",
                  "--no-build",
                  "--out",
                  out,
                  "--lcm-url",
                  testing::UniqueLcmUrl(8680),
                  "--instructor",
                  "0",
                  "--instructor-lesson",
                  tmp + "/a.toml",
                  "--speed",
                  "2",
                  "--no-video",
                  "--png-every",
                  "0",
                  "--width",
                  "320",
                  "--height",
                  "240"},
                 tmp + "/lab.log", {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
  ASSERT_TRUE(testing::WaitForFile(out + "/run/instructor.url", 90)) << ReadFile(tmp + "/lab.log");
  int port = 0;
  std::string token;
  SplitUrl(ReadFile(out + "/run/instructor.url"), &port, &token);
  httplib::Client web("127.0.0.1", port);
  web.set_read_timeout(30, 0);
  const std::string auth = "?token=" + token;
  // Both of the first lesson's events fire (the second on entering Mode 2).
  nlohmann::json lesson;
  for (int i = 0; i < 1200; ++i) {
    const auto r = web.Get("/api/lesson" + auth);
    ASSERT_TRUE(r);
    lesson = nlohmann::json::parse(r->body);
    if (lesson["events"].size() == 2 && lesson["events"][1]["fired"].get<bool>()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(lesson["loaded"].get<bool>()) << lesson.dump();
  ASSERT_TRUE(lesson["events"][1]["fired"].get<bool>()) << lesson.dump();
  for (const auto& e : lesson["events"])  // what became of each event's command, as it was answered
    EXPECT_TRUE(Until(
        [&] {
          const auto r = web.Get("/api/lesson" + auth);
          if (!r) return false;
          const auto l = nlohmann::json::parse(r->body);
          for (const auto& x : l["events"])
            if (x["text"] == e["text"])
              return x.contains("outcome") && x["outcome"]["state"] == "done";
          return false;
        },
        10))
        << e.dump();
  EXPECT_GE(lesson["events"][0]["fired_at_s"].get<double>(), 3.0);
  // The station killed: restarted, it carries on with the lesson in force
  // (run/instructor_lesson.json), and fires none of its events again.
  {
    std::ifstream pid_file(out + "/run/instructor_station.pid");
    pid_t pid = 0;
    ASSERT_TRUE(pid_file >> pid) << "no run/instructor_station.pid";
    ASSERT_EQ(kill(pid, SIGKILL), 0);
    nlohmann::json again;
    for (int i = 0; i < 600; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      std::ifstream now(out + "/run/instructor_station.pid");
      pid_t p2 = 0;
      if (!(now >> p2) || p2 == pid) continue;
      const auto r = web.Get("/api/lesson" + auth);
      if (!r || r->status != 200) continue;
      again = nlohmann::json::parse(r->body);
      break;
    }
    ASSERT_TRUE(again.is_object()) << "the station did not come back";
    ASSERT_EQ(again["events"].size(), lesson["events"].size()) << again.dump();
    for (std::size_t i = 0; i < lesson["events"].size(); ++i)
      for (const char* key : {"text", "fired", "fired_at_s", "command_id"})
        EXPECT_EQ(again["events"][i][key], lesson["events"][i][key]) << key << again.dump();
  }
  // On the page: a bad lesson refused naming its key, the one in force kept...
  const auto refused =
      web.Post("/api/lesson" + auth, "name=b.toml&text=%5B%5Bevents%5D%5D%0Aat_s+%3D+1%0A",
               "application/x-www-form-urlencoded");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 400);
  EXPECT_NE(refused->body.find("'events[0].do': missing"), std::string::npos) << refused->body;
  EXPECT_EQ(nlohmann::json::parse(web.Get("/api/lesson" + auth)->body)["source"],
            out + "/instructor_lesson.toml");
  // ... and a good one taken, fired when the payload is within 5 ft of the port.
  const auto taken = web.Post("/api/lesson" + auth,
                              "name=near.toml&text=%5B%5Bevents%5D%5D%0Awhen+%3D+%22dock_distance_"
                              "ft+%3C+5%22%0Ado+%3D+%22malfunction+joint+6+slow+2%22%0A",
                              "application/x-www-form-urlencoded");
  ASSERT_TRUE(taken);
  EXPECT_EQ(taken->status, 200) << taken->body;
  EXPECT_NE(taken->body.find("near.toml"), std::string::npos) << taken->body;
  ASSERT_EQ(lab.Wait(300), 0) << ReadFile(tmp + "/lab.log");
  EXPECT_TRUE(fs::exists(out + "/instructor_lesson.toml"));

  const auto summary = nlohmann::json::parse(ReadFile(out + "/summary.json"));
  EXPECT_TRUE(summary["docked"].get<bool>());
  int from_instructor = 0;
  for (const auto& c : summary["control"]) from_instructor += c["process"] == "instructor_station";
  EXPECT_EQ(from_instructor, 3) << summary["control"].dump(1);
  const auto& mf = summary["malfunctions"];
  ASSERT_EQ(mf.size(), 3u) << mf.dump(1);
  EXPECT_EQ(mf[0]["injected"][0], "camera 4 lost");
  EXPECT_EQ(mf[1]["repaired"][0], "camera 4 lost");
  EXPECT_EQ(mf[2]["injected"][0], "joint 6 slow 2");
  const auto stats = nlohmann::json::parse(ReadFile(out + "/stats/instructor_station.json"));
  // (the restarted station's own run: the page's lesson's one event)
  EXPECT_EQ(stats["counters"].value("lesson.events", 0), 1);
  EXPECT_TRUE(summary["resimulation"]["exact"].get<bool>()) << summary["resimulation"].dump();
  // The debrief shows the lesson the session ended with, its event's outcome.
  Subprocess debrief(
      {SourcePath("scripts/lab"), "debrief", out, "--no-build", "--port", "0", "--for", "60"},
      tmp + "/debrief.log");
  nlohmann::json shown;
  EXPECT_TRUE(Until(
      [&] {
        const std::string url = DebriefUrl(tmp + "/debrief.log");
        if (url.empty()) return false;
        int debrief_port = 0;
        std::string debrief_token;
        SplitUrl(url, &debrief_port, &debrief_token);
        httplib::Client page("127.0.0.1", debrief_port);
        const auto r = page.Get("/api/lesson?token=" + debrief_token);
        if (!r || r->status != 200) return false;
        shown = nlohmann::json::parse(r->body);
        return true;
      },
      60))
      << ReadFile(tmp + "/debrief.log");
  EXPECT_NE(shown.value("source", "").find("near.toml"), std::string::npos) << shown.dump();
  ASSERT_EQ(shown["events"].size(), 1u) << shown.dump();
  EXPECT_EQ(shown["events"][0]["outcome"]["state"], "done") << shown.dump();
  debrief.Signal(SIGINT);
  EXPECT_EQ(debrief.Wait(30), 0) << ReadFile(tmp + "/debrief.log");
  fs::remove_all(tmp);
}

// The station's resident memory, kB (Linux /proc).
long RssKb(pid_t pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

// A TCP connection to 127.0.0.1:port from the loopback address `from`
// (another client as the station sees it); -1 when refused.
int ConnectFrom(const char* from, int port) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  inet_pton(AF_INET, from, &a.sin_addr);
  if (bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    close(fd);
    return -1;
  }
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
  if (connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

// True when the station has closed the connection (EOF or reset) within timeout_ms.
bool ClosedBy(int fd, int timeout_ms) {
  pollfd p{fd, POLLIN, 0};
  if (poll(&p, 1, timeout_ms) <= 0) return false;
  char b[256];
  return recv(fd, b, sizeof b, MSG_DONTWAIT) <= 0;
}

// docs/instructor.md "Bounds": a station with no session key (started by
// hand) hears anyone. 10,000 forged statuses of new processes, a flood of
// made-up restarts and a telemetry packet from the far future leave its
// memory flat and its answers small; 100 idle and 100 slow connections
// from other clients leave its page answering.
TEST(InstructorStation, StaysBoundedUnderForgedStatusesAndAnswersUnderIdleConnections) {
  const std::string tmp = testing::MakeTempDir("instructor-bounds");
  const std::string lcm_url = testing::UniqueLcmUrl(8700);
  const std::string token = "bounds-test-token-0123456789";
  const std::int64_t epoch_us = std::chrono::duration_cast<std::chrono::microseconds>(
                                    std::chrono::system_clock::now().time_since_epoch())
                                    .count();
  Subprocess station(
      {BuildPath("instructor_station/instructor_station"), "--lcm-url", lcm_url, "--port", "0",
       "--token", token, "--url-file", tmp + "/url", "--stats", tmp + "/stats.json"},
      tmp + "/station.log", {"RMSLAB_SESSION_EPOCH_US=" + std::to_string(epoch_us)});
  ASSERT_TRUE(testing::WaitForFile(tmp + "/url", 60)) << ReadFile(tmp + "/station.log");
  int port = 0;
  std::string got_token;
  SplitUrl(ReadFile(tmp + "/url"), &port, &got_token);
  ASSERT_EQ(got_token, token);
  httplib::Client web("127.0.0.1", port);
  web.set_read_timeout(10, 0);
  const std::string auth = "token=" + token;

  transport::LcmOptions lo;
  lo.url = lcm_url;
  transport::UdpLcm forger(lo);
  auto statuses = [&](int n, int counters, bool restarts) {
    for (int i = 0; i < n; ++i) {
      process_status_t m{};
      m.pid = restarts ? 1000 + i : 4242;
      forger.SetSender({0, sender_t::PROCESS_TOOL, m.pid});
      m.process = restarts ? "forged-" + std::to_string(i % 4) : "forged-" + std::to_string(i);
      m.host = "host";
      for (int k = 0; k < counters; ++k) {
        m.counter_names.push_back("latency." + std::string(80, 'x') + std::to_string(k) +
                                  ".p50_us");
        m.counter_values.push_back(k);
      }
      m.num_counters = static_cast<std::int16_t>(counters);
      transport::PublishMessage(forger, wire::channels::kStatus, m);
      if (i % 50 == 49) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  };
  statuses(500, 200, false);
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const long rss_before = RssKb(station.pid());
  statuses(10000, 200, false);
  // A name that is not the sender's: a tool claiming to be the DCP.
  {
    process_status_t m{};
    m.pid = 4242;
    forger.SetSender({0, sender_t::PROCESS_TOOL, 4242});
    m.process = "dynamics_proc";
    transport::PublishMessage(forger, wire::channels::kStatus, m);
  }
  statuses(12000, 0, true);
  // Telemetry from the far future: DOCKED, Mode 3.
  {
    dcp_telemetry_t t{};
    forger.SetSender({0, sender_t::PROCESS_DYNAMICS, 4243});
    t.frame = std::int64_t{1} << 40;
    t.mode = 3;
    t.docked = true;
    transport::PublishMessage(forger, wire::channels::kDcpTelemetry, t);
  }
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const long rss_after = RssKb(station.pid());
  std::printf("station RSS %ld kB after 500 forged statuses, %ld kB after 22,000 more\n",
              rss_before, rss_after);
  EXPECT_LT(rss_after - rss_before, 30 * 1024) << "kB";

  const auto status = web.Get("/api/status?" + auth);
  ASSERT_TRUE(status);
  ASSERT_EQ(status->status, 200);
  EXPECT_LT(status->body.size(), 256u * 1024) << "bytes";
  const auto sj = nlohmann::json::parse(status->body);
  EXPECT_LE(sj["processes"].size(), 16u);
  EXPECT_FALSE(sj["processes"].contains("dynamics_proc")) << sj["processes"].dump();
  EXPECT_TRUE(sj["dcp"].is_null()) << sj["dcp"].dump();  // the far-future packet refused
  const std::int64_t events = sj["events"].get<std::int64_t>();
  EXPECT_GT(events, 10500) << "the restarts heard";
  const auto ev = web.Get("/api/events?since=0&" + auth);
  ASSERT_TRUE(ev);
  const auto ej = nlohmann::json::parse(ev->body);
  ASSERT_FALSE(ej.empty());
  EXPECT_LE(ej.size(), 1000u);
  EXPECT_EQ(ej[0]["seq"].get<std::int64_t>(), events - 10000) << "the last 10,000 kept";

  // A body declared larger than a request may be: 413 at once.
  {
    const int fd = ConnectFrom("127.0.0.4", port);
    ASSERT_GE(fd, 0);
    const std::string head =
        "POST /api/control?" + auth + " HTTP/1.1\r\nHost: x\r\nContent-Length: 99999999999\r\n\r\n";
    ASSERT_EQ(send(fd, head.data(), head.size(), MSG_NOSIGNAL), static_cast<ssize_t>(head.size()));
    pollfd p{fd, POLLIN, 0};
    ASSERT_EQ(poll(&p, 1, 2000), 1) << "no answer within 2 s";
    char b[64] = {};
    ASSERT_GT(recv(fd, b, sizeof b - 1, 0), 12);
    EXPECT_EQ(std::string(b).substr(0, 12), "HTTP/1.1 413") << b;
    close(fd);
  }
  // 100 idle connections from one client, 100 slow ones from another.
  std::vector<int> idle, slow;
  for (int i = 0; i < 100; ++i) {
    if (int fd = ConnectFrom("127.0.0.2", port); fd >= 0) idle.push_back(fd);
    if (int fd = ConnectFrom("127.0.0.3", port); fd >= 0) {
      const char head[] = "GET /api/status HTTP/1.1\r\nHost: x\r\n";
      (void)send(fd, head, sizeof head - 1, MSG_NOSIGNAL);
      slow.push_back(fd);
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  const auto answered = web.Get("/api/status?" + auth);
  const double took_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(answered) << "no answer under 200 held connections";
  EXPECT_EQ(answered->status, 200);
  std::printf("answered in %.3f s beside %zu idle and %zu slow connections\n", took_s, idle.size(),
              slow.size());
  EXPECT_LT(took_s, 3.0);
  // One client holds at most 64: the rest are closed as they come.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  int closed_soon = 0;
  for (int fd : idle) closed_soon += ClosedBy(fd, 0);
  EXPECT_GE(closed_soon, 36) << "beyond 64 a client";
  // The idle ones are closed after 5 s of silence, header or not.
  std::this_thread::sleep_for(std::chrono::seconds(7));
  int closed_idle = 0, closed_slow = 0;
  for (int fd : idle) closed_idle += ClosedBy(fd, 100);
  for (int fd : slow) closed_slow += ClosedBy(fd, 100);
  EXPECT_EQ(closed_idle, static_cast<int>(idle.size()));
  EXPECT_EQ(closed_slow, static_cast<int>(slow.size()));
  for (int fd : idle) close(fd);
  for (int fd : slow) close(fd);

  station.Signal(SIGTERM);
  ASSERT_EQ(station.Wait(30), 0) << ReadFile(tmp + "/station.log");
  const auto stats = nlohmann::json::parse(ReadFile(tmp + "/stats.json"));
  EXPECT_GE(stats["counters"].value("dropped.status_refused", 0), 1);
  EXPECT_GE(stats["counters"].value("dropped.far_ahead", 0), 1);
}

}  // namespace
}  // namespace rms
