#pragma once
// The instructor station's web server (GNU libmicrohttpd, Debian's
// libmicrohttpd-dev: per-client connection limits and idle timeouts over
// epoll, which cpp-httplib 0.11 lacks): the page, its JSON and images, and
// its commands (docs/instructor.md "The page and its API", "Bounds").
// Requests are answered on the server's own threads; commands are queued
// for the LCM thread to send.
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/instructor_station/instructor_lesson.h"
#include "rms/instructor_station/instructor_station.h"
#include "rms/instructor_station/session_watch.h"
#include "rms/instructor_station/station_views.h"

namespace rms::instructor_station {

// A command for RMS_CONTROL (session_control_t), from a web request to the
// LCM thread.
struct ControlRequest {
  std::int8_t command = 0;         // session_control_t::FREEZE ...
  std::string name;                // CHECKPOINT, RESTORE: the checkpoint's name
  std::int64_t id = -1;            // its sequence on the wire (Push gives it)
  std::int64_t not_before_us = 0;  // sent no sooner (wall clock; 0: at once)
};

class ControlQueue {
 public:
  // Queues `r` and gives its id: its session_control_t.sequence, so its
  // answers can be told (RMS_CONTROL_ANSWER).
  std::int64_t Push(ControlRequest r);
  // The requests due by `now_us`, in order.
  std::vector<ControlRequest> Drain(std::int64_t now_us);
  // The first id (a restarted station's: SessionWatch::NextCommandId).
  void set_next_id(std::int64_t id) { next_id_ = id; }

 private:
  std::mutex mu_;
  std::int64_t next_id_ = 0;
  std::vector<ControlRequest> queue_;
};

// The map's static outlines: each fixed cluster of the orbiter and the CAE
// seen from above (x forward up the page, y right), ft.
nlohmann::json MapJson(const LabConfig& config);

class WebServer {
 public:
  WebServer(const LabConfig& config, const InstructorOptions& options, SessionWatch* watch,
            StationViews* views, ControlQueue* controls, InstructorLesson* lesson,
            Counters* counters);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;
  // Binds and serves on a thread of its own; returns the port it listens on.
  // Throws TransportError (the address, the port and why) when it cannot bind.
  int Start();
  void Stop();
  // Counts (atomic: from the server's threads), for the process's counters.
  std::int64_t requests() const;  // http.requests
  std::int64_t refused() const;   // http.refused
  std::int64_t sent() const;      // control.sent

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rms::instructor_station
