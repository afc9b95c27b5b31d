// The instructor's station as an instructor runs it (docs/instructor.md):
// `scripts/lab demo --instructor` prints the page's URL; the page, driven in
// the system's Chromium by puppeteer-core (tests/browser/instructor_page.mjs),
// shows live views that change as the arm moves, freezes, runs and resets
// the session, and shows a late viewer the events from the start; the commands
// are in the session's log (summary.json "control"). Requests without the
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
  // not UTF-8: anyone with the session's id can send one.
  {
    const auto manifest = nlohmann::json::parse(ReadFile(out + "/manifest.json"));
    transport::LcmOptions lo;
    lo.url = lcm_url;
    transport::UdpLcm forger(lo);
    forger.SetSender({transport::ParseSessionId(manifest["session_id"], "session_id"),
                      sender_t::PROCESS_TOOL, 4242});
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
  int freezes = 0, runs = 0, resets = 0;
  for (const auto& c : summary["control"]) {
    EXPECT_EQ(c["process"], "instructor_station") << c.dump();
    freezes += c["command"] == "freeze";
    runs += c["command"] == "run";
    resets += c["command"] == "reset";
  }
  EXPECT_EQ(freezes, 1) << summary["control"].dump();
  EXPECT_EQ(runs, 1) << summary["control"].dump();
  EXPECT_EQ(resets, 1) << summary["control"].dump();
  // The reset began a second attempt, and the autopilot flew it to the dock.
  EXPECT_EQ(summary["attempts"].size(), 2u) << summary["attempts"].dump();
  const auto stats = nlohmann::json::parse(ReadFile(out + "/stats/instructor_station.json"));
  EXPECT_GT(stats["counters"].value("views.rendered", 0), 10);
  EXPECT_EQ(stats["counters"].value("http.refused", 0), 5);
  EXPECT_EQ(stats["counters"].value("control.sent", 0), 3);
  const auto op = nlohmann::json::parse(ReadFile(out + "/stats/operator_station.json"));
  EXPECT_EQ(op["counters"].value("control.resets", 0), 1);
  // What the page did re-simulates word for word.
  const testing::ScriptRun resim = testing::Script(
      {SourcePath("scripts/lab"), "resim", out, "--no-build", "--out", tmp + "/resim"},
      tmp + "/resim.log");
  EXPECT_EQ(resim.rc, 0) << resim.out;
  EXPECT_NE(resim.out.find("identical, word for word"), std::string::npos) << resim.out;
}

}  // namespace
}  // namespace rms
