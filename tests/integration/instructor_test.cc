// The instructor's station as an instructor runs it (docs/instructor.md):
// `scripts/lab demo --instructor` prints the page's URL; the page, driven in
// the system's Chromium by puppeteer-core (tests/browser/instructor_page.mjs),
// shows live views that change as the arm moves, freezes, runs and resets
// the session, and shows a late viewer the events from the start; it injects
// a stuck joint and a lost camera station, which the DCP honours and the
// autopilot reports, and repairs them; the commands are in the session's log
// (summary.json "control" and "malfunctions") and re-simulate word for word. Requests without the
// token, or with bad parameters, are refused and counted; a second station
// cannot take the port.
#include <httplib.h>

#include <filesystem>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

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
  EXPECT_EQ(browser.Wait(180), 0) << ReadFile(tmp + "/browser.log");
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
  EXPECT_EQ(malfunctions, 2) << summary["control"].dump();
  EXPECT_EQ(repairs, 1) << summary["control"].dump();
  // The malfunctions as the DCP took them, with their times and frames: the
  // joint stuck, the camera lost, both repaired at once.
  const auto& mf = summary["malfunctions"];
  ASSERT_EQ(mf.size(), 3u) << mf.dump();
  EXPECT_NE(mf[0]["injected"][0].get<std::string>().find(" stuck"), std::string::npos) << mf.dump();
  EXPECT_EQ(mf[1]["injected"][0], "camera 1 lost") << mf.dump();
  EXPECT_EQ(mf[2]["repaired"].size(), 2u) << mf.dump();
  EXPECT_TRUE(mf[2]["in_force"].empty()) << mf.dump();
  for (std::size_t i = 1; i < mf.size(); ++i) {
    EXPECT_GE(mf[i]["time_s"].get<double>(), mf[i - 1]["time_s"].get<double>());
    EXPECT_GT(mf[i]["dcp_frame"].get<std::int64_t>(), mf[i - 1]["dcp_frame"].get<std::int64_t>());
  }
  const auto dcp = nlohmann::json::parse(ReadFile(out + "/stats/dynamics_proc.json"));
  EXPECT_EQ(dcp["counters"].value("control.malfunctions", 0), 2);
  EXPECT_EQ(dcp["counters"].value("control.repairs", 0), 1);
  // The reset began a second attempt, and the autopilot flew it to the dock.
  EXPECT_EQ(summary["attempts"].size(), 2u) << summary["attempts"].dump();
  const auto stats = nlohmann::json::parse(ReadFile(out + "/stats/instructor_station.json"));
  EXPECT_GT(stats["counters"].value("views.rendered", 0), 10);
  EXPECT_EQ(stats["counters"].value("http.refused", 0), 6);
  EXPECT_EQ(stats["counters"].value("control.sent", 0), 6);
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

}  // namespace
}  // namespace rms
