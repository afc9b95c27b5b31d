// A sweep's batch of cells (docs/sessions.md "Sweeps"), several at once on
// their own threads.
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rms/base/check.h"
#include "rms/base/config_settings.h"
#include "rms/resim/resim.h"

namespace rms::resim {
namespace {

// The fields of a tab-separated line.
std::vector<std::string> Fields(const std::string& line) {
  std::vector<std::string> f;
  std::size_t at = 0;
  for (std::size_t tab; (tab = line.find('\t', at)) != std::string::npos; at = tab + 1)
    f.push_back(line.substr(at, tab - at));
  f.push_back(line.substr(at));
  return f;
}

// A line of the batch that is a cell: INDEX<TAB>KEY<TAB>SESSION<TAB>KEY=VALUE...
struct CellLine {
  std::string index, session;
  std::vector<std::string> sets;  // KEY=VALUE, as given
};

// The session the consecutive cells of a run share, read by the first of
// them that needs it (its cells may run on several threads at once).
class SharedSession {
 public:
  explicit SharedSession(std::string dir) : dir_(std::move(dir)) {}
  const std::string& dir() const { return dir_; }
  // The session, or the exception its reading threw (to each cell of it).
  std::shared_ptr<const RecordedSession> Get() {
    std::call_once(read_, [this] {
      try {
        recorded_ = ReadRecordedSession(dir_);
      } catch (...) {
        error_ = std::current_exception();
      }
    });
    if (error_) std::rethrow_exception(error_);
    return recorded_;
  }

 private:
  std::string dir_;
  std::once_flag read_;
  std::shared_ptr<const RecordedSession> recorded_;
  std::exception_ptr error_;
};

// One cell's result line's JSON (its {"error": ...} when it has none);
// *failed set when it has none.
std::string CellResult(const CellLine& c, SharedSession* session, bool* failed) {
  try {
    ResimOptions opt;
    opt.session = c.session;
    opt.discard = true;
    for (const std::string& s : c.sets) opt.settings.push_back(ParseConfigSetting(s));
    if (!OtherDesign(opt)) throw InputError("a cell needs at least one KEY=VALUE (another design)");
    opt.recorded = session->Get();
    return JsonLine(Resimulate(opt).cell);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_resim: cell %s: %s\n", c.index.c_str(), e.what());
    *failed = true;
    return JsonLine(nlohmann::json{{"error", e.what()}});
  }
}

// The cells of one session, `jobs` at once: each result line written whole
// as soon as it is made. True when a cell had an error line.
bool RunSessionsCells(const std::vector<CellLine>& cells, int jobs) {
  SharedSession session(cells.front().session);
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex out;
  auto work = [&] {
    for (std::size_t i; (i = next.fetch_add(1)) < cells.size();) {
      bool bad = false;
      const std::string json = CellResult(cells[i], &session, &bad);
      if (bad) failed = true;
      const std::lock_guard<std::mutex> lock(out);
      std::printf("%s\t%s\n", cells[i].index.c_str(), json.c_str());
      std::fflush(stdout);
    }
  };
  const int threads = static_cast<int>(std::min<std::size_t>(jobs, cells.size()));
  std::vector<std::thread> others;
  for (int t = 1; t < threads; ++t) others.emplace_back(work);
  work();
  for (std::thread& t : others) t.join();
  return failed;
}

}  // namespace

std::string JsonLine(const nlohmann::json& j) {
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}
std::string JsonLine(const nlohmann::ordered_json& j) {
  return j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

int RunCells(std::istream& in, int jobs) {
  RMS_CHECK(jobs >= 1);
  int rc = 0;
  std::vector<CellLine> run;  // consecutive cells of one session
  auto flush = [&] {
    if (!run.empty() && RunSessionsCells(run, jobs)) rc = std::max(rc, 1);
    run.clear();
  };
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    const std::vector<std::string> f = Fields(line);
    if (f.size() < 3 || f[0].empty() || f[0].size() > 18 ||
        f[0].find_first_not_of("0123456789") != std::string::npos) {
      std::fprintf(stderr, "rms_resim: --cells: not a cell (INDEX<TAB>KEY<TAB>SESSION...): %s\n",
                   line.c_str());
      rc = 2;
      continue;
    }
    if (!run.empty() && run.front().session != f[2]) flush();
    run.push_back({f[0], f[2], std::vector<std::string>(f.begin() + 3, f.end())});
  }
  flush();
  return rc;
}

}  // namespace rms::resim
