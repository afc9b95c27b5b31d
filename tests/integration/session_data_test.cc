// Every session is data (docs/sessions.md "Re-simulation", "Attempts"):
// a session flown by hand in a real terminal, on a machine whose every core
// is busy, with a reset, a checkpoint restored, the DCP killed and
// restarted, and a freeze, re-simulates word for word; its summary lists
// every attempt; a log that misses the session's start re-simulates from
// the DCP's state logged later, and one that lacks every state says so.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "rms/dcp_state_t.hpp"

#include "cpu_load.h"
#include "lab_processes.h"
#include "session_files.h"
#include "subprocess.h"
#include "tmux.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::Script;
using testing::ScriptRun;
using testing::SourcePath;
using testing::Subprocess;
using testing::Tmux;

void Sleep(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

bool WaitFor(const std::function<bool()>& done, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    Sleep(0.1);
  }
  return done();
}

int PidOf(const std::string& out, const std::string& process) {
  std::ifstream f(out + "/run/" + process + ".pid");
  int pid = 0;
  return (f >> pid) ? pid : -1;
}

ScriptRun Control(const std::string& out, const std::vector<std::string>& args,
                  const std::string& log) {
  std::vector<std::string> cmd = {SourcePath("scripts/lab"), "control", "--session", out};
  cmd.insert(cmd.end(), args.begin(), args.end());
  return Script(cmd, log, 60);
}

// Copies SESSION to DIR with only the log events `keep` says yes to.
void CopyWithLog(const std::string& from, const std::string& to,
                 const std::function<bool(const lcm::LogEvent&, std::int64_t first_us)>& keep) {
  fs::create_directories(to);
  for (const char* f : {"manifest.json", "config.toml"})
    fs::copy_file(from + "/" + f, to + "/" + f);
  fs::copy(from + "/run", to + "/run", fs::copy_options::recursive);
  lcm::LogFile in(from + "/lcmlog", "r"), out(to + "/lcmlog", "w");
  std::int64_t first = -1;
  while (const lcm::LogEvent* ev = in.readNextEvent()) {
    if (first < 0) first = ev->timestamp;
    if (keep(*ev, first)) out.writeEvent(const_cast<lcm::LogEvent*>(ev));
  }
}

// A design's cell: rms_resim SESSION --set DESIGN REST --result-json, its
// stdout alone (REST: --discard, or --out DIR).
ScriptRun CellOf(const std::string& session, const std::string& design, const std::string& rest,
                 const std::string& log) {
  std::string cmd = "'";
  cmd.append(testing::BuildPath("tools/rms_resim")).append("' '").append(session);
  cmd.append("' --set ").append(design).append(" ").append(rest);
  cmd.append(" --result-json --quiet 2>/dev/null");
  return Script({"/bin/sh", "-c", cmd}, log);
}

class HandFlownSession : public ::testing::Test {
 protected:
  // Flown once, by hand in tmux, under CPU load; shared by the tests that read it.
  static void SetUpTestSuite() {
    tmp_ = new std::string(testing::MakeTempDir("handflown"));
    out_ = new std::string(*tmp_ + "/session");
    testing::CpuLoad load(*tmp_);
    Tmux tmux(*tmp_);
    const std::string cmd =
        "RMSLAB_BUILD=" RMSLAB_BUILD_DIR " " + SourcePath("scripts/lab") +
        " demo --by-hand --no-build --out " + *out_ + " --lcm-url '" + testing::UniqueLcmUrl(9700) +
        "' --png-every 0 --no-video --width 160 --height 120 --subject ann --note 'first try' >" +
        *tmp_ + "/lab.log 2>&1; echo $? >" + *tmp_ + "/lab.rc.tmp; mv " + *tmp_ + "/lab.rc.tmp " +
        *tmp_ + "/lab.rc";  // whole when it is there (a loaded machine read it empty)
    ASSERT_EQ(tmux.Start(cmd, 120, 45), 0);
    const std::string op_log = *out_ + "/logs/operator_station.log";
    ASSERT_TRUE(WaitFor(
                    [&] {
                      return (PidOf(*out_, "operator_station") > 0 && fs::exists(op_log)) ||
                             fs::exists(*tmp_ + "/lab.rc");
                    },
                    90) &&
                !fs::exists(*tmp_ + "/lab.rc"))
        << ReadFile(*tmp_ + "/lab.log");
    Sleep(2.0);
    auto press = [&](const std::string& key, int n, double each_s) {
      for (int i = 0; i < n; ++i) {
        tmux.Send({key});
        Sleep(each_s);
      }
    };
    press("w", 4, 0.3);  // attempt 1: away from the start
    press("d", 3, 0.3);
    Sleep(1.0);
    press("BSpace", 1, 1.0);  // reset: attempt 2
    press("s", 3, 0.3);
    ASSERT_EQ(Control(*out_, {"checkpoint", "cp1"}, *tmp_ + "/cp.log").rc, 0)
        << ReadFile(*tmp_ + "/cp.log");
    press("a", 4, 0.3);
    ASSERT_EQ(Control(*out_, {"restore", "cp1", "--run"}, *tmp_ + "/restore.log").rc, 0)
        << ReadFile(*tmp_ + "/restore.log");  // attempt 3
    press("w", 2, 0.3);
    const int dcp = PidOf(*out_, "dynamics_proc");
    ASSERT_GT(dcp, 0);
    kill(dcp, SIGKILL);  // the launcher restarts it; it resumes its last state
    ASSERT_TRUE(WaitFor(
        [&] { return PidOf(*out_, "dynamics_proc") > 0 && PidOf(*out_, "dynamics_proc") != dcp; },
        60));
    Sleep(2.0);
    press("d", 3, 0.3);
    press("p", 1, 1.5);  // freeze, a step, run
    press("period", 1, 0.5);
    press("p", 1, 1.0);
    // The same from the session's control: freeze, three steps, run.
    ASSERT_EQ(Control(*out_, {"freeze"}, *tmp_ + "/freeze.log").rc, 0)
        << ReadFile(*tmp_ + "/freeze.log");
    ASSERT_EQ(Control(*out_, {"step", "3"}, *tmp_ + "/step.log").rc, 0)
        << ReadFile(*tmp_ + "/step.log");
    ASSERT_EQ(Control(*out_, {"run"}, *tmp_ + "/run.log").rc, 0) << ReadFile(*tmp_ + "/run.log");
    press("e", 2, 0.3);
    press("Q", 1, 0.5);
    ASSERT_TRUE(WaitFor([&] { return fs::exists(*tmp_ + "/lab.rc"); }, 120))
        << ReadFile(*tmp_ + "/lab.log");
    EXPECT_EQ(ReadFile(*tmp_ + "/lab.rc"), "0\n") << ReadFile(*tmp_ + "/lab.log");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*tmp_);
    delete tmp_;
    delete out_;
  }
  static std::string* tmp_;
  static std::string* out_;
};
std::string* HandFlownSession::tmp_ = nullptr;
std::string* HandFlownSession::out_ = nullptr;

TEST_F(HandFlownSession, ReSimulatesWordForWord) {
  const ScriptRun r =
      Script({SourcePath("scripts/lab"), "resim", *out_, "--no-build"}, *tmp_ + "/resim.log", 120);
  EXPECT_EQ(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("identical, word for word"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("note:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("the DCP's whole state agreed"), std::string::npos) << r.out;
}

// A design's cell made in memory (--discard: session::SummarizeDcpRun) is
// the cell made from its session written and summarised, over a session
// with a reset, a restore and a restarted DCP.
TEST_F(HandFlownSession, AnotherDesignsCellMadeInMemoryIsTheWrittenSessionsCell) {
  for (const std::string design : {"dcp.tpob_ft=0.4", "arm.upper_boom_ft=19"}) {
    SCOPED_TRACE(design);
    const std::string dir = *tmp_ + "/design-" + design;
    auto run = [&](const std::string& rest, const std::string& log) {
      return CellOf(*out_, design, rest, log);
    };
    const ScriptRun memory = run("--discard", dir + "-memory.log");
    const ScriptRun written = run("--out '" + dir + "'", dir + "-written.log");
    ASSERT_EQ(written.rc, 0) << written.out;
    EXPECT_EQ(memory.rc, 0);
    EXPECT_EQ(memory.out, written.out);
    const auto summary = nlohmann::json::parse(ReadFile(dir + "/summary.json"));
    std::set<std::string> starts;
    for (const auto& a : summary["attempts"]) starts.insert(a["started_by"].get<std::string>());
    EXPECT_EQ(starts, (std::set<std::string>{"start", "reset", "restore"})) << summary["attempts"];
  }
}

// The same over a forged log: a second RESTORE to the DCP's checkpoint
// logged just before its last frame, so the re-simulated DCP makes frames it made
// already (the summary's own rules for repeated frames and restores apply).
TEST_F(HandFlownSession, ARestoreLoggedAgainGivesTheSameCellInMemoryAsWritten) {
  struct Event {
    std::int64_t timestamp;
    std::string channel;
    std::vector<std::uint8_t> data;
  };
  std::vector<Event> events;
  {
    lcm::LogFile in(*out_ + "/lcmlog", "r");
    while (const lcm::LogEvent* ev = in.readNextEvent()) {
      const auto* d = static_cast<const std::uint8_t*>(ev->data);
      events.push_back({ev->timestamp, ev->channel, {d, d + ev->datalen}});
    }
  }
  std::size_t restore = events.size(), last_frame = events.size();
  for (std::size_t i = 0; i < events.size(); ++i) {
    const Event& e = events[i];
    if (e.channel.rfind("RMS_DCP_FRAME", 0) == 0) last_frame = i;
    rms::dcp_state_t m;
    if (restore == events.size() && e.channel.rfind("RMS_DCP_STATE", 0) == 0 &&
        m.decode(e.data.data(), 0, static_cast<int>(e.data.size())) > 0 &&
        m.reason == rms::dcp_state_t::RESTORE)
      restore = i;
  }
  ASSERT_LT(restore, events.size()) << "the session has no restore";
  ASSERT_LT(restore, last_frame);
  // A second restore (sent later: not the network's copy of the first,
  // which the re-simulation would take as the first one's).
  Event again = events[restore];
  again.timestamp = events[last_frame - 1].timestamp;
  {
    rms::dcp_state_t m;
    ASSERT_GT(m.decode(again.data.data(), 0, static_cast<int>(again.data.size())), 0);
    m.send_time_us += again.timestamp - events[restore].timestamp;
    again.data.resize(static_cast<std::size_t>(m.getEncodedSize()));
    ASSERT_GT(m.encode(again.data.data(), 0, static_cast<int>(again.data.size())), 0);
    testing::TagAsTheSession(*out_, again.channel, &again.data);  // the DCP's, as it would send it
  }
  events.insert(events.begin() + static_cast<std::ptrdiff_t>(last_frame), again);
  const std::string forged = *tmp_ + "/forged";
  fs::copy(*out_, forged, fs::copy_options::recursive);
  {
    lcm::LogFile out(forged + "/lcmlog", "w");
    for (Event& e : events) {
      lcm::LogEvent ev{};
      ev.timestamp = e.timestamp;
      ev.channel = e.channel;
      ev.datalen = static_cast<std::int32_t>(e.data.size());
      ev.data = e.data.data();
      out.writeEvent(&ev);
    }
  }
  for (const std::string design : {"dcp.dock_distance_ft=0.01", "arm.upper_boom_ft=21.5"}) {
    SCOPED_TRACE(design);
    const std::string dir = *tmp_ + "/forged-" + design;
    auto run = [&](const std::string& rest, const std::string& log) {
      return CellOf(forged, design, rest, log);
    };
    const ScriptRun memory = run("--discard", dir + "-memory.log");
    const ScriptRun written = run("--out '" + dir + "'", dir + "-written.log");
    ASSERT_EQ(written.rc, 0) << written.out;
    EXPECT_EQ(memory.out, written.out);
    // The restore was taken: frames the DCP had made are in its new log again.
    const auto summary = nlohmann::json::parse(ReadFile(dir + "/summary.json"));
    EXPECT_GT(summary["ignored"]["total"].get<int>(), 0) << summary["ignored"];
  }
}

TEST_F(HandFlownSession, TheSummaryListsEveryAttempt) {
  const auto s = nlohmann::json::parse(ReadFile(*out_ + "/summary.json"));
  ASSERT_TRUE(s.contains("attempts")) << s.dump(2).substr(0, 2000);
  const auto& a = s["attempts"];
  ASSERT_GE(a.size(), 3u) << a.dump(2);
  EXPECT_EQ(a[0]["started_by"], "start");
  EXPECT_EQ(a[1]["started_by"], "reset");
  EXPECT_EQ(a[2]["started_by"], "restore");
  double total = 0;
  for (const auto& x : a) {
    EXPECT_TRUE(x.contains("phase_durations_s"));
    EXPECT_TRUE(x.contains("scorecard"));
    EXPECT_GE(x["duration_s"].get<double>(), 0.0);
    total += x["duration_s"].get<double>();
  }
  EXPECT_NEAR(total, s["totals"]["duration_s"].get<double>(), 0.2);
  EXPECT_GE(s["totals"]["resets"].get<int>(), 1);
  EXPECT_GE(s["totals"]["restores"].get<int>(), 1);
  EXPECT_GE(s["totals"]["restarts"].get<int>(), 1);
  const auto m = nlohmann::json::parse(ReadFile(*out_ + "/manifest.json"));
  EXPECT_EQ(m["subject"], "ann");
  EXPECT_EQ(m["note"], "first try");
}

// Every time field of summary.json is session time at full precision
// (docs/sessions.md "Session time"): none is seconds since 1970 nor rounded;
// the freeze, each of three steps and the run read successive frames.
void CheckTimes(const nlohmann::json& j, const std::string& at, double rate_hz, bool time = false) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) {
      const bool t = time || (k.size() > 2 && k.compare(k.size() - 2, 2, "_s") == 0);
      CheckTimes(v, std::string(at).append(".").append(k), rate_hz, t);
    }
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i)
      CheckTimes(j[i], at + "[" + std::to_string(i) + "]", rate_hz, time);
  } else if (time && j.is_number()) {
    const double v = j.get<double>();
    EXPECT_LT(std::abs(v), 1e6) << at << " = " << v << ": seconds since 1970?";
  }
}

TEST_F(HandFlownSession, EveryTimeIsSessionTimeAtFullPrecision) {
  const auto s = nlohmann::json::parse(ReadFile(*out_ + "/summary.json"));
  const double rate = 30.0;
  CheckTimes(s, "summary", rate);
  // Frame times at full precision: frames over the rate, exactly.
  auto on_a_frame = [&](double t_s) {
    return std::abs(t_s * rate - std::round(t_s * rate)) < 1e-6;
  };
  std::vector<std::pair<std::string, double>> control;
  for (const auto& c : s["control"]) {
    ASSERT_TRUE(c["time_s"].is_number()) << c.dump();
    EXPECT_TRUE(on_a_frame(c["time_s"].get<double>())) << c.dump();
    EXPECT_TRUE(c["wall_s"].is_number()) << c.dump();
    control.emplace_back(c["command"].get<std::string>(), c["time_s"].get<double>());
  }
  for (const auto& m : s["mode_changes"]) EXPECT_TRUE(on_a_frame(m["time_s"].get<double>()));
  for (const auto& a : s["attempts"]) EXPECT_TRUE(on_a_frame(a["start_s"].get<double>()));
  // freeze at frame F, a step of three frames (one command: docs/protocol.md
  // "RMS_CONTROL"), run at F + 3: the session stood still but for the steps.
  // (the last freeze: scripts/lab control's, after the station's keys)
  const auto last = std::find_if(control.rbegin(), control.rend(),
                                 [](const auto& c) { return c.first == "freeze"; });
  ASSERT_NE(last, control.rend()) << s["control"].dump();
  const auto freeze = std::prev(last.base());
  ASSERT_GE(control.end() - freeze, 3) << s["control"].dump();
  EXPECT_EQ(freeze[1].first, "step") << s["control"].dump();
  EXPECT_GE(freeze[1].second, freeze[0].second - 1e-9) << s["control"].dump();
  EXPECT_LT(freeze[1].second, freeze[0].second + 1.0 / rate - 1e-9) << s["control"].dump();
  const auto& step = s["control"][static_cast<std::size_t>(freeze + 1 - control.begin())];
  EXPECT_EQ(step.value("name", ""), "3") << step.dump();
  ASSERT_EQ(step["answers"].size(), 1u) << step.dump();
  EXPECT_EQ(step["answers"][0]["outcome"], "done") << step.dump();
  EXPECT_EQ(freeze[2].first, "run");
  EXPECT_NEAR(freeze[2].second - freeze[0].second, 3.0 / rate, 1e-9) << s["control"].dump();
  EXPECT_GT(s["wall_duration_s"].get<double>(), s["duration_s"].get<double>() - 1.0);
  // The CSV's DCP rows: the frame they answer and its session time.
  const std::string csv = *tmp_ + "/csv_times";
  ASSERT_EQ(Script({SourcePath("scripts/lab"), "export", *out_, "--no-build", "--out", csv},
                   *tmp_ + "/export_times.log")
                .rc,
            0);
  std::ifstream rows(csv + "/dcp_frame.csv");
  std::string line;
  std::getline(rows, line);
  int checked = 0;
  while (std::getline(rows, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    ASSERT_GE(cells.size(), 5u);
    EXPECT_EQ(std::stod(cells[1]), std::stoll(cells[4]) / rate)
        << line;  // session_time, input_frame
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST_F(HandFlownSession, ALogThatMissesTheStartReSimulatesFromALaterState) {
  // The recorder started 6 s late: the DCP's start and its first states are
  // not in the log; the first periodic state (every 5 s of frames) is.
  const std::string late = *tmp_ + "/late";
  CopyWithLog(*out_, late, [](const lcm::LogEvent& ev, std::int64_t first) {
    return ev.timestamp - first > 6000000;
  });
  const ScriptRun r =
      Script({SourcePath("scripts/lab"), "resim", late, "--no-build"}, *tmp_ + "/late.log", 120);
  EXPECT_EQ(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("identical, word for word"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not re-simulated: the log starts at DCP frame"), std::string::npos)
      << r.out;
}

TEST_F(HandFlownSession, ALogWithoutTheDcpsStateSaysWhatIsMissing) {
  const std::string bare = *tmp_ + "/bare";
  CopyWithLog(*out_, bare, [](const lcm::LogEvent& ev, std::int64_t first) {
    return ev.timestamp - first > 3000000 && ev.channel.rfind("RMS_DCP_STATE", 0) != 0;
  });
  const ScriptRun r =
      Script({SourcePath("scripts/lab"), "resim", bare, "--no-build"}, *tmp_ + "/bare.log", 120);
  EXPECT_NE(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("holds no RMS_DCP_STATE"), std::string::npos) << r.out;
}

// The DOM a real browser (headless Chromium) makes of a page, its scripts run.
std::string BrowserDom(const std::string& page, const std::string& out) {
  Subprocess chrome({"/usr/bin/chromium", "--headless=new", "--no-sandbox", "--disable-gpu",
                     "--virtual-time-budget=8000", "--dump-dom", "file://" + page},
                    out);
  EXPECT_EQ(chrome.Wait(120), 0);
  return ReadFile(out);
}

int ChartsRendered(const std::string& dom) {
  const auto at = dom.find("data-charts-rendered=\"");
  return at == std::string::npos ? -1 : std::atoi(dom.c_str() + at + 22);
}

// The report's embedded data (window.RMS_REPORT = {...};).
nlohmann::json ReportData(const std::string& html) {
  const std::string key = "window.RMS_REPORT = ";
  const auto a = html.find(key);
  if (a == std::string::npos) return nullptr;
  const auto b = html.find(";\n</script>", a);
  std::string j = html.substr(a + key.size(), b - a - key.size());
  for (std::size_t p = j.find("<\\/"); p != std::string::npos; p = j.find("<\\/", p))
    j.replace(p, 3, "</");
  return nlohmann::json::parse(j);
}

TEST_F(HandFlownSession, ItsReportShowsEveryAttemptThePathAndTheTimeline) {
  const std::string page = *tmp_ + "/report.html";
  const ScriptRun r = Script({SourcePath("scripts/lab"), "report", *out_, "--out", page},
                             *tmp_ + "/report.log", 120);
  ASSERT_EQ(r.rc, 0) << r.out;
  const std::string html = ReadFile(page);
  for (const char* want :
       {"<h2>Attempts</h2>", "The operator's scorecard", "The configuration's tolerances",
        "<td>reset</td>", "<td>restore", "ann", "first try", "Frames", "Losses and refusals"}) {
    EXPECT_NE(html.find(want), std::string::npos) << want;
  }
  EXPECT_EQ(html.find("<pre>"), std::string::npos) << "raw JSON in the report";
  EXPECT_EQ(html.find("<script src="), std::string::npos) << "not self-contained";
  const nlohmann::json d = ReportData(html);
  ASSERT_TRUE(d.is_object());
  const auto& goal = d["series"]["distance_to_goal_ft"];
  ASSERT_GT(goal.size(), 10u);
  for (const auto& g : goal) ASSERT_GE(g.get<double>(), 0.0) << "a signed distance";
  ASSERT_EQ(d["series"]["p_ft"].size(), goal.size());
  // By hand the inputs are plotted as the rates commanded, each column with
  // its unit: the terminal's coarse presses fly at the full 2 ft/s (not a
  // deflection of -1..1), no faster.
  const auto& inputs = d["series"]["inputs"];
  ASSERT_TRUE(inputs.is_object()) << "by hand: the inputs are plotted";
  ASSERT_EQ(inputs["names"].size(), inputs["units"].size());
  ASSERT_EQ(inputs["names"].size(), 7u) << inputs["names"].dump();
  for (int k = 0; k < 7; ++k)
    EXPECT_EQ(inputs["units"][k], k < 3 ? "ft/s" : "deg/s") << inputs["names"][k];
  double fastest_ft_s = 0.0;
  for (const auto& row : inputs["values"])
    for (int k = 0; k < 3; ++k)
      fastest_ft_s = std::max(fastest_ft_s, std::abs(row[k].get<double>()));
  EXPECT_GT(fastest_ft_s, 1.0) << "the presses' 2 ft/s plotted as a deflection";
  EXPECT_LE(fastest_ft_s, 2.0 + 1e-9);
  std::set<std::string> kinds;
  for (const auto& e : d["events"]) kinds.insert(e["kind"].get<std::string>());
  for (const char* k : {"reset", "restore", "freeze", "restart"})
    EXPECT_TRUE(kinds.count(k)) << k << " not in the timeline";
  EXPECT_GE(d["attempts"].size(), 3u);
  // A freeze is session time standing still: a point on the session's axis
  // with its wall length said, never a stall (docs/sessions.md "Report").
  const auto summary = nlohmann::json::parse(ReadFile(*out_ + "/summary.json"));
  std::size_t collisions = 0;
  double shortest_freeze_s = 1e9;
  for (const auto& e : d["events"]) {
    if (e["kind"] == "freeze") {
      EXPECT_FALSE(e.contains("duration_s")) << e.dump();
      const std::string text = e["text"].get<std::string>();
      EXPECT_NE(text.find("of wall time"), std::string::npos) << e.dump();
      if (text.rfind("frozen ", 0) == 0)
        shortest_freeze_s = std::min(shortest_freeze_s, std::stod(text.substr(7)));
    }
    collisions += e["kind"] == "collision";
  }
  // A stall the report names (a loaded machine may stall the station a
  // few hundred ms) is shorter than every freeze: no freeze was read as one.
  const std::string said = "outside a freeze: ";
  if (const auto at = html.find(said); at != std::string::npos) {
    const double stall_s = std::stod(html.substr(at + said.size())) / 1000;
    EXPECT_LT(stall_s, shortest_freeze_s) << "a freeze read as a stall";
  }
  // One set of collisions: the timeline's are the summary's.
  EXPECT_EQ(collisions, summary["collisions"].size()) << summary["collisions"].dump();
  const std::string dom = BrowserDom(page, *tmp_ + "/report_dom.html");
  EXPECT_GE(ChartsRendered(dom), 6) << dom.substr(0, 1500);
  for (const char* want :
       {"End effector path", "Joint angles", "Operator inputs", "Event timeline"}) {
    EXPECT_NE(dom.find(want), std::string::npos) << want;
  }
}

TEST_F(HandFlownSession, CompareShowsTheSubjectsLearningCurveAndAReSimulationApart) {
  // A second session of the same subject (a timeline), and the first flown
  // again with another design (a re-simulation: a session of its own).
  const std::string second = *tmp_ + "/second";
  const ScriptRun s2 = Script(
      {SourcePath("scripts/lab"), "demo", "--no-build", "--out", second, "--timeline",
       SourcePath("scripts/timelines/short.tl"), "--lcm-url", testing::UniqueLcmUrl(9750),
       "--png-every", "0", "--no-video", "--width", "160", "--height", "120", "--subject", "ann"},
      *tmp_ + "/second.log", 120);
  ASSERT_EQ(s2.rc, 0) << s2.out;
  const std::string wide = *tmp_ + "/wide.toml";
  {
    std::string cfg = ReadFile(*out_ + "/config.toml");
    const auto at = cfg.find("dock_distance_ft");
    ASSERT_NE(at, std::string::npos);
    cfg.replace(at, cfg.find('\n', at) - at, "dock_distance_ft = 0.5");
    std::ofstream(wide) << cfg;
  }
  const ScriptRun rs = Script({SourcePath("scripts/lab"), "resim", *out_, "--no-build", "--config",
                               wide, "--out", *tmp_ + "/wide"},
                              *tmp_ + "/wide.log", 120);
  ASSERT_EQ(rs.rc, 0) << rs.out;
  const ScriptRun c = Script({SourcePath("scripts/lab"), "compare", *out_, second, *tmp_ + "/wide",
                              "--no-build", "--out", *tmp_ + "/compare"},
                             *tmp_ + "/compare.log", 120);
  ASSERT_EQ(c.rc, 0) << c.out;
  const std::string csv = ReadFile(*tmp_ + "/compare/compare.csv");
  std::istringstream rows(csv);
  std::string line;
  std::getline(rows, line);
  EXPECT_NE(line.find("task_time_s"), std::string::npos) << line;
  int hand_rows = 0, second_rows = 0, resim_rows = 0;
  while (std::getline(rows, line)) {
    hand_rows += line.rfind("session,", 0) == 0;
    second_rows += line.rfind("second,", 0) == 0;
    resim_rows += line.rfind("wide,", 0) == 0 && line.find("re-simulation") != std::string::npos;
  }
  const auto summary = nlohmann::json::parse(ReadFile(*out_ + "/summary.json"));
  EXPECT_EQ(hand_rows, static_cast<int>(summary["attempts"].size())) << csv;  // a row an attempt
  EXPECT_EQ(second_rows, 1) << csv;
  EXPECT_EQ(resim_rows, hand_rows) << csv;
  const std::string html = ReadFile(*tmp_ + "/compare/compare.html");
  const auto a = html.find("window.RMS_COMPARE = ");
  ASSERT_NE(a, std::string::npos);
  const auto data =
      nlohmann::json::parse(html.substr(a + 21, html.find(";\n</script>", a) - a - 21));
  // The flown session's result is its last attempt, which began with a
  // restore: flagged, and no trial for the learning curve unless asked.
  ASSERT_TRUE(data["subjects"].contains("ann")) << data["subjects"].dump();
  EXPECT_EQ(data["subjects"]["ann"].size(), 1u)
      << "the subject's fresh trial only: not the restored attempt, not the re-simulation";
  EXPECT_EQ(data["left_off"], nlohmann::json::array({"session"})) << data["left_off"].dump();
  EXPECT_EQ(data["no_attempt"], nlohmann::json::array()) << data["no_attempt"].dump();
  EXPECT_NE(html.find("(from a restore)"), std::string::npos);
  EXPECT_NE(csv.find(",restore,"), std::string::npos) << csv;
  const std::string dom = BrowserDom(*tmp_ + "/compare/compare.html", *tmp_ + "/compare_dom.html");
  EXPECT_GE(ChartsRendered(dom), 2) << dom.substr(0, 1500);
  // A session whose log holds no flight (empty) has no attempt: said as
  // such, not as a restore.
  const std::string empty = *tmp_ + "/empty";
  fs::create_directories(empty);
  for (const char* f : {"config.toml", "manifest.json"})
    fs::copy_file(second + "/" + f, empty + "/" + f);
  std::ofstream(empty + "/lcmlog").close();
  ASSERT_EQ(Script({testing::BuildPath("tools/rms_session"), "summary", empty},
                   *tmp_ + "/empty_summary.log")
                .rc,
            0);
  const ScriptRun ce = Script({SourcePath("scripts/lab"), "compare", second, empty, "--no-build",
                               "--out", *tmp_ + "/compare_empty"},
                              *tmp_ + "/compare_empty.log", 120);
  ASSERT_EQ(ce.rc, 0) << ce.out;
  const std::string html_empty = ReadFile(*tmp_ + "/compare_empty/compare.html");
  EXPECT_NE(html_empty.find("No attempt in the summary of empty"), std::string::npos);
  EXPECT_EQ(html_empty.find("Left off the learning curves"), std::string::npos);
  const ScriptRun all =
      Script({SourcePath("scripts/lab"), "compare", *out_, second, *tmp_ + "/wide", "--no-build",
              "--all-trials", "--out", *tmp_ + "/compare_all"},
             *tmp_ + "/compare_all.log", 120);
  ASSERT_EQ(all.rc, 0) << all.out;
  const std::string html_all = ReadFile(*tmp_ + "/compare_all/compare.html");
  const auto b = html_all.find("window.RMS_COMPARE = ");
  const auto data_all =
      nlohmann::json::parse(html_all.substr(b + 21, html_all.find(";\n</script>", b) - b - 21));
  EXPECT_EQ(data_all["subjects"]["ann"].size(), 2u) << "asked for: the two sessions";
}

TEST_F(HandFlownSession, ItsMcapExportHoldsEveryMessageAndEachMatchesItsSchema) {
  const std::string mcap = *tmp_ + "/session.mcap";
  const ScriptRun r =
      Script({SourcePath("scripts/lab"), "export", *out_, "--mcap", "--out", mcap, "--no-build"},
             *tmp_ + "/mcap.log", 120);
  ASSERT_EQ(r.rc, 0) << r.out;
  // Read back with the MCAP library, every message validated against its
  // channel's JSON schema (tools/mcap/check_mcap.mjs: @mcap/core, ajv).
  Subprocess check({"/usr/bin/node", SourcePath("tools/mcap/check_mcap.mjs"), mcap},
                   *tmp_ + "/mcap_check.log");
  ASSERT_EQ(check.Wait(120), 0) << ReadFile(*tmp_ + "/mcap_check.log");
  const std::string out = ReadFile(*tmp_ + "/mcap_check.log");
  const auto j =
      nlohmann::json::parse(out.substr(out.find('{'), out.rfind('}') - out.find('{') + 1));
  EXPECT_EQ(j["invalid"], 0);
  const auto summary = nlohmann::json::parse(ReadFile(*out_ + "/summary.json"));
  for (const char* ch :
       {"RMS_OPERATOR_INPUT", "RMS_OPERATOR_STATE", "RMS_DCP_FRAME", "RMS_DCP_TELEMETRY",
        "RMS_DCP_STATE", "RMS_ESG_FRAME", "RMS_STATUS", "RMS_CONTROL"}) {
    ASSERT_TRUE(j["channels"].contains(ch)) << ch << ": " << out;
    EXPECT_EQ(j["channels"][ch], summary["log"]["by_channel"][ch]) << ch;
  }
}

TEST(CommandLines, UsageErrorsExitTwoAndAControlCommandNobodyAnswersFails) {
  const std::string tmp = testing::MakeTempDir("cli");
  for (const std::vector<std::string>& cmd :
       {std::vector<std::string>{testing::BuildPath("tools/rms_resim"), "--bogus"},
        {testing::BuildPath("tools/rms_session"), "bogus"},
        {testing::BuildPath("tools/rms_report")},
        {testing::BuildPath("tools/rms_compare")},
        {testing::BuildPath("tools/rms_control"), "--bogus", "freeze"},
        {testing::BuildPath("dynamics_proc/dynamics_proc"), "--bogus"},
        {SourcePath("scripts/lab"), "export"},
        {SourcePath("scripts/lab"), "compare"},
        {SourcePath("scripts/lab"), "resim"},
        {SourcePath("scripts/lab"), "nonsense"}}) {
    const ScriptRun r = Script(cmd, tmp + "/usage.log", 60);
    EXPECT_EQ(r.rc, 2) << cmd[0] << " " << cmd[1 % cmd.size()] << ": " << r.out;
  }
  const ScriptRun h =
      Script({testing::BuildPath("tools/rms_resim"), "--help"}, tmp + "/help.log", 60);
  EXPECT_EQ(h.rc, 0);
  const ScriptRun c =
      Script({SourcePath("scripts/lab"), "control", "--lcm-url", testing::UniqueLcmUrl(9790),
              "--session-id", "0x0000000000000777", "freeze"},
             tmp + "/nobody.log", 60);
  EXPECT_EQ(c.rc, 1) << c.out;
  EXPECT_NE(c.out.find("no operator station of session"), std::string::npos) << c.out;
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace rms
