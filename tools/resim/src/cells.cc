// A sweep's batch of cells (docs/sessions.md "Sweeps"), several at once on
// their own threads.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <system_error>
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
  std::string why;
  try {
    ResimOptions opt;
    opt.session = c.session;
    opt.discard = true;
    for (const std::string& s : c.sets) opt.settings.push_back(ParseConfigSetting(s));
    if (!OtherDesign(opt)) throw InputError("a cell needs at least one KEY=VALUE (another design)");
    opt.recorded = session->Get();
    return JsonLine(Resimulate(opt).cell);
  } catch (const std::bad_alloc&) {
    why = "out of memory (std::bad_alloc): fewer cells at once (--jobs) may fit";
  } catch (const std::exception& e) {
    why = e.what();
  }
  std::fprintf(stderr, "rms_resim: cell %s: %s\n", c.index.c_str(), why.c_str());
  *failed = true;
  return JsonLine(nlohmann::json{{"error", why}});
}

// A cell as read, with the session it shares with the cells of that
// session that come before and after it.
struct QueuedCell {
  CellLine line;
  std::shared_ptr<SharedSession> session;
};

// The cells read and not yet taken by the threads that run them.
class CellQueue {
 public:
  void Push(QueuedCell c) {
    {
      const std::lock_guard<std::mutex> lock(mu_);
      cells_.push_back(std::move(c));
    }
    ready_.notify_one();
  }
  // No more cells: each thread takes what is left, then ends.
  void Close() {
    {
      const std::lock_guard<std::mutex> lock(mu_);
      closed_ = true;
    }
    ready_.notify_all();
  }
  // The next cell; none once closed and empty.
  std::optional<QueuedCell> Pop() {
    std::unique_lock<std::mutex> lock(mu_);
    ready_.wait(lock, [this] { return closed_ || !cells_.empty(); });
    if (cells_.empty()) return std::nullopt;
    QueuedCell c = std::move(cells_.front());
    cells_.pop_front();
    return c;
  }

 private:
  std::mutex mu_;
  std::condition_variable ready_;
  std::deque<QueuedCell> cells_;
  bool closed_ = false;
};

// Runs a cell and writes its result line whole, whichever thread runs it.
class CellRunner {
 public:
  void Run(const QueuedCell& c) {
    bool bad = false;
    const std::string json = CellResult(c.line, c.session.get(), &bad);
    if (bad) failed_ = true;
    const std::lock_guard<std::mutex> lock(out_);
    std::printf("%s\t%s\n", c.line.index.c_str(), json.c_str());
    std::fflush(stdout);
  }
  bool failed() const { return failed_; }

 private:
  std::mutex out_;
  std::atomic<bool> failed_{false};
};

// One more thread running `work` (a cell's: one a cell read, up to --jobs).
// False when it cannot be started (a process limit, an address-space
// limit): said, and the cells run on those there are.
bool StartThread(const std::function<void()>& work, int jobs, std::vector<std::thread>* threads) {
  try {
    threads->emplace_back(work);
    return true;
  } catch (const std::system_error& e) {
    std::fprintf(stderr,
                 "rms_resim: --cells --jobs %d: %zu threads could be started (%s): the cells run "
                 "on %zu at once\n",
                 jobs, threads->size(), e.what(), std::max<std::size_t>(threads->size(), 1));
    return false;
  }
}

}  // namespace

int RunCells(std::istream& in, int jobs) {
  RMS_CHECK(jobs >= 1);
  int rc = 0;
  CellRunner runner;
  CellQueue queue;
  const std::function<void()> work = [&] {
    while (const std::optional<QueuedCell> c = queue.Pop()) runner.Run(*c);
  };
  // A thread started with each cell read, up to `jobs` (with one job, or no
  // thread to be had, each cell runs as it is read).
  std::vector<std::thread> threads;
  bool more = jobs > 1;
  std::shared_ptr<SharedSession> session;  // the last cell's (read once for its run of cells)
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
    // A session is freed with the last of its run of cells.
    if (!session || session->dir() != f[2]) session = std::make_shared<SharedSession>(f[2]);
    QueuedCell c{{f[0], f[2], std::vector<std::string>(f.begin() + 3, f.end())}, session};
    if (more && static_cast<int>(threads.size()) < jobs) more = StartThread(work, jobs, &threads);
    if (threads.empty())
      runner.Run(c);
    else
      queue.Push(std::move(c));
  }
  session.reset();
  queue.Close();
  for (std::thread& t : threads) t.join();
  if (runner.failed()) rc = std::max(rc, 1);
  return rc;
}

}  // namespace rms::resim
