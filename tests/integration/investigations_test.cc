// Investigations at scale (docs/sessions.md "Sweeps" and "Branching"), the
// way an experimenter runs them: two recorded sessions swept over a 3 x 2
// grid of designs, whose cells agree with single `rms_resim --config` runs;
// the same sweep across the suite's namespace hosts through GNU parallel; a
// rerun and a resumed sweep that redo nothing finished; a failed cell tried
// again and reported; a Slurm array job whose tasks fill the cache; the
// table drawn by a real browser; and a session branched from a recorded
// instant whose prefix re-simulates word for word. One ctest
// (integration.investigations): the two sessions are recorded once.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <sys/stat.h>
#include <tuple>

#include "live_session.h"
#include "netns_lab.h"
#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::Script;
using testing::ScriptRun;
using testing::SourcePath;

// A CSV file as rows of named fields (the sweep's table: no quoted commas
// in the columns read here but "what changed", which is read as the rest).
std::vector<std::map<std::string, std::string>> ReadCsv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> names;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& l) {
    std::vector<std::string> f;
    std::string cur;
    bool quoted = false;
    for (char c : l) {
      if (c == '"') {
        quoted = !quoted;
      } else if (c == ',' && !quoted) {
        f.push_back(cur);
        cur.clear();
      } else {
        cur += c;
      }
    }
    f.push_back(cur);
    return f;
  };
  if (std::getline(in, line)) names = split(line);
  while (std::getline(in, line)) {
    const auto f = split(line);
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < names.size() && i < f.size(); ++i) row[names[i]] = f[i];
    rows.push_back(row);
  }
  return rows;
}

std::string Lines(const std::string& text, const std::string& needle) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line))
    if (line.find(needle) != std::string::npos) out += line + "\n";
  return out;
}

std::vector<std::string> Joblogs(const std::string& dir) {
  std::vector<std::string> v;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("joblog-", 0) == 0) v.push_back(e.path().string());
  std::sort(v.begin(), v.end());
  return v;
}

// DIR/build: this build's tools, but for an rms_resim that is a shell
// script running `before` and then the real one (RMSLAB_BUILD=DIR/build).
void WrappedBuild(const std::string& dir, const std::string& before) {
  fs::create_directories(dir + "/build/tools");
  for (const auto& e : fs::directory_iterator(testing::BuildPath("tools")))
    fs::create_symlink(e.path(), fs::path(dir + "/build/tools") / e.path().filename());
  const std::string resim = dir + "/build/tools/rms_resim";
  fs::remove(resim);
  std::ofstream(resim) << "#!/bin/sh\n"
                       << before << "exec '" << testing::BuildPath("tools/rms_resim")
                       << "' \"$@\"\n";
  fs::permissions(resim, fs::perms::owner_all);
}

// How many of a sweep page's plots a browser (headless Chromium) draws.
int PlotsDrawn(const std::string& page) {
  testing::Subprocess chrome(
      {"/usr/bin/chromium", "--headless=new", "--no-sandbox", "--disable-gpu",
       "--virtual-time-budget=5000", "--dump-dom", "file://" + page},
      page + ".dom");
  if (chrome.Wait(120) != 0) return -1;
  const std::string dom = ReadFile(page + ".dom");
  int drawn = 0;
  for (std::size_t at = dom.find("data-drawn=\"1\""); at != std::string::npos;
       at = dom.find("data-drawn=\"1\"", at + 1))
    ++drawn;
  return drawn;
}

class Investigations : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new std::string(testing::MakeTempDir("investigations"));
    a_ = new std::string();
    b_ = new std::string();
    // The autopilot and a timeline, each at 4x, small frames, no video.
    const std::string url = testing::UniqueLcmUrl(9300);
    for (const auto& [name, extra] :
         {std::pair{"autopilot", std::vector<std::string>{"--speed", "4"}},
          std::pair{"mission",
                    std::vector<std::string>{"--speed", "4", "--timeline",
                                             SourcePath("scripts/timelines/mission.tl")}}}) {
      fs::create_directories(*tmp_ + "/" + name);
      testing::LiveSession s(*tmp_ + "/" + name, url, extra);
      ASSERT_EQ(s.Wait(300), 0) << ReadFile(s.log());
      *(std::string(name) == "autopilot" ? a_ : b_) = s.out();
    }
  }
  static void TearDownTestSuite() {
    fs::remove_all(*tmp_);
    delete tmp_;
    delete a_;
    delete b_;
  }
  // scripts/lab sweep over both sessions on the 3 x 2 grid.
  static ScriptRun Sweep(const std::string& out, const std::string& cache,
                         std::vector<std::string> extra = {}) {
    std::vector<std::string> argv = {SourcePath("scripts/lab"),
                                     "sweep",
                                     *a_,
                                     *b_,
                                     "--vary",
                                     "dcp.tpob_ft=0.2,0.3,0.4",
                                     "--vary",
                                     "arm.upper_boom_ft=20.9,21.5",
                                     "--out",
                                     out,
                                     "--cache",
                                     cache,
                                     "--no-build"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return Script(argv, out + ".log");
  }
  static std::string* tmp_;
  static std::string* a_;
  static std::string* b_;
};
std::string* Investigations::tmp_ = nullptr;
std::string* Investigations::a_ = nullptr;
std::string* Investigations::b_ = nullptr;

// The session's configuration with the two keys set, by editing its text.
std::string WriteDesign(const std::string& session, const std::string& tpob,
                        const std::string& boom, const std::string& path) {
  std::string text = ReadFile(session + "/config.toml");
  text = std::regex_replace(text, std::regex(R"((\ntpob_ft\s*=\s*)[^\s#]+)"), "$01" + tpob);
  text = std::regex_replace(text, std::regex(R"((\nupper_boom_ft\s*=\s*)[^\s#]+)"), "$01" + boom);
  std::ofstream(path) << text;
  return path;
}

TEST_F(Investigations, TwoSessionsOnAThreeByTwoGridAgreeWithSingleResims) {
  const std::string out = *tmp_ + "/sweep-local";
  const ScriptRun r = Sweep(out, *tmp_ + "/cache-local", {"--jobs", "2"});
  ASSERT_EQ(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("12 cells (2 sessions x 6 designs)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("sweep [####"), std::string::npos) << "no progress bar: " << r.out;
  const auto rows = ReadCsv(out + "/sweep.csv");
  ASSERT_EQ(rows.size(), 12u);
  int k = 0;
  for (const auto& row : rows) {
    SCOPED_TRACE("cell " + row.at("cell"));
    ASSERT_EQ(row.at("status"), "ok") << row.at("error");
    const std::string design = *tmp_ + "/design-" + std::to_string(++k) + ".toml";
    WriteDesign(row.at("session"), row.at("dcp.tpob_ft"), row.at("arm.upper_boom_ft"), design);
    const std::string single = *tmp_ + "/single-" + std::to_string(k);
    const ScriptRun one = Script({testing::BuildPath("tools/rms_resim"), row.at("session"),
                                  "--config", design, "--out", single, "--quiet"},
                                 single + ".log");
    ASSERT_EQ(one.rc, 0) << one.out;
    const auto summary = nlohmann::json::parse(ReadFile(single + "/summary.json"));
    const auto comparison = nlohmann::json::parse(ReadFile(single + "/comparison.json"));
    EXPECT_EQ(row.at("acquired"), summary["acquired"].get<bool>() ? "1" : "0");
    EXPECT_EQ(row.at("docked"), summary["docked"].get<bool>() ? "1" : "0");
    EXPECT_EQ(row.at("held_frames"), std::to_string(summary["held_frames"].get<long>()));
    EXPECT_EQ(row.at("collisions"), std::to_string(summary["totals"]["collisions"].get<long>()));
    EXPECT_EQ(row.at("frames_identical"),
              std::to_string(comparison["frames_identical"].get<long>()));
    EXPECT_EQ(row.at("frames_compared"), std::to_string(comparison["frames_compared"].get<long>()));
    if (summary["docked"].get<bool>()) {
      EXPECT_EQ(std::stod(row.at("docked_at [s]")),
                summary["attempts"][summary["result_attempt"].get<int>() - 1]["reached_s"]["docked"]
                    .get<double>());
    }
    // The recorded design is the recording, word for word; the longer boom
    // departs from it, and the table says where.
    const bool recorded = row.at("dcp.tpob_ft") == "0.3" && row.at("arm.upper_boom_ft") == "20.9";
    if (recorded) {
      EXPECT_EQ(row.at("frames_identical"), row.at("frames_compared"));
      EXPECT_EQ(row.at("first_divergence_frame"), "");
      EXPECT_EQ(row.at("changes"), "0");
    }
    if (row.at("arm.upper_boom_ft") == "21.5") {
      EXPECT_NE(row.at("first_divergence_frame"), "");
    }
  }
  // The page: a browser draws one plot per varied key.
  const std::string html = ReadFile(out + "/sweep.html");
  EXPECT_EQ(html.find("<script src="), std::string::npos) << "not self-contained";
  EXPECT_EQ(PlotsDrawn(out + "/sweep.html"), 2) << "plots not drawn";
}

// Values that are markup are the page's text, not its code: the table shows
// them and the plot is still drawn.
TEST_F(Investigations, AValueThatIsMarkupIsShownAsTextAndThePlotIsStillDrawn) {
  const std::string out = *tmp_ + "/markup";
  const ScriptRun r = Script({SourcePath("scripts/lab"), "sweep", *a_, "--vary",
                              "cameras[0].name=\"<!--<script>\",\"A</script><b>x&amp;\"", "--out",
                              out, "--cache", *tmp_ + "/cache-markup", "--no-build"},
                             out + ".log");
  ASSERT_EQ(r.rc, 0) << r.out;
  const std::string html = ReadFile(out + "/sweep.html");
  EXPECT_EQ(html.find("<!--<script>"), std::string::npos);
  EXPECT_EQ(html.find("<b>x"), std::string::npos);
  EXPECT_EQ(PlotsDrawn(out + "/sweep.html"), 1) << "the plot not drawn";
}

// stdout alone of a tool run through sh (its stderr left out).
ScriptRun Stdout(const std::string& command, const std::string& log) {
  return Script({"/bin/sh", "-c", command + " 2>/dev/null"}, log);
}

std::string Quoted(const std::string& s) { return "'" + s + "'"; }

TEST_F(Investigations, ABatchOfCellsGivesEachCellsResultAsASingleRunAndAWrittenSessionDo) {
  // Both sessions' designs interleaved (each log read once for its designs),
  // a key the configuration lacks, and a line that is no cell.
  const std::string dir = *tmp_ + "/batch";
  fs::create_directories(dir);
  struct Cell {
    std::string index, session, sets;
  };
  const std::vector<Cell> cells = {{"7", *a_, "dcp.tpob_ft=0.4"},
                                   {"3", *b_, "arm.upper_boom_ft=21.5"},
                                   {"4", *b_, "arm.upper_boom_ft=19"},  // collisions, holds
                                   {"12", *a_, "arm.upper_boom_ft=21.5\tdcp.tpob_ft=0.2"},
                                   {"5", *b_, "dcp.no_such_key=1"},
                                   {"9", *b_, "dcp.tpob_ft=0.3"}};
  std::ofstream list(dir + "/cells.tsv");
  for (const Cell& c : cells) list << c.index << "\tkey\t" << c.session << "\t" << c.sets << "\n";
  list << "not a cell\n";
  list.close();
  const std::string resim = testing::BuildPath("tools/rms_resim");
  const ScriptRun batch =
      Stdout(Quoted(resim) + " --cells " + Quoted(dir + "/cells.tsv"), dir + "/batch.log");
  EXPECT_EQ(batch.rc, 2) << "a line that is no cell is a usage error: " << batch.out;
  std::istringstream lines(batch.out);
  std::string line;
  for (const Cell& c : cells) {
    SCOPED_TRACE("cell " + c.index);
    ASSERT_TRUE(std::getline(lines, line)) << batch.out;
    ASSERT_EQ(line.substr(0, line.find('\t')), c.index);
    std::string sets;
    std::istringstream each(std::regex_replace(c.sets, std::regex("\t"), " "));
    for (std::string kv; each >> kv;) sets += " --set " + kv;
    const ScriptRun single =
        Stdout(Quoted(resim) + " " + Quoted(c.session) + sets + " --discard --result-json --quiet",
               dir + "/single-" + c.index + ".log");
    EXPECT_EQ(line.substr(line.find('\t') + 1) + "\n", single.out);
    // Made in memory (SummarizeDcpRun), as from the session written and summarised.
    const ScriptRun written =
        Stdout(Quoted(resim) + " " + Quoted(c.session) + sets + " --out " +
                   Quoted(dir + "/written-" + c.index) + " --result-json --quiet",
               dir + "/written-" + c.index + ".log");
    EXPECT_EQ(single.out, written.out);
    if (c.index == "5") {
      EXPECT_NE(line.find("\"error\""), std::string::npos) << line;
    }
  }
  EXPECT_FALSE(std::getline(lines, line)) << "a line more: " << line;
  // Cells at once on their threads: the same lines (in the order they end)
  // and exit code, a session's cells one after another as several at once.
  std::ofstream more(dir + "/cells.tsv", std::ios::app);
  for (int i = 1; i <= 6; ++i)
    more << 20 + i << "\tkey\t" << *a_ << "\tdcp.tpob_ft=0.2" << i << "\n";
  more.close();
  auto sorted_lines = [](const std::string& text) {
    std::vector<std::string> v;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) v.push_back(l);
    std::sort(v.begin(), v.end());
    return v;
  };
  const ScriptRun one =
      Stdout(Quoted(resim) + " --cells " + Quoted(dir + "/cells.tsv"), dir + "/one.log");
  for (const char* jobs : {"2", "3"}) {
    const ScriptRun at_once =
        Stdout(Quoted(resim) + " --cells " + Quoted(dir + "/cells.tsv") + " --jobs " + jobs,
               dir + "/jobs" + jobs + ".log");
    EXPECT_EQ(at_once.rc, one.rc) << jobs;
    EXPECT_EQ(sorted_lines(at_once.out), sorted_lines(one.out)) << "--jobs " << jobs;
    EXPECT_EQ(sorted_lines(at_once.out).size(), cells.size() + 6);
  }
  // --jobs is a count of cells at once, and only for --cells; --threads
  // (the session's own design) is none of a batch's.
  for (const std::string& args :
       {" --cells " + Quoted(dir + "/cells.tsv") + " --jobs 0",
        " --cells " + Quoted(dir + "/cells.tsv") + " --jobs two",
        " --cells " + Quoted(dir + "/cells.tsv") + " --threads 2", " " + Quoted(*a_) + " --jobs 2"})
    EXPECT_EQ(Stdout(Quoted(resim) + args, dir + "/usage.log").rc, 2) << args;
}

// Each cell's line comes as it is made, not when the batch's input ends: a
// writer that waits for the first line before it closes the input is not
// kept waiting (one cell at a time, and several at once).
TEST_F(Investigations, ACellsLineComesBeforeTheBatchsInputEnds) {
  const std::string dir = *tmp_ + "/streaming";
  fs::create_directories(dir);
  for (const char* jobs : {"1", "2"}) {
    const std::string out = dir + "/out" + jobs;
    const std::string script =
        "{ printf '7\\tkey\\t%s\\tdcp.tpob_ft=0.4\\n' \"$1\"; "
        "while [ ! -s \"$2\" ]; do sleep 0.1; done; } | \"$3\" --cells - --jobs \"$4\" > \"$2\"";
    testing::Subprocess batch(
        {"/bin/sh", "-c", script, "sh", *a_, out, testing::BuildPath("tools/rms_resim"), jobs},
        out + ".log");
    EXPECT_EQ(batch.Wait(120), 0) << "--jobs " << jobs
                                  << ": the line came only at the input's end? "
                                  << ReadFile(out + ".log");
    EXPECT_EQ(ReadFile(out).rfind("7\t{\"outcome\"", 0), 0u) << ReadFile(out);
  }
}

// A session whose log was cut short: swept up to the cut, each cell's row
// says so (its note), and so does the sweep, once; the design is not blamed
// silently for what the log lacks.
TEST_F(Investigations, ASessionWhoseLogIsCutShortIsSweptWithANoteSaid) {
  const std::string dir = *tmp_ + "/cut";
  fs::create_directories(dir);
  // Torn: cut inside an event. Clean: cut where an event begins (its sync
  // word), so the log is whole but shorter than its summary counted.
  const std::string log = ReadFile(*a_ + "/lcmlog");
  const std::string sync("\xED\xA1\xDA\x01", 4);
  const std::size_t event_start = log.find(sync, log.size() * 2 / 3);
  ASSERT_NE(event_start, std::string::npos);
  for (const auto& [name, size] :
       {std::pair{"torn", log.size() * 2 / 3 + 5}, std::pair{"clean", event_start}}) {
    fs::copy(*a_, dir + "/" + name, fs::copy_options::recursive);
    fs::resize_file(dir + "/" + name + "/lcmlog", size);
  }
  const ScriptRun r = Script(
      {SourcePath("scripts/lab"), "sweep", dir + "/torn", dir + "/clean", "--vary",
       "dcp.tpob_ft=0.25,0.35", "--out", dir + "/out", "--cache", dir + "/cache", "--no-build"},
      dir + "/out.log");
  ASSERT_EQ(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("note: " + dir + "/torn: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("note: " + dir + "/clean: "), std::string::npos) << r.out;
  const auto rows = ReadCsv(dir + "/out/sweep.csv");
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_NE(row.at("note").find("its summary.json counted logged"), std::string::npos)
        << row.at("note");
    if (row.at("session") == dir + "/torn") {
      EXPECT_NE(row.at("note").find("no whole event"), std::string::npos) << row.at("note");
    }
  }
}

TEST_F(Investigations, TheSameSweepAcrossTheNamespaceHostsThroughGnuParallel) {
  const std::string dir = *tmp_ + "/hosts";
  fs::create_directories(dir);
  testing::NetnsLab net("sw" + std::to_string(getpid() % 100000), dir, 2);
  ASSERT_TRUE(net.ok()) << ReadFile(dir + "/netns.log");
  // A lab file whose [sweep] runs one cell at a time on each of `hosts`.
  auto write_lab = [&](const std::string& path, const std::vector<std::string>& list) {
    std::string hosts;
    for (const std::string& h : list)
      hosts.append(hosts.empty() ? "" : ", ").append(nlohmann::json(h).dump());
    std::ofstream(path) << "[hosts]\noperator_station = \"" << net.host(1)
                        << "\"\ndynamics_proc = \"" << net.host(2) << "\"\nscene_proc = \""
                        << net.host(1) << "\"\nesg_renderer = \"" << net.host(2)
                        << "\"\nrecorder = \"localhost\"\n[lcm]\ngroup = \"239.255.76.69\"\n"
                           "port = 7670\nttl = 1\n[remote]\nroot = \"\"\nbuild = \"\"\n"
                           "[sweep]\nhosts = ["
                        << hosts << "]\njobs_per_host = 1\n";
    return path;
  };
  const std::string lab = write_lab(dir + "/lab.toml", {net.host(1), net.host(2)});
  const ScriptRun local = Sweep(dir + "/local", dir + "/cache-local");
  ASSERT_EQ(local.rc, 0) << local.out;
  // Started with no SHELL, as a CI job or cron starts it: a namespace
  // host's login gives the command the user's shell as ssh does (GNU
  // parallel's remote worker runs each batch with $SHELL).
  const std::optional<std::string> shell =
      std::getenv("SHELL") ? std::optional<std::string>(std::getenv("SHELL")) : std::nullopt;
  unsetenv("SHELL");
  const ScriptRun across = Sweep(dir + "/across", dir + "/cache-across", {"--hosts", lab});
  if (shell) setenv("SHELL", shell->c_str(), 1);
  ASSERT_EQ(across.rc, 0) << across.out;
  // Every cell ran on one of the lab's hosts (the joblog's Host), and both
  // hosts took cells; the table is the local one, cell for cell.
  const auto logs = Joblogs(dir + "/across");
  ASSERT_EQ(logs.size(), 1u);
  std::set<std::string> hosts;
  std::istringstream jl(ReadFile(logs[0]));
  std::string line;
  std::getline(jl, line);  // the header
  int jobs = 0;
  while (std::getline(jl, line)) {
    ++jobs;
    std::istringstream fields(line);
    std::string field[7];  // Seq, Host, Starttime, JobRuntime, Send, Receive, Exitval, ...
    for (std::string& f : field) std::getline(fields, f, '\t');
    hosts.insert(field[1]);
    EXPECT_NE(field[1].find("netns-login"), std::string::npos) << line;
    EXPECT_EQ(field[6], "0") << line;
  }
  EXPECT_GE(jobs, 2) << "each host one batch of cells at least";
  EXPECT_EQ(hosts.size(), 2u) << ReadFile(logs[0]);
  EXPECT_EQ(ReadFile(dir + "/across/sweep.csv"), ReadFile(dir + "/local/sweep.csv"));
  // A host that does not answer, beside one that does: left out, every cell done.
  const std::string half =
      write_lab(dir + "/half.toml", {"netns:rmslab-no-such-host", net.host(1)});
  const ScriptRun partly = Sweep(dir + "/partly", dir + "/cache-partly", {"--hosts", half});
  ASSERT_EQ(partly.rc, 0) << partly.out;
  EXPECT_NE(partly.out.find("host netns:rmslab-no-such-host does not answer"), std::string::npos)
      << partly.out;
  EXPECT_EQ(ReadFile(dir + "/partly/sweep.csv"), ReadFile(dir + "/local/sweep.csv"));
}

TEST_F(Investigations, ARerunOrAResumedSweepRedoesNothingFinished) {
  const std::string out = *tmp_ + "/resume", cache = *tmp_ + "/cache-resume";
  std::string table;
  // The sweep again: `run` cells run, `cached` from the cache, the same table.
  auto again = [&](int run, int cached) {
    const ScriptRun r = Sweep(out, cache);
    EXPECT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("sweep: " + std::to_string(run) + " cells run"), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find(", " + std::to_string(cached) + " from the cache"), std::string::npos)
        << r.out;
    if (table.empty()) table = ReadFile(out + "/sweep.csv");
    EXPECT_EQ(ReadFile(out + "/sweep.csv"), table);
    return r.out;
  };
  again(12, 0);
  again(0, 12);  // all from the cache, nothing run
  // A sweep stopped part way (three results lost): only those three run.
  int removed = 0;
  for (const auto& e : fs::directory_iterator(cache))
    if (removed < 3 && fs::remove(e.path())) ++removed;
  again(3, 9);
  // Two entries spoiled (not JSON; JSON but no result): said, run again.
  int spoiled = 0;
  for (const auto& e : fs::directory_iterator(cache)) {
    if (spoiled < 2) std::ofstream(e.path()) << (spoiled++ == 0 ? "garbage" : "[]");
  }
  EXPECT_FALSE(Lines(again(2, 10), "its cell is run again").empty());
  // An entry edited by hand (its result changed, still a valid result), one
  // linked to /dev/zero and one a FIFO (docs/security.md "Session folders
  // are untrusted"): each refused and said, promptly, its cell run again,
  // the table the same.
  std::vector<fs::path> entries;
  for (const auto& e : fs::directory_iterator(cache))
    if (e.path().extension() == ".json") entries.push_back(e.path());
  ASSERT_GE(entries.size(), 3u);
  {
    auto j = nlohmann::json::parse(ReadFile(entries[0].string()));
    ASSERT_TRUE(j.contains("result")) << j.dump();
    j["result"]["outcome"]["docked"] = !j["result"]["outcome"]["docked"].get<bool>();
    std::ofstream(entries[0]) << j.dump();
  }
  fs::remove(entries[1]);
  fs::create_symlink("/dev/zero", entries[1]);
  fs::remove(entries[2]);
  ASSERT_EQ(mkfifo(entries[2].c_str(), 0644), 0);
  const auto t0 = std::chrono::steady_clock::now();
  const std::string said = again(3, 9);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(240)) << "it waited";
  EXPECT_NE(said.find("does not match its checksum"), std::string::npos) << said;
  EXPECT_NE(said.find("a link, not followed"), std::string::npos) << said;
  EXPECT_NE(said.find("not a regular file"), std::string::npos) << said;
  // A wider grid runs only its new cells.
  const ScriptRun wider =
      Script({SourcePath("scripts/lab"), "sweep", *a_, *b_, "--vary", "dcp.tpob_ft=0.2,0.3,0.4,0.5",
              "--vary", "arm.upper_boom_ft=20.9,21.5", "--out", out + "-wider", "--cache", cache,
              "--no-build"},
             out + "-wider.log");
  ASSERT_EQ(wider.rc, 0) << wider.out;
  EXPECT_NE(wider.out.find("4 cells run"), std::string::npos) << wider.out;
  EXPECT_NE(wider.out.find("12 from the cache"), std::string::npos) << wider.out;
}

// The results a sweep's cache holds (its .json entries).
std::size_t CachedResults(const std::string& cache) {
  std::size_t n = 0;
  if (fs::is_directory(cache))
    for (const auto& e : fs::directory_iterator(cache)) n += e.path().extension() == ".json";
  return n;
}

// The processes on this machine whose environment says they run a batch
// of the sweep in `dir` (RMSLAB_SWEEP=dir), "PID COMMAND" a line.
std::string ProcessesOfSweep(const std::string& dir) {
  const std::string mark = "RMSLAB_SWEEP=" + dir;
  std::string found;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string pid = e.path().filename().string();
    if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream env(e.path() / "environ");
    std::string var;
    bool ours = false;
    while (std::getline(env, var, '\0')) ours = ours || var == mark;
    if (!ours) continue;
    std::string cmd;
    std::getline(std::ifstream(e.path() / "cmdline"), cmd);
    std::replace(cmd.begin(), cmd.end(), '\0', ' ');
    found.append(pid).append(" ").append(cmd).append("\n");
  }
  return found;
}

TEST_F(Investigations, ASweepInterruptedKeepsWhatItFinishedAndTheRerunDoesTheRest) {
  const std::string out = *tmp_ + "/interrupted", cache = *tmp_ + "/cache-interrupted";
  const std::vector<std::string> argv = {SourcePath("scripts/lab"),
                                         "sweep",
                                         *a_,
                                         *b_,
                                         "--vary",
                                         "dcp.tpob_ft=0.2,0.25,0.3,0.35,0.4",
                                         "--vary",
                                         "arm.upper_boom_ft=20.5,20.9,21.2,21.5,21.8",
                                         "--out",
                                         out,
                                         "--cache",
                                         cache,
                                         "--no-build",
                                         "--jobs",
                                         "1"};
  testing::Subprocess sweep(argv, out + ".log");
  auto cached = [&] { return CachedResults(cache); };
  for (int i = 0; i < 600 && cached() < 3 && sweep.Running(); ++i) usleep(50000);
  sweep.Signal(SIGINT);
  EXPECT_EQ(sweep.Wait(60), 130) << ReadFile(out + ".log");
  const std::string said = ReadFile(out + ".log");
  EXPECT_NE(said.find("sweep interrupted (SIGINT): the "), std::string::npos) << said;
  // No batch left running (each carries RMSLAB_SWEEP=its folder).
  std::string left;
  for (int i = 0; i < 50; ++i) {
    left = ProcessesOfSweep(out);
    if (left.empty()) break;
    usleep(100000);
  }
  EXPECT_EQ(left, "") << "cells still running after the sweep was interrupted";
  const std::size_t kept = cached();
  ASSERT_GE(kept, 3u) << said;
  ASSERT_LT(kept, 50u) << "it ran to the end before the interruption: " << said;
  const ScriptRun rest = Script(argv, out + "-rest.log");
  ASSERT_EQ(rest.rc, 0) << rest.out;
  EXPECT_NE(rest.out.find(std::to_string(50 - kept) + " cells run"), std::string::npos)
      << kept << " were kept: " << rest.out;
  EXPECT_NE(rest.out.find(std::to_string(kept) + " from the cache"), std::string::npos) << rest.out;
}

// A batch that stalls (a host hung, a file system stuck) is stopped at its
// time limit and tried again; one that stalls every time fails with why.
TEST_F(Investigations, AStalledBatchIsStoppedAtItsTimeLimitAndTriedAgain) {
  const std::string dir = *tmp_ + "/stalling";
  // A build whose rms_resim, handed a batch, stalls while the file `stall`
  // is there (`once`: and takes it away, so only the first batch stalls).
  WrappedBuild(dir, "if [ \"$1\" = --cells ] && [ -e '" + dir +
                        "/stall' ]; then\n  grep -q once '" + dir + "/stall' && rm -f '" + dir +
                        "/stall'\n  sleep 120\nfi\n");
  auto sweep = [&](const std::string& name, const std::string& retries, const std::string& vary) {
    return Script(
        {"/usr/bin/env", "RMSLAB_BUILD=" + dir + "/build", "RMSLAB_SWEEP_BATCH_TIMEOUT_S=3",
         SourcePath("scripts/lab"), "sweep", *a_, "--vary", vary, "--out", dir + "/" + name,
         "--cache", dir + "/cache-" + name, "--no-build", "--retries", retries, "--jobs", "1"},
        dir + "/" + name + ".log", 100);
  };
  const auto t0 = std::chrono::steady_clock::now();
  std::ofstream(dir + "/stall") << "once\n";
  const ScriptRun once = sweep("once", "2", "dcp.tpob_ft=0.2,0.3,0.4,0.5");
  // Done well before the stalled batch's sleep (120 s) would have ended.
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(100));
  ASSERT_EQ(once.rc, 0) << once.out;
  // (The stalled batch's cells, however many a batch holds.)
  EXPECT_NE(once.out.find(" again (try 2 of 3)"), std::string::npos) << once.out;
  for (const auto& row : ReadCsv(dir + "/once/sweep.csv")) EXPECT_EQ(row.at("status"), "ok");
  std::ofstream(dir + "/stall") << "always\n";
  const ScriptRun always = sweep("always", "0", "dcp.tpob_ft=0.2,0.3");
  EXPECT_EQ(always.rc, 1) << always.out;
  const auto rows = ReadCsv(dir + "/always/sweep.csv");
  ASSERT_EQ(rows.size(), 2u) << always.out;
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "failed");
    EXPECT_NE(row.at("error").find("ran past its time limit (3 s) and was stopped"),
              std::string::npos)
        << row.at("error");
  }
}

// An rms_resim rebuilt while the sweep runs: the results may be either
// binary's, so none of this run's is kept (the cache keys name the first).
TEST_F(Investigations, AnRmsResimRebuiltDuringTheSweepKeepsNoResultOfIt) {
  const std::string dir = *tmp_ + "/rebuilt";
  // Handed a batch, it changes itself (as a rebuild changes the binary).
  WrappedBuild(dir, "[ \"$1\" = --cells ] && echo '# rebuilt' >> \"$0\"\n");
  const ScriptRun r =
      Script({"/usr/bin/env", "RMSLAB_BUILD=" + dir + "/build", SourcePath("scripts/lab"), "sweep",
              *a_, "--vary", "dcp.tpob_ft=0.2,0.3", "--out", dir + "/out", "--cache",
              dir + "/cache", "--no-build", "--retries", "0"},
             dir + "/out.log");
  EXPECT_EQ(r.rc, 1) << r.out;
  const auto rows = ReadCsv(dir + "/out/sweep.csv");
  ASSERT_EQ(rows.size(), 2u) << r.out;
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "failed");
    EXPECT_NE(row.at("error").find("changed during the sweep (rebuilt?)"), std::string::npos)
        << row.at("error");
  }
  std::size_t kept = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir + "/cache"))
    kept += e.is_regular_file() && e.path().extension() == ".json";
  EXPECT_EQ(kept, 0u) << "results of the rebuilt binary's run left in the cache";
}

TEST_F(Investigations, ABatchThatDiesOrALogThatChangesLeavesItsCellsFailedWithWhy) {
  const std::string dir = *tmp_ + "/dying";
  // A build whose rms_resim dies (SIGKILL) when it is handed a batch; the
  // real one otherwise (the sweep's checks).
  WrappedBuild(dir, "case \"$1\" in --cells) kill -9 $$ ;; esac\n");
  const ScriptRun r =
      Script({"/usr/bin/env", "RMSLAB_BUILD=" + dir + "/build", SourcePath("scripts/lab"), "sweep",
              *a_, "--vary", "dcp.tpob_ft=0.2,0.3", "--out", dir + "/out", "--cache",
              dir + "/cache", "--no-build", "--retries", "0", "--jobs", "1"},
             dir + "/out.log");
  EXPECT_EQ(r.rc, 1) << r.out;
  auto rows = ReadCsv(dir + "/out/sweep.csv");
  ASSERT_EQ(rows.size(), 2u) << r.out;
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "failed");
    EXPECT_NE(row.at("error").find("its process on this machine (rms_resim --cells) ended on "
                                   "signal 9 (SIGKILL) before this cell's line"),
              std::string::npos)
        << row.at("error");
  }
  EXPECT_NE(r.out.find("sweep [##############################] 2/2 cells (0 cached, 2 failed)"),
            std::string::npos)
      << "the progress line does not count the cells lost: " << r.out;

  // A log that changes during the sweep: what was run on it is not kept.
  const std::string copy = dir + "/session";
  fs::copy(*a_, copy, fs::copy_options::recursive);
  const std::vector<std::string> argv = {
      SourcePath("scripts/lab"),
      "sweep",
      copy,
      "--vary",
      "dcp.tpob_ft=0.2,0.22,0.25,0.27,0.3,0.32,0.35,0.37,0.4,0.42",
      "--vary",
      "arm.upper_boom_ft=20.5,20.7,20.9,21.2,21.5",
      "--out",
      dir + "/changing",
      "--cache",
      dir + "/cache2",
      "--no-build",
      "--retries",
      "0",
      "--jobs",
      "1"};
  testing::Subprocess sweep(argv, dir + "/changing.log");
  auto cached = [&] { return CachedResults(dir + "/cache2"); };
  for (int i = 0; i < 3000 && cached() < 1 && sweep.Running(); ++i) usleep(10000);
  if (!sweep.Running()) GTEST_SKIP() << "the sweep ended before its log could be changed";
  std::ofstream(copy + "/lcmlog", std::ios::app) << "not an event";
  ASSERT_EQ(sweep.Wait(300), 1) << ReadFile(dir + "/changing.log");
  EXPECT_EQ(cached(), 0u) << "a result of the changed log was kept";
  rows = ReadCsv(dir + "/changing/sweep.csv");
  ASSERT_EQ(rows.size(), 50u);
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "failed");
    EXPECT_NE(row.at("error").find("its session's log changed during the sweep"), std::string::npos)
        << row.at("error");
  }
}

TEST_F(Investigations, AFailedCellIsTriedAgainAndReportedNeverDropped) {
  const std::string dir = *tmp_ + "/failing";
  fs::create_directories(dir);
  const std::string lab = dir + "/lab.toml";
  std::ofstream(lab)
      << "[hosts]\noperator_station = \"localhost\"\ndynamics_proc = "
         "\"localhost\"\nscene_proc = \"localhost\"\nesg_renderer = "
         "\"localhost\"\nrecorder = \"localhost\"\n[lcm]\ngroup = "
         "\"239.255.76.69\"\nport = 7670\nttl = 0\n[remote]\nroot = \"\"\nbuild = "
         "\"\"\n[sweep]\nhosts = [\"netns:rmslab-no-such-host\"]\njobs_per_host = 2\n";
  const ScriptRun r = Sweep(dir + "/out", dir + "/cache", {"--hosts", lab, "--retries", "1"});
  EXPECT_EQ(r.rc, 1) << r.out;
  EXPECT_FALSE(Lines(r.out, "FAILED").empty()) << r.out;
  EXPECT_NE(r.out.find("trying 12 failed cells again (try 2 of 2)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rmslab-no-such-host"), std::string::npos) << "the reason is not shown";
  // Its only host does not answer its login: GNU parallel is not started,
  // and each cell says which host and why.
  EXPECT_TRUE(Joblogs(dir + "/out").empty());
  const auto rows = ReadCsv(dir + "/out/sweep.csv");
  ASSERT_EQ(rows.size(), 12u) << "a failed cell was dropped from the table";
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "failed");
    EXPECT_NE(row.at("error").find("answered (netns:rmslab-no-such-host: "), std::string::npos)
        << row.at("error");
  }
  EXPECT_TRUE(fs::is_empty(dir + "/cache")) << "a failure was cached";
}

TEST_F(Investigations, ASlurmArrayJobsTasksFillTheCacheAndTheTableFollows) {
  const std::string out = *tmp_ + "/slurm", cache = *tmp_ + "/cache-slurm";
  ScriptRun r = Sweep(out, cache, {"--slurm"});
  ASSERT_EQ(r.rc, 0) << r.out;
  const std::string job = ReadFile(out + "/sweep.sbatch");
  EXPECT_NE(job.find("#SBATCH --array=1-12"), std::string::npos) << job;
  EXPECT_FALSE(fs::exists(out + "/sweep.csv")) << "--slurm ran the cells itself";
  EXPECT_NE(r.out.find("--cached-only"), std::string::npos) << r.out;
  // Before the job has run, the table says every cell is missing and runs none.
  r = Sweep(out, cache, {"--cached-only"});
  EXPECT_EQ(r.rc, 1) << r.out;
  EXPECT_NE(r.out.find("not in the cache"), std::string::npos) << r.out;
  EXPECT_TRUE(Joblogs(out).empty()) << "--cached-only ran cells";
  // Slurm would run each task with its SLURM_ARRAY_TASK_ID: so does the test.
  for (int task = 12; task >= 1; --task) {
    const std::string log = out + "/task-" + std::to_string(task) + ".log";
    testing::Subprocess t({"/bin/sh", out + "/sweep.sbatch"}, log,
                          {"SLURM_ARRAY_TASK_ID=" + std::to_string(task)});
    ASSERT_EQ(t.Wait(60), 0) << ReadFile(log);
    // Its result line (stdout; the re-flown DCP's warnings, such as the gaps
    // a loaded machine's wire left in the recording, go to stderr beside it).
    std::string said = "\n", want = "\n";
    said += ReadFile(log);
    want += std::to_string(task);
    want += "\t{\"outcome\"";
    EXPECT_NE(said.find(want), std::string::npos) << said;
  }
  r = Sweep(out, cache, {"--cached-only"});
  ASSERT_EQ(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("12 from the cache"), std::string::npos) << r.out;
  EXPECT_EQ(ReadCsv(out + "/sweep.csv").size(), 12u);
  EXPECT_TRUE(Joblogs(out).empty());
}

TEST_F(Investigations, ABadKeyOrValueIsRefusedBeforeAnythingRuns) {
  struct Case {
    const char* vary;
    const char* says;
    const char* timeout = "";  // RMSLAB_SWEEP_BATCH_TIMEOUT_S
  } cases[] = {{"dcp.no_such_key=1,2", "no key 'no_such_key'"},
               {"dcp.tpob_ft=0.2,-1", "must be > 0"},
               {"dcp.tpob_ft=0.2,abc", "no TOML value"},
               {"dcp.tpob_ft", "must be KEY=V1,V2"},
               {"dcp.tpob_ft=0.2,0.2", "'0.2' and '0.2' are the same value"},
               {"dcp.tpob_ft=0.2,0.20", "'0.2' and '0.20' are the same value"},
               {"dcp.tpob_ft=1,1.0", "'1' and '1.0' are the same value"},
               {"arm.base_position_ft[1]=-8,-8.0", "'-8' and '-8.0' are the same value"},
               {"dcp.tpob_ft=0.2,0.3", "RMSLAB_SWEEP_BATCH_TIMEOUT_S='abc': must be", "abc"},
               {"dcp.tpob_ft=0.2,0.3", "RMSLAB_SWEEP_BATCH_TIMEOUT_S='0.5': must be", "0.5"}};
  for (const Case& c : cases) {
    const std::string out = *tmp_ + "/bad-" + std::to_string(&c - cases);
    const ScriptRun r =
        Script({"/usr/bin/env", std::string("RMSLAB_SWEEP_BATCH_TIMEOUT_S=") + c.timeout,
                SourcePath("scripts/lab"), "sweep", *a_, "--vary", c.vary, "--out", out, "--cache",
                out + "-cache", "--no-build"},
               out + ".log");
    EXPECT_EQ(r.rc, 2) << c.vary << ": " << r.out;
    EXPECT_NE(r.out.find(c.says), std::string::npos) << c.vary << ": " << r.out;
    EXPECT_FALSE(fs::exists(out)) << c.vary << ": a refused sweep left a folder";
    EXPECT_FALSE(fs::exists(out + "-cache")) << c.vary << ": a refused sweep left its cache";
  }
}

TEST_F(Investigations, ABranchedSessionReproducesItsParentsPrefixWordForWord) {
  const std::string child = *tmp_ + "/branch";
  // From 20 s of the autopilot's session (after it acquired), the autopilot flies on.
  const ScriptRun r =
      Script({SourcePath("scripts/lab"), "demo", "--no-build", "--from", *a_ + "@20", "--out",
              child, "--speed", "4", "--lcm-url", testing::UniqueLcmUrl(9400), "--png-every", "0",
              "--no-video", "--width", "160", "--height", "120"},
             child + ".log");
  ASSERT_EQ(r.rc, 0) << r.out;
  const auto m = nlohmann::json::parse(ReadFile(child + "/manifest.json"));
  ASSERT_TRUE(m.contains("branch")) << m.dump(2);
  EXPECT_EQ(m["branch"]["parent"], fs::absolute(*a_).lexically_normal().string());
  const double rate = 30.0;
  EXPECT_EQ(m["branch"]["frame"].get<long>(), 600);
  EXPECT_DOUBLE_EQ(m["branch"]["time_s"].get<double>(), 600 / rate);
  EXPECT_EQ(m["branch"]["parent_log_sha256"].get<std::string>().size(), 64u);
  // The branch began where its parent was: past Mode 1, the payload held.
  const auto s = nlohmann::json::parse(ReadFile(child + "/summary.json"));
  EXPECT_EQ(s["attempts"][0]["started_in_mode"], 2) << s["attempts"].dump();
  EXPECT_TRUE(s["docked"].get<bool>());
  // Re-simulating the child: the parent's prefix word for word, then its own.
  const ScriptRun resim =
      Script({testing::BuildPath("tools/rms_resim"), child}, child + "-resim.log");
  EXPECT_EQ(resim.rc, 0) << resim.out;
  EXPECT_NE(resim.out.find("601 of 601 frames identical, word for word; the DCP's state at its "
                           "end is the branch's first state"),
            std::string::npos)
      << resim.out;
  EXPECT_NE(resim.out.find("recorded frames identical, word for word"), std::string::npos)
      << resim.out;
  // Flown again under another design, the branch is still a branch: compare
  // says so of both (no fresh trial), not "start".
  const ScriptRun other = Script({SourcePath("scripts/lab"), "resim", child, "--no-build", "--set",
                                  "dcp.tpob_ft=0.4", "--out", child + "-tpob"},
                                 child + "-tpob.log");
  ASSERT_EQ(other.rc, 0) << other.out;
  EXPECT_EQ(nlohmann::json::parse(ReadFile(child + "-tpob/manifest.json"))["began_from"], "branch");
  const ScriptRun cmp = Script({SourcePath("scripts/lab"), "compare", child, child + "-tpob",
                                "--no-build", "--out", child + "-compare"},
                               child + "-compare.log");
  ASSERT_EQ(cmp.rc, 0) << cmp.out;
  {
    std::istringstream rows(ReadFile(child + "-compare/compare.csv"));
    std::string line;
    std::getline(rows, line);
    int branch_rows = 0, fresh_rows = 0;
    while (std::getline(rows, line)) {
      // ... started_by, started_from, ...: the log's start, from a branch.
      branch_rows += line.find(",start,branch,") != std::string::npos;
      fresh_rows += line.find(",start,start,") != std::string::npos;
    }
    EXPECT_EQ(branch_rows, 2) << ReadFile(child + "-compare/compare.csv");
    EXPECT_EQ(fresh_rows, 0) << ReadFile(child + "-compare/compare.csv");
  }
  // A branch whose first state is not its parent's state there is caught:
  // the manifest pointed at another instant.
  auto moved = m;
  moved["branch"]["frame"] = 450;
  moved["branch"]["time_s"] = 450 / rate;
  std::ofstream(child + "/manifest.json") << moved.dump(2);
  const ScriptRun wrong =
      Script({testing::BuildPath("tools/rms_resim"), child}, child + "-wrong.log");
  EXPECT_EQ(wrong.rc, 1) << wrong.out;
  EXPECT_NE(wrong.out.find("the branch's first state is not the DCP's state at the end of the "
                           "prefix"),
            std::string::npos)
      << wrong.out;
  for (const auto& [field, value, says] :
       {std::tuple{"frame", nlohmann::json("abc"), "'branch.frame' is not a DCP frame"},
        std::tuple{"frame", nlohmann::json(-1), "'branch.frame' is not a DCP frame"},
        std::tuple{"time_s", nlohmann::json(3.0),
                   "'branch.time_s' is not its frame's session time"},
        std::tuple{"parent", nlohmann::json(*tmp_ + "/nowhere"), "cannot be re-simulated"}}) {
    auto bad = m;
    bad["branch"][field] = value;
    std::ofstream(child + "/manifest.json") << bad.dump(2);
    const ScriptRun t = Script({testing::BuildPath("tools/rms_resim"), child}, child + "-bad.log");
    EXPECT_EQ(t.rc, 1) << field << ": " << t.out;
    EXPECT_NE(t.out.find(says), std::string::npos) << field << ": " << t.out;
  }
  // The parent's log changed since: scripts/lab resim says so.
  std::ofstream(child + "/manifest.json") << m.dump(2);
  {
    std::ofstream(*a_ + "/lcmlog", std::ios::app) << "x";
    const ScriptRun t =
        Script({SourcePath("scripts/lab"), "resim", child, "--no-build"}, child + "-changed.log");
    EXPECT_EQ(t.rc, 1) << t.out;
    EXPECT_NE(t.out.find("is not the session it was made from"), std::string::npos) << t.out;
    fs::resize_file(*a_ + "/lcmlog", fs::file_size(*a_ + "/lcmlog") - 1);
  }
  // An instant the parent never reached is refused before anything starts.
  const ScriptRun late = Script({SourcePath("scripts/lab"), "demo", "--no-build", "--from",
                                 *a_ + "@f999999", "--out", child + "-late"},
                                child + "-late.log");
  EXPECT_EQ(late.rc, 2) << late.out;
  EXPECT_NE(late.out.find("is not among them"), std::string::npos) << late.out;
  EXPECT_FALSE(fs::exists(child + "-late"));
}

}  // namespace
}  // namespace rms
