// The record made at the source (docs/sessions.md "The record"): each
// process's journal (rms/transport/journal.h) and the session's lcmlog made
// from the journals and what the network delivered (rms/session/record.h).
#include "rms/session/record.h"

#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <random>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <tuple>
#include <vector>

#include "rms/base/check.h"
#include "rms/transport/journal.h"

namespace rms {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  fs::path d =
      fs::temp_directory_path() / ("rmslab_record_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// An event as liblcm reads it back.
struct Event {
  std::int64_t time_us;
  std::string channel, data;
  bool operator==(const Event&) const = default;
};

std::vector<Event> ReadWithLiblcm(const fs::path& path) {
  std::vector<Event> out;
  lcm::LogFile f(path.string(), "r");
  EXPECT_TRUE(f.good()) << path;
  for (const lcm::LogEvent* ev = f.readNextEvent(); ev; ev = f.readNextEvent())
    out.push_back(
        {ev->timestamp, ev->channel, std::string(static_cast<const char*>(ev->data), ev->datalen)});
  return out;
}

// A log written by liblcm itself: what lcm-logger writes.
void WriteWithLiblcm(const fs::path& path, const std::vector<Event>& events) {
  lcm::LogFile f(path.string(), "w");
  ASSERT_TRUE(f.good());
  for (const Event& e : events) {
    lcm::LogEvent ev{};
    ev.timestamp = e.time_us;
    ev.channel = e.channel;
    ev.datalen = static_cast<std::int32_t>(e.data.size());
    ev.data = const_cast<char*>(e.data.data());
    ASSERT_EQ(f.writeEvent(&ev), 0);
  }
}

void Journalize(const fs::path& dir, const std::string& process, const std::vector<Event>& events) {
  auto j = transport::Journal::CreateIn(dir.string(), process);
  for (const Event& e : events)
    ASSERT_TRUE(j->Append(e.channel, e.data.data(), static_cast<int>(e.data.size()), e.time_us));
}

TEST(Journal, WritesEventsLiblcmReadsEachRunInAFileOfItsOwn) {
  const fs::path dir = FreshDir("journal");
  const std::vector<Event> events = {{1000, "RMS_DCP_FRAME_X", std::string("\x01\x02\x00\x03", 4)},
                                     {2000, "RMS_STATUS_X", ""},
                                     {1500, "RMS_DCP_TELEMETRY_X", std::string(5000, 'q')}};
  {
    auto j = transport::Journal::CreateIn(dir.string(), "dynamics_proc");
    EXPECT_EQ(j->path(), (dir / "dynamics_proc.0.lcmlog").string());
    for (const Event& e : events)
      ASSERT_TRUE(j->Append(e.channel, e.data.data(), static_cast<int>(e.data.size()), e.time_us));
    EXPECT_EQ(j->events(), 3);
    EXPECT_EQ(j->failed(), 0);
    // A second run (a restart) never writes after the first.
    auto again = transport::Journal::CreateIn(dir.string(), "dynamics_proc");
    EXPECT_EQ(again->path(), (dir / "dynamics_proc.1.lcmlog").string());
  }
  EXPECT_EQ(ReadWithLiblcm(dir / "dynamics_proc.0.lcmlog"), events);
  EXPECT_TRUE(ReadWithLiblcm(dir / "dynamics_proc.1.lcmlog").empty());
  EXPECT_THROW(transport::Journal::CreateIn((dir / "none").string(), "x"), InputError);
  std::ofstream(dir / "a_file") << "x";
  EXPECT_THROW(transport::Journal::CreateIn((dir / "a_file").string(), "x"), InputError);
}

// A write the disk cannot take whole (here a file-size limit, as a full
// disk would) is cut back to the last whole event: the journal still reads
// to its end, and the failures are counted.
TEST(Journal, AWriteThatFailsIsCutBackToTheLastWholeEventAndCounted) {
  const fs::path dir = FreshDir("full");
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{10000, 10000};
    setrlimit(RLIMIT_FSIZE, &limit);
    auto j = transport::Journal::CreateIn(dir.string(), "scene_proc");
    const std::string data(700, 'e');
    int ok = 0, failed = 0;
    for (int i = 0; i < 40; ++i) {
      (j->Append("RMS_ESG_FRAME", data.data(), static_cast<int>(data.size()), 1000 + i) ? ok
                                                                                        : failed)++;
    }
    std::ofstream(dir / "counts") << ok << " " << failed << " " << j->events() << " "
                                  << j->failed();
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  int ok = 0, failed = 0, events = 0, counted_failed = 0;
  std::ifstream(dir / "counts") >> ok >> failed >> events >> counted_failed;
  EXPECT_GT(ok, 5);
  EXPECT_GT(failed, 0);
  EXPECT_EQ(ok + failed, 40);
  EXPECT_EQ(events, ok);
  EXPECT_EQ(counted_failed, failed);
  const auto read = ReadWithLiblcm(dir / "scene_proc.0.lcmlog");
  EXPECT_EQ(static_cast<int>(read.size()), ok);
  // Whole events only: the file ends where the last one does.
  const std::size_t event_bytes = transport::kLogEventHeaderBytes + 13 + 700;
  EXPECT_EQ(fs::file_size(dir / "scene_proc.0.lcmlog"),
            static_cast<std::uintmax_t>(ok) * event_bytes);
}

// A session folder with journals and a recorder's log: the record holds
// every journal event and the recorder's events no journal has (a
// stranger's), in time order; a second copy the wire delivered of a
// journal's message is counted and left out (at its receive time it would
// follow what its sender sent next); it says what the recorder missed.
TEST(Record, HoldsEveryJournalEventAndWhatOnlyTheNetworkHeardInTimeOrder) {
  const fs::path s = FreshDir("session");
  fs::create_directories(s / "journal");
  const Event a1{100, "RMS_DCP_FRAME", "a1"}, a2{200, "RMS_DCP_FRAME", "a2"},
      a3{300, "RMS_DCP_FRAME", "a3"}, a4{400, "RMS_DCP_FRAME", "a4"};
  const Event b1{150, "RMS_ESG_FRAME", "b1"}, b2{250, "RMS_ESG_FRAME", "b2"},
      b3{350, "RMS_ESG_FRAME", "b3"};
  // Same bytes on another channel: another message.
  const Event same_bytes{260, "RMS_STATUS", "a2"};
  Journalize(s / "journal", "dynamics_proc", {a1, a2, a3, a4});
  Journalize(s / "journal", "scene_proc", {b1, b2, b3});
  Journalize(s / "journal", "esg_renderer", {same_bytes});
  // The recorder's times are later (receive times); it missed a3, a4 and b3,
  // heard a stranger and a2 twice, and not the status.
  const Event stranger{210, "RMS_CONTROL", "stranger"};
  WriteWithLiblcm(s / "wire.lcmlog", {{101, a1.channel, a1.data},
                                      {152, b1.channel, b1.data},
                                      {203, a2.channel, a2.data},
                                      stranger,
                                      {230, a2.channel, a2.data},
                                      {251, b2.channel, b2.data}});
  const auto record = session::MakeRecord(s.string());
  const std::vector<Event> want = {a1, b1, a2, stranger, b2, same_bytes, a3, b3, a4};
  EXPECT_EQ(ReadWithLiblcm(s / "lcmlog"), want);
  EXPECT_TRUE(record["made"].get<bool>());
  EXPECT_EQ(record["lcmlog"]["events"], 9);
  EXPECT_EQ(record["lcmlog"]["from_journals"], 8);
  EXPECT_EQ(record["lcmlog"]["from_wire_only"], 1);
  EXPECT_EQ(record["wire"]["events"], 6);
  EXPECT_EQ(record["wire"]["duplicated"]["total"], 1);
  EXPECT_EQ(record["wire"]["duplicated"]["by_channel"]["RMS_DCP_FRAME"], 1);
  EXPECT_EQ(record["wire"]["missed"]["total"], 4);
  EXPECT_EQ(record["wire"]["missed"]["by_channel"]["RMS_DCP_FRAME"], 2);
  EXPECT_EQ(record["wire"]["missed"]["by_channel"]["RMS_ESG_FRAME"], 1);
  EXPECT_EQ(record["wire"]["missed"]["by_channel"]["RMS_STATUS"], 1);
  EXPECT_EQ(record["journals"].size(), 3u);
  EXPECT_EQ(record["journals"][0]["process"], "dynamics_proc");
  EXPECT_EQ(record["journals"][0]["run"], 0);
  // The journals are gone, the recorder's log is as it was, record.json says it.
  EXPECT_FALSE(fs::exists(s / "journal"));
  EXPECT_EQ(ReadWithLiblcm(s / "wire.lcmlog").size(), 6u);
  EXPECT_TRUE(fs::exists(s / "record.json"));
  // Made again: nothing to make it from, nothing changed.
  const auto again = session::MakeRecord(s.string());
  EXPECT_FALSE(again["made"].get<bool>());
  EXPECT_EQ(ReadWithLiblcm(s / "lcmlog"), want);
}

// A journal damaged part way (its second event's sync word overwritten):
// read past the damage, the event it spoiled comes from the wire, the bytes
// passed over are counted, and every journal is kept to look into.
TEST(Record, ADamagedJournalIsCountedAndKept) {
  const fs::path s = FreshDir("damaged");
  fs::create_directories(s / "journal");
  const Event a1{100, "RMS_DCP_FRAME", "a1"}, a2{200, "RMS_DCP_FRAME", "a2"},
      a3{300, "RMS_DCP_FRAME", "a3"};
  Journalize(s / "journal", "dynamics_proc", {a1, a2, a3});
  Journalize(s / "journal", "scene_proc", {{150, "RMS_ESG_FRAME", "b1"}});
  const fs::path dcp = s / "journal" / "dynamics_proc.0.lcmlog";
  ASSERT_TRUE(fs::exists(dcp));
  const auto first_event_bytes = static_cast<std::streamoff>(4 + 8 + 8 + 4 + 4 + 13 + 2);
  {
    std::fstream f(dcp, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(first_event_bytes);
    f.write("XXXX", 4);
  }
  WriteWithLiblcm(s / "wire.lcmlog", {{201, a2.channel, a2.data}, {301, a3.channel, a3.data}});
  const auto record = session::MakeRecord(s.string());
  EXPECT_TRUE(record["made"].get<bool>());
  EXPECT_EQ(record["journals"][0]["skipped_bytes"].get<long>(), first_event_bytes)
      << record.dump(2);
  EXPECT_EQ(record["journals"][0]["unread_bytes"].get<long>(), 0) << record.dump(2);
  EXPECT_EQ(record["journals"][0]["events"], 2) << "a1 and a3: read past a2";
  EXPECT_EQ(record["lcmlog"]["from_wire_only"], 1) << "a2";
  EXPECT_TRUE(record["journals_kept"].get<bool>());
  EXPECT_TRUE(fs::exists(dcp));
  EXPECT_TRUE(fs::exists(s / "journal" / "scene_proc.0.lcmlog"));
}

// Random journals and a recorder that hears a random part of them, some
// twice (seeded, the seed printed): every journal event is in the record
// once, every recorder event no journal has too, no second copy of a
// journal's, each source's order is kept.
TEST(Record, RandomSourcesEveryEventOnceEachSourcesOrderKept) {
  const unsigned seed = 20261204;
  std::printf("seed %u\n", seed);
  std::mt19937 rng(seed);
  for (int round = 0; round < 20; ++round) {
    const fs::path s = FreshDir("random" + std::to_string(round));
    fs::create_directories(s / "journal");
    std::vector<std::vector<Event>> journals(1 + rng() % 4);
    std::vector<Event> wire;
    std::int64_t t = 1000;
    int serial = 0;
    for (int i = 0; i < 300; ++i) {
      t += rng() % 3;  // times that tie often
      const std::size_t p = rng() % journals.size();
      Event e{t, "RMS_CH" + std::to_string(p), "m" + std::to_string(serial++)};
      if (rng() % 4 == 0) e.data = "dup";  // messages alike in every byte
      journals[p].push_back(e);
      const unsigned heard = rng() % 10;
      if (heard < 7)
        wire.push_back({t + 1 + static_cast<std::int64_t>(rng() % 5), e.channel, e.data});
      if (heard == 0) wire.push_back({t + 9, e.channel, e.data});  // the network's duplicate
      if (heard == 9) wire.push_back({t + 2, "RMS_STRANGER", "s" + std::to_string(i)});
    }
    std::stable_sort(wire.begin(), wire.end(),
                     [](const Event& a, const Event& b) { return a.time_us < b.time_us; });
    for (std::size_t p = 0; p < journals.size(); ++p)
      Journalize(s / "journal", "p" + std::to_string(p), journals[p]);
    WriteWithLiblcm(s / "wire.lcmlog", wire);
    session::MakeRecord(s.string());
    const std::vector<Event> got = ReadWithLiblcm(s / "lcmlog");
    // Each journal's events, in its order, as a subsequence of the record.
    for (const auto& j : journals) {
      std::size_t at = 0;
      for (const Event& e : got)
        if (at < j.size() && e == j[at]) ++at;
      EXPECT_EQ(at, j.size()) << "round " << round;
    }
    std::map<std::tuple<std::string, std::string>, int> in_journals, in_wire, in_record;
    for (const auto& j : journals)
      for (const Event& e : j) ++in_journals[{e.channel, e.data}];
    for (const Event& e : wire) ++in_wire[{e.channel, e.data}];
    for (const Event& e : got) ++in_record[{e.channel, e.data}];
    for (const auto& [k, n] : in_record) {
      const int j = in_journals.count(k) ? in_journals[k] : 0;
      const int w = in_wire.count(k) ? in_wire[k] : 0;
      EXPECT_EQ(n, j > 0 ? j : w) << std::get<0>(k) << " " << std::get<1>(k);
    }
    EXPECT_TRUE(std::is_sorted(got.begin(), got.end(), [](const Event& a, const Event& b) {
      return a.time_us < b.time_us;
    }));
  }
}

TEST(Record, AFolderWithoutJournalsIsLeftAsItIs) {
  const fs::path s = FreshDir("old");
  WriteWithLiblcm(s / "lcmlog", {{1, "RMS_STATUS", "x"}});
  EXPECT_FALSE(session::MakeRecord(s.string())["made"].get<bool>());
  fs::create_directories(s / "journal");  // empty: a re-simulation's, say
  EXPECT_FALSE(session::MakeRecord(s.string())["made"].get<bool>());
  EXPECT_EQ(ReadWithLiblcm(s / "lcmlog").size(), 1u);
}

}  // namespace
}  // namespace rms
