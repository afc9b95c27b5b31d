#include "rms/instructor_station/web_server.h"

#include <microhttpd.h>
#include <netdb.h>

#include <arpa/inet.h>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <spdlog/spdlog.h>
#include <sys/socket.h>

#include "rms/base/check.h"
#include "rms/esg_renderer/draw_order.h"
#include "rms/scene_model/scene_model.h"
#include "rms/session_control_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/frame_numbers.h"
#include "rms/wire/malfunction.h"

#include "page.h"

namespace rms::instructor_station {

std::int64_t ControlQueue::Push(ControlRequest r) {
  std::lock_guard<std::mutex> lock(mu_);
  r.id = next_id_++;
  queue_.push_back(std::move(r));
  return queue_.back().id;
}

std::vector<ControlRequest> ControlQueue::Drain(std::int64_t now_us) {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<ControlRequest> out;
  // In order: one not yet due holds back those after it.
  std::size_t n = 0;
  while (n < queue_.size() && queue_[n].not_before_us <= now_us) ++n;
  out.assign(queue_.begin(), queue_.begin() + static_cast<std::ptrdiff_t>(n));
  queue_.erase(queue_.begin(), queue_.begin() + static_cast<std::ptrdiff_t>(n));
  return out;
}

nlohmann::json MapJson(const LabConfig& config) {
  const scene_model::SceneModel model = scene_model::BuildSceneModel(config);
  scene_model::ScenePose pose;
  pose.p_RoPo_R_ft = config.payload.p_RoPo_R_ft;
  pose.R_RP = config.payload.R_RP;
  const scene_model::ClusterPoses poses = scene_model::ComputeClusterPoses(config, pose);
  nlohmann::json outlines = nlohmann::json::array();
  for (int id = 0; id < scene_model::kNumClusters; ++id) {
    const scene_model::Cluster& c = model[id];
    if (!c.is_static() || c.points.empty()) continue;
    std::vector<Eigen::Vector2f> xy;
    for (const Eigen::Vector3d& p : c.points) {
      const Eigen::Vector3d p_R = poses.X_RC[id] * p;
      xy.emplace_back(static_cast<float>(p_R.x()), static_cast<float>(p_R.y()));
    }
    nlohmann::json pts = nlohmann::json::array();
    for (const Eigen::Vector2f& q : esg_renderer::ConvexHull2d(xy)) pts.push_back({q.x(), q.y()});
    outlines.push_back({{"name", scene_model::ClusterName(id)},
                        {"group", c.group == scene_model::ClusterGroup::kCae ? "cae" : "orbiter"},
                        {"points", pts}});
  }
  nlohmann::json stations = nlohmann::json::array();
  for (const auto& cam : config.cameras) stations.push_back(cam.name);
  // The page's malfunction menu, from the one table (rms/wire/malfunction.h).
  nlohmann::json joints = nlohmann::json::array();
  for (int j = 1; j <= wire::kNumJoints; ++j) joints.push_back(wire::JointName(j));
  // Each part's word and the names of its numbers (none: it has no number).
  nlohmann::json parts = nlohmann::json::object();
  for (const wire::MalfunctionPartInfo& p : wire::kMalfunctionParts) {
    parts[p.word] = p.part == wire::MalfunctionPart::kJoint    ? joints
                    : p.part == wire::MalfunctionPart::kCamera ? stations
                                                               : nlohmann::json::array();
    RMS_CHECK(static_cast<int>(parts[p.word].size()) == p.count);
  }
  nlohmann::json kinds = nlohmann::json::array();
  for (const wire::MalfunctionKindInfo& k : wire::kMalfunctionKinds) {
    kinds.push_back({{"name", k.name},
                     {"part", wire::PartInfo(k.part).word},
                     {"pattern", k.pattern},
                     {"value", k.value},
                     {"min", k.min_value},
                     {"max", k.max_value},
                     {"typical", k.typical_value}});
  }
  return {{"outlines", outlines},
          {"payload_ft", {config.payload.p_RoPo_R_ft.x(), config.payload.p_RoPo_R_ft.y()}},
          {"stations", stations},
          {"malfunctions", kinds},
          {"parts", parts},
          {"joints", joints}};
}

namespace {

// JSON text, whatever bytes the session's messages carried: a stranger's
// invalid UTF-8 in a process or checkpoint name becomes U+FFFD instead of
// breaking the answer (and so the page).
std::string Json(const nlohmann::json& j) {
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// Equal in time independent of where they differ.
bool SameToken(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

// One request, as the routes see it: the query's and a form body's
// parameters together (the first of each name).
struct Request {
  std::string method, path, token;
  std::map<std::string, std::string> params;
  bool has_param(const char* n) const { return params.count(n) > 0; }
  std::string param(const char* n) const {
    auto it = params.find(n);
    return it == params.end() ? std::string() : it->second;
  }
};

struct Answer {
  unsigned status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;
};

std::int64_t IntParam(const Request& req, const char* name, std::int64_t fallback, std::int64_t lo,
                      std::int64_t hi) {
  if (!req.has_param(name)) return fallback;
  const std::string v = req.param(name);
  char* end = nullptr;
  const long long n = v.empty() || !std::isdigit(static_cast<unsigned char>(v[0]))
                          ? -1
                          : std::strtoll(v.c_str(), &end, 10);
  if (n < 0 || !end || *end != '\0' || n < lo || n > hi) {
    throw InputError(std::string("parameter ") + name + "='" + v.substr(0, 32) + "': a number " +
                     std::to_string(lo) + ".." + std::to_string(hi));
  }
  return n;
}

std::int8_t CommandCode(const std::string& c) {
  if (c == "freeze") return session_control_t::FREEZE;
  if (c == "run") return session_control_t::RUN;
  if (c == "step") return session_control_t::STEP;
  if (c == "checkpoint") return session_control_t::CHECKPOINT;
  if (c == "restore") return session_control_t::RESTORE;
  if (c == "reset") return session_control_t::RESET;
  if (c == "malfunction") return session_control_t::MALFUNCTION;
  if (c == "repair") return session_control_t::REPAIR;
  throw InputError("command '" + c.substr(0, 32) +
                   "': freeze, run, step, checkpoint, restore, reset, malfunction or repair");
}

// What a connection has sent so far (libmicrohttpd calls back as a body arrives).
struct Upload {
  Request request;
  MHD_PostProcessor* form = nullptr;
  std::size_t bytes = 0;
  bool answered = false;  // a response is queued
  ~Upload() {
    if (form) MHD_destroy_post_processor(form);
  }
};

MHD_Result TakeFormValue(void* cls, MHD_ValueKind, const char* key, const char*, const char*,
                         const char*, const char* data, std::uint64_t off, std::size_t size) {
  auto* u = static_cast<Upload*>(cls);
  if (!key) return MHD_YES;
  std::string& v = u->request.params[key];
  if (off == 0 && !v.empty()) return MHD_YES;  // the first of each name
  v.append(data ? data : "", size);
  return MHD_YES;
}

MHD_Result TakeQueryValue(void* cls, MHD_ValueKind, const char* key, const char* value) {
  auto* r = static_cast<Request*>(cls);
  if (key) r->params.emplace(key, value ? value : "");
  return MHD_YES;
}

}  // namespace

// Connections (docs/instructor.md "Bounds"): served by a few threads over
// epoll, so an idle or slow client holds no worker; at most kMaxConnections
// at once and kMaxPerClient from one address (more are refused as they
// connect); a connection silent for kIdleSeconds -- before its header is
// whole, or between requests -- is closed; a request's header and body
// together at most kMaxRequestBytes.
constexpr unsigned kWorkers = 4;
constexpr unsigned kMaxConnections = 512;
constexpr unsigned kMaxPerClient = 64;
constexpr unsigned kIdleSeconds = 5;
constexpr std::size_t kMaxRequestBytes = 64 * 1024;

struct WebServer::Impl {
  const LabConfig& config;
  InstructorOptions options;
  SessionWatch* watch;
  StationViews* views;
  ControlQueue* controls;
  InstructorLesson* lesson;
  Counters* counters;
  MHD_Daemon* daemon = nullptr;
  std::string map_json;
  std::atomic<std::int64_t> requests{0}, refused{0}, sent{0};

  // Every request needs the token, on loopback too: a page from elsewhere
  // in the same browser (or one reached through DNS rebinding) can then
  // neither send commands nor read the session.
  bool Allowed(const Request& req) const {
    if (options.token.empty()) return true;
    std::string t = req.token;
    if (t.empty()) t = req.param("token");
    return SameToken(t, options.token);
  }

  Answer Serve(const Request& req);
  Answer Route(const Request& req);
  Answer Control(const Request& req);
  Answer RefusedInDebrief(const char* why);
  Answer PastView(const Request& req, int view);
  Answer Mark(const Request& req);
  Answer LoadLesson(const Request& req);
  nlohmann::json LessonJson() const;
  Answer Checkpoints() const;
  static MHD_Result OnRequest(void* cls, MHD_Connection* c, const char* url, const char* method,
                              const char* version, const char* upload, std::size_t* upload_size,
                              void** con_cls);
  static void OnCompleted(void* cls, MHD_Connection* c, void** con_cls,
                          MHD_RequestTerminationCode toe);
};

Answer WebServer::Impl::Serve(const Request& req) {
  ++requests;
  Answer a;
  if (req.path == "/favicon.ico") {  // browsers ask, without the page's token: nothing to give
    a.status = 204;
    return a;
  }
  if (!Allowed(req)) {
    ++refused;
    a.status = 403;
    a.content_type = "text/plain";
    a.body = "403: this needs the session's token (the URL the launcher printed)\n";
    return a;
  }
  try {
    return Route(req);
  } catch (const std::exception& e) {
    ++refused;
    a.status = 400;
    a.body = Json(nlohmann::json{{"error", e.what()}});
    return a;
  }
}

Answer WebServer::Impl::Route(const Request& req) {
  Answer a;
  const bool get = req.method == "GET" || req.method == "HEAD";
  if (get && req.path == "/") {
    a.content_type = "text/html; charset=utf-8";
    a.body = kPageHtml;
  } else if (get && req.path == "/api/status") {
    a.body = Json(watch->StatusJson());
  } else if (get && req.path == "/api/events") {
    const std::int64_t since = IntParam(req, "since", 0, 0, std::int64_t{1} << 40);
    a.body = Json(watch->EventsJson(since, SessionWatch::kMaxEventsAnswer));
  } else if (get && req.path == "/api/path") {
    const auto since =
        static_cast<std::size_t>(IntParam(req, "since", 0, 0, std::int64_t{1} << 40));
    a.body = Json(watch->PathJson(since));
  } else if (get && req.path == "/api/map") {
    a.body = map_json;
  } else if (get && req.path == "/api/checkpoints") {
    return Checkpoints();
  } else if (get && req.path == "/api/view") {
    const int v = static_cast<int>(IntParam(req, "v", 0, 0, kNumViews - 1));
    if (req.has_param("frame")) return PastView(req, v);
    views->Request(v);
    const ViewImage img = views->Latest(v);
    a.headers = {{"Cache-Control", "no-store"}, {"X-Rmslab-Frame", std::to_string(img.frame)}};
    if (img.png.empty()) {
      a.status = 503;  // not drawn yet: asked for now, try again shortly
      a.content_type = "text/plain";
      a.body = "not drawn yet\n";
    } else {
      a.content_type = "image/png";
      a.body.assign(reinterpret_cast<const char*>(img.png.data()), img.png.size());
    }
  } else if (req.method == "POST" && req.path == "/api/control") {
    return Control(req);
  } else if (get && req.path == "/api/command") {
    if (!req.has_param("id")) throw InputError("parameter id: the id /api/control answered");
    const std::int64_t id = IntParam(req, "id", 0, 0, std::int64_t{1} << 40);
    a.body = Json(watch->CommandJson(id));
  } else if (get && req.path == "/api/plot") {
    const auto since =
        static_cast<std::size_t>(IntParam(req, "since", 0, 0, std::int64_t{1} << 40));
    a.body = Json(watch->PlotJson(since));
  } else if (get && req.path == "/api/marks") {
    a.body = Json(watch->MarksJson());
  } else if (req.method == "POST" && req.path == "/api/mark") {
    return Mark(req);
  } else if (get && req.path == "/api/lesson") {
    a.body = Json(LessonJson());
  } else if (req.method == "POST" && req.path == "/api/lesson") {
    return LoadLesson(req);
  } else {
    ++refused;
    a.status = 404;
    a.content_type = "text/plain";
    a.body = "404: no such page\n";
  }
  return a;
}

// A debrief replays a recorded session: a command or a lesson is refused
// (409, counted as refused) with why.
Answer WebServer::Impl::RefusedInDebrief(const char* why) {
  Answer a;
  a.status = 409;
  a.body = Json(nlohmann::json{{"error", std::string("a debrief of a recorded session: ") + why}});
  ++refused;
  return a;
}

Answer WebServer::Impl::Control(const Request& req) {
  if (options.debrief) return RefusedInDebrief("nothing to control");
  const std::string command = req.param("command");
  ControlRequest r;
  r.command = CommandCode(command);
  if (r.command == session_control_t::CHECKPOINT || r.command == session_control_t::RESTORE) {
    r.name = req.param("name");
    if (r.name.size() < 5 || r.name.compare(r.name.size() - 5, 5, ".json") != 0) r.name += ".json";
    wire::CheckpointFolder::ValidateName(r.name);  // InputError: said to the page
  }
  // docs/sessions.md "Malfunctions": checked here (InputError: said to the
  // page), sent in the canonical text.
  const std::string what = req.param("name");
  if (r.command == session_control_t::MALFUNCTION)
    r.name = wire::MalfunctionText(wire::ParseMalfunction(what));
  if (r.command == session_control_t::REPAIR) r.name = wire::RepairText(wire::ParseRepair(what));
  // A step's count goes in its name: one command, one answer.
  if (r.command == session_control_t::STEP) {
    const std::int64_t n = IntParam(req, "n", 1, 1, session_control_t::MAX_STEPS);
    if (n > 1) r.name = std::to_string(n);
  }
  // A freeze or run by hand: the instructor's to run again, not a lesson's
  // timed freeze's (docs/lessons.md "From the instructor's station").
  if (r.command == session_control_t::FREEZE || r.command == session_control_t::RUN)
    lesson->CancelTimedRuns();
  // docs/sessions.md "Freeze, run, step, checkpoint": a restore freezes the
  // session first and lets the last frames through, as scripts/lab control
  // does, so the DCP restores with no frame in flight.
  if (r.command == session_control_t::RESTORE) {
    controls->Push({session_control_t::FREEZE, "", -1, 0});
    r.not_before_us = transport::WallTimeUs() + 300'000;
  }
  const std::int64_t id = controls->Push(r);
  ++sent;
  // Its outcome comes as the processes answer: GET /api/command?id=ID.
  Answer a;
  a.body = Json(nlohmann::json{{"id", id}, {"command", command}, {"name", r.name}});
  return a;
}

// GET /api/view?v=V&frame=F: view V at DCP frame F (the nearest kept at or
// before it), drawn on the LCM thread: 503 until it is (ask again).
Answer WebServer::Impl::PastView(const Request& req, int v) {
  const std::int64_t frame = IntParam(req, "frame", 0, 0, wire::kMaxFrameNumber);
  Answer a;
  a.headers = {{"Cache-Control", "no-store"}};
  if (watch->HistoryRange().first < 0) {
    a.status = 404;
    a.content_type = "text/plain";
    a.body = "no DCP frame kept yet\n";
    return a;
  }
  const ViewImage img = views->Past(v, frame);
  if (img.png.empty()) views->RequestPast(v, frame);
  if (img.png.empty()) {
    a.status = 503;
    a.content_type = "text/plain";
    a.body = "not drawn yet\n";
    return a;
  }
  a.headers.emplace_back("X-Rmslab-Frame", std::to_string(img.frame));
  a.content_type = "image/png";
  a.body.assign(reinterpret_cast<const char*>(img.png.data()), img.png.size());
  return a;
}

// POST /api/mark: form fields `text` (1..500 bytes) and `t` (session time,

namespace {

// "12", "12.5": digits with at most one point (no sign, exponent, hex or
// spaces, which strtod would take).
bool PlainDecimal(const std::string& v) {
  if (v.empty() || v.size() > 32 || v.front() == '.' || v.back() == '.') return false;
  int points = 0;
  for (char c : v) {
    if (c == '.')
      ++points;
    else if (c < '0' || c > '9')
      return false;
  }
  return points <= 1;
}

// A Unicode direction embedding, override or isolate (UTF-8 E2 80 AA..AE,
// E2 81 A6..A9): shown, it reverses the text around it.
bool HasBidiControl(const std::string& s) {
  for (std::size_t i = 0; i + 2 < s.size(); ++i) {
    const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
    if (b(0) != 0xE2) continue;
    if ((b(1) == 0x80 && b(2) >= 0xAA && b(2) <= 0xAE) ||
        (b(1) == 0x81 && b(2) >= 0xA6 && b(2) <= 0xA9))
      return true;
  }
  return false;
}

}  // namespace

// s; default: the newest frame's).
Answer WebServer::Impl::Mark(const Request& req) {
  std::string text = req.param("text");
  if (text.empty() || text.size() > SessionWatch::kMaxMarkTextBytes)
    throw InputError("form field 'text': a note of 1.." +
                     std::to_string(SessionWatch::kMaxMarkTextBytes) + " bytes");
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  if (HasBidiControl(text))
    throw InputError(
        "form field 'text': a direction control (U+202A..U+202E, U+2066..U+2069) would show "
        "the note as other text: refused");
  double t_s = 0.0;
  if (req.has_param("t")) {
    const std::string v = req.param("t");
    char* end = nullptr;
    t_s = std::strtod(v.c_str(), &end);
    if (!PlainDecimal(v) || !end || *end != '\0' || !std::isfinite(t_s) || t_s < 0 ||
        t_s > SessionWatch::kMaxMarkSessionS)
      throw InputError("parameter t='" + v.substr(0, 32) + "': a session time, s, 0..1e7");
  } else if (const auto d = watch->LatestDcpFrame()) {
    t_s = static_cast<double>(d->frame) / config.session.frame_rate_hz;
  }
  Answer a;
  a.body = Json(watch->AddMark(t_s, text));
  return a;
}

// docs/lessons.md "From the instructor's station": a lesson file's text
// (form field `text`, within the request's 64 KiB) and its name (`name`,
// for the page), checked as the operator station checks one: refused (400,
// the key and the reason) with the lesson in force unchanged.
Answer WebServer::Impl::LoadLesson(const Request& req) {
  if (options.debrief) return RefusedInDebrief("no lesson can fire");
  std::string name = req.param("name").substr(0, 100);
  for (char& c : name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';  // shown on the page
  std::string source = "the page's lesson";
  if (!name.empty()) source.append(" ").append(name);
  if (!req.has_param("text"))
    throw InputError("form field 'text' missing: the lesson file's TOML (docs/lessons.md)");
  const auto t = watch->LatestTelemetry();
  const double session_s =
      t ? static_cast<double>(t->input_frame + 1) / config.session.frame_rate_hz : 0.0;
  try {
    lesson->Load(req.param("text"), source, session_s);
  } catch (const InputError& e) {
    spdlog::warn("lesson from the page refused: {}", e.what());
    throw;
  }
  spdlog::info("lesson loaded from the page: {}", source);
  watch->NoteLocal("lesson", "lesson loaded: " + source);
  Answer a;
  a.body = Json(LessonJson());
  return a;
}

// The lesson, each fired event with what became of its command
// (/api/command's answer: done, refused with the reason, pending).
nlohmann::json WebServer::Impl::LessonJson() const {
  nlohmann::json j = lesson->Json();
  for (nlohmann::json& e : j["events"]) {
    if (e["command_id"].is_number_integer())
      e["outcome"] = watch->CommandJson(e["command_id"].get<std::int64_t>());
  }
  return j;
}

Answer WebServer::Impl::Checkpoints() const {
  std::vector<std::string> names;  // by name, for the page's list
  std::error_code ec;
  if (!options.checkpoint_dir.empty()) {
    for (const auto& e : std::filesystem::directory_iterator(options.checkpoint_dir, ec)) {
      const std::string n = e.path().filename().string();
      if (e.is_regular_file(ec) && !e.is_symlink(ec) && n.size() > 5 &&
          n.compare(n.size() - 5, 5, ".json") == 0 && names.size() < 1000)
        names.push_back(n);
    }
  }
  std::sort(names.begin(), names.end());
  Answer a;
  a.body = Json(nlohmann::json(names));
  return a;
}

namespace {

MHD_Result Queue(MHD_Connection* c, const Answer& a) {
  MHD_Response* res = MHD_create_response_from_buffer(
      a.body.size(), const_cast<char*>(a.body.data()), MHD_RESPMEM_MUST_COPY);
  MHD_add_response_header(res, "Content-Type", a.content_type.c_str());
  for (const auto& [k, v] : a.headers) MHD_add_response_header(res, k.c_str(), v.c_str());
  const MHD_Result ok = MHD_queue_response(c, a.status, res);
  MHD_destroy_response(res);
  return ok;
}

Answer TooLarge() {
  Answer a;
  a.status = 413;
  a.content_type = "text/plain";
  a.body = "413: a request's body is at most 64 KiB\n";
  return a;
}

}  // namespace

// libmicrohttpd's callback: first with the header (an Upload made), then
// with each piece of the body, then once more to answer. A body declared or
// found larger than kMaxRequestBytes is answered 413 at once, the rest of
// it not read.
MHD_Result WebServer::Impl::OnRequest(void* cls, MHD_Connection* c, const char* url,
                                      const char* method, const char*, const char* upload,
                                      std::size_t* upload_size, void** con_cls) {
  auto* self = static_cast<Impl*>(cls);
  auto* u = static_cast<Upload*>(*con_cls);
  auto refuse = [&] {
    ++self->requests;
    ++self->refused;
    u->answered = true;
    return Queue(c, TooLarge());
  };
  if (!u) {
    u = new Upload;
    *con_cls = u;
    u->request.method = method ? method : "";
    u->request.path = url ? url : "";
    if (const char* t = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "X-Rmslab-Token"))
      u->request.token = t;
    if (u->request.method == "POST") u->form = MHD_create_post_processor(c, 4096, TakeFormValue, u);
    const char* n = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Content-Length");
    if (n && std::strtoull(n, nullptr, 10) > kMaxRequestBytes) return refuse();
    return MHD_YES;
  }
  if (u->answered) {  // the rest of a body refused
    *upload_size = 0;
    return MHD_YES;
  }
  if (*upload_size > 0) {
    u->bytes += *upload_size;
    if (u->bytes > kMaxRequestBytes) {
      *upload_size = 0;
      return refuse();
    }
    if (u->form) MHD_post_process(u->form, upload, *upload_size);
    *upload_size = 0;
    return MHD_YES;
  }
  Request& req = u->request;
  MHD_get_connection_values(c, MHD_GET_ARGUMENT_KIND, TakeQueryValue, &req);
  u->answered = true;
  return Queue(c, self->Serve(req));
}

void WebServer::Impl::OnCompleted(void*, MHD_Connection*, void** con_cls,
                                  MHD_RequestTerminationCode) {
  delete static_cast<Upload*>(*con_cls);
  *con_cls = nullptr;
}

WebServer::WebServer(const LabConfig& config, const InstructorOptions& options, SessionWatch* watch,
                     StationViews* views, ControlQueue* controls, InstructorLesson* lesson,
                     Counters* counters)
    : impl_(new Impl{
          config, options, watch, views, controls, lesson, counters, nullptr, {}, {}, {}, {}}) {
  impl_->map_json = Json(MapJson(config));
}

WebServer::~WebServer() { Stop(); }

namespace {

// The address to serve on, numeric or a name this host resolves.
sockaddr_storage BindAddress(const std::string& bind, int port) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (getaddrinfo(bind.c_str(), service.c_str(), &hints, &found) != 0 || !found) {
    throw transport::TransportError("cannot serve the page on " + bind +
                                    ": not an address of this host");
  }
  sockaddr_storage a{};
  std::memcpy(&a, found->ai_addr, std::min<std::size_t>(found->ai_addrlen, sizeof a));
  freeaddrinfo(found);
  return a;
}

int BoundPort(const sockaddr_storage& a) {
  return ntohs(a.ss_family == AF_INET6 ? reinterpret_cast<const sockaddr_in6&>(a).sin6_port
                                       : reinterpret_cast<const sockaddr_in&>(a).sin_port);
}

}  // namespace

int WebServer::Start() {
  Impl& s = *impl_;
  sockaddr_storage addr = BindAddress(s.options.bind, s.options.port);
  unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_EPOLL;
  if (addr.ss_family == AF_INET6) flags |= MHD_USE_IPv6;
  s.daemon = MHD_start_daemon(
      flags, static_cast<std::uint16_t>(s.options.port), nullptr, nullptr, &Impl::OnRequest, &s,
      MHD_OPTION_SOCK_ADDR, reinterpret_cast<sockaddr*>(&addr), MHD_OPTION_THREAD_POOL_SIZE,
      kWorkers, MHD_OPTION_CONNECTION_LIMIT, kMaxConnections, MHD_OPTION_PER_IP_CONNECTION_LIMIT,
      kMaxPerClient, MHD_OPTION_CONNECTION_TIMEOUT, kIdleSeconds,
      MHD_OPTION_CONNECTION_MEMORY_LIMIT, static_cast<std::size_t>(128 * 1024),
      MHD_OPTION_NOTIFY_COMPLETED, &Impl::OnCompleted, &s, MHD_OPTION_END);
  int port = 0;
  if (s.daemon) {
    const MHD_DaemonInfo* info = MHD_get_daemon_info(s.daemon, MHD_DAEMON_INFO_BIND_PORT);
    port = info ? info->port : BoundPort(addr);
  }
  if (port == 0) {
    throw transport::TransportError("cannot serve the page on " + s.options.bind + ":" +
                                    std::to_string(s.options.port) +
                                    " (in use, or not an address of this host): choose another "
                                    "with --instructor PORT");
  }
  return port;
}

void WebServer::Stop() {
  if (!impl_ || !impl_->daemon) return;
  MHD_stop_daemon(impl_->daemon);
  impl_->daemon = nullptr;
}

std::int64_t WebServer::requests() const { return impl_->requests; }
std::int64_t WebServer::refused() const { return impl_->refused; }
std::int64_t WebServer::sent() const { return impl_->sent; }

}  // namespace rms::instructor_station
