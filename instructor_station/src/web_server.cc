#include "rms/instructor_station/web_server.h"

#include <httplib.h>

#include <atomic>
#include <filesystem>
#include <thread>

#include "rms/base/check.h"
#include "rms/esg_renderer/draw_order.h"
#include "rms/scene_model/scene_model.h"
#include "rms/session_control_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/malfunction.h"

#include "page.h"

namespace rms::instructor_station {

void ControlQueue::Push(ControlRequest r) {
  std::lock_guard<std::mutex> lock(mu_);
  queue_.push_back(std::move(r));
}

std::vector<ControlRequest> ControlQueue::Drain() {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<ControlRequest> out;
  out.swap(queue_);
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
  nlohmann::json kinds = nlohmann::json::array();
  for (const wire::MalfunctionKindInfo& k : wire::kMalfunctionKinds) {
    kinds.push_back({{"name", k.name},
                     {"pattern", k.pattern},
                     {"value", k.value},
                     {"min", k.min_value},
                     {"max", k.max_value}});
  }
  nlohmann::json joints = nlohmann::json::array();
  for (int j = 1; j <= wire::kNumJoints; ++j) joints.push_back(wire::JointName(j));
  return {{"outlines", outlines},
          {"payload_ft", {config.payload.p_RoPo_R_ft.x(), config.payload.p_RoPo_R_ft.y()}},
          {"stations", stations},
          {"malfunctions", kinds},
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

std::int64_t IntParam(const httplib::Request& req, const char* name, std::int64_t fallback,
                      std::int64_t lo, std::int64_t hi) {
  if (!req.has_param(name)) return fallback;
  const std::string v = req.get_param_value(name);
  if (v.empty() || !std::isdigit(static_cast<unsigned char>(v[0]))) {
    throw InputError(std::string("parameter ") + name + "='" + v.substr(0, 32) + "': a number " +
                     std::to_string(lo) + ".." + std::to_string(hi));
  }
  char* end = nullptr;
  const long long n = std::strtoll(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || n < lo || n > hi) {
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

}  // namespace

// Requests answered at once; more wait in the listen queue.
constexpr int kWorkers = 32;

struct WebServer::Impl {
  const LabConfig& config;
  InstructorOptions options;
  SessionWatch* watch;
  StationViews* views;
  ControlQueue* controls;
  Counters* counters;
  httplib::Server server;
  std::thread thread;
  std::string map_json;
  std::atomic<std::int64_t> requests{0}, refused{0}, sent{0};

  // Every request needs the token, on loopback too: a page from elsewhere
  // in the same browser (or one reached through DNS rebinding) can then
  // neither send commands nor read the session.
  bool Allowed(const httplib::Request& req) const {
    if (options.token.empty()) return true;
    std::string t = req.get_header_value("X-Rmslab-Token");
    if (t.empty() && req.has_param("token")) t = req.get_param_value("token");
    return SameToken(t, options.token);
  }

  void Routes();
  void Control(const httplib::Request& req, httplib::Response& res);
  void Checkpoints(httplib::Response& res) const;
};

void WebServer::Impl::Routes() {
  // Without SO_REUSEPORT (cpp-httplib sets it by default): a second station
  // on a port in use must fail, not share it and mix two sessions' pages.
  server.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  // A slow or idle client cannot hold a worker for long, nor send much.
  server.set_read_timeout(3, 0);
  server.set_write_timeout(5, 0);
  server.set_keep_alive_timeout(2);
  server.set_payload_max_length(64 * 1024);
  server.new_task_queue = [] { return new httplib::ThreadPool(kWorkers); };
  server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    ++requests;
    if (req.path == "/favicon.ico") {  // browsers ask, without the page's token: nothing to give
      res.status = 204;
      return httplib::Server::HandlerResponse::Handled;
    }
    if (Allowed(req)) return httplib::Server::HandlerResponse::Unhandled;
    ++refused;
    res.status = 403;
    res.set_content("403: this needs the session's token (the URL the launcher printed)\n",
                    "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  });
  server.set_exception_handler(
      [this](const httplib::Request&, httplib::Response& res, const std::exception_ptr& ep) {
        ++refused;
        std::string what = "error";
        try {
          std::rethrow_exception(ep);
        } catch (const std::exception& e) {
          what = e.what();
        } catch (...) {
        }
        res.status = 400;
        res.set_content(Json(nlohmann::json{{"error", what}}), "application/json");
      });
  server.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(kPageHtml, "text/html; charset=utf-8");
  });
  server.Get("/api/status", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(Json(watch->StatusJson()), "application/json");
  });
  server.Get("/api/events", [this](const httplib::Request& req, httplib::Response& res) {
    const std::int64_t since = IntParam(req, "since", 0, 0, std::int64_t{1} << 40);
    res.set_content(Json(watch->EventsJson(since, 1000)), "application/json");
  });
  server.Get("/api/path", [this](const httplib::Request& req, httplib::Response& res) {
    const auto since =
        static_cast<std::size_t>(IntParam(req, "since", 0, 0, std::int64_t{1} << 40));
    res.set_content(Json(watch->PathJson(since)), "application/json");
  });
  server.Get("/api/map", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(map_json, "application/json");
  });
  server.Get("/api/checkpoints",
             [this](const httplib::Request&, httplib::Response& res) { Checkpoints(res); });
  server.Get("/api/view", [this](const httplib::Request& req, httplib::Response& res) {
    const int v = static_cast<int>(IntParam(req, "v", 0, 0, kNumViews - 1));
    views->Request(v);
    const ViewImage img = views->Latest(v);
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Rmslab-Frame", std::to_string(img.frame));
    if (img.png.empty()) {
      res.status = 503;  // not drawn yet: asked for now, try again shortly
      res.set_content("not drawn yet\n", "text/plain");
      return;
    }
    res.set_content(reinterpret_cast<const char*>(img.png.data()), img.png.size(), "image/png");
  });
  server.Post("/api/control",
              [this](const httplib::Request& req, httplib::Response& res) { Control(req, res); });
}

void WebServer::Impl::Control(const httplib::Request& req, httplib::Response& res) {
  const std::string command =
      req.has_param("command") ? req.get_param_value("command") : std::string();
  ControlRequest r;
  r.command = CommandCode(command);
  if (r.command == session_control_t::CHECKPOINT || r.command == session_control_t::RESTORE) {
    r.name = req.has_param("name") ? req.get_param_value("name") : std::string();
    if (r.name.size() < 5 || r.name.compare(r.name.size() - 5, 5, ".json") != 0) r.name += ".json";
    wire::CheckpointFolder::ValidateName(r.name);  // InputError: said to the page
  }
  // docs/sessions.md "Malfunctions": checked here (InputError: said to the
  // page), sent in the canonical text.
  const std::string what = req.has_param("name") ? req.get_param_value("name") : std::string();
  if (r.command == session_control_t::MALFUNCTION)
    r.name = wire::MalfunctionText(wire::ParseMalfunction(what));
  if (r.command == session_control_t::REPAIR) r.name = wire::RepairText(wire::ParseRepair(what));
  const int steps =
      r.command == session_control_t::STEP ? static_cast<int>(IntParam(req, "n", 1, 1, 300)) : 1;
  for (int i = 0; i < steps; ++i) controls->Push(r);
  sent += steps;
  res.set_content(Json(nlohmann::json{{"sent", command}, {"name", r.name}, {"times", steps}}),
                  "application/json");
}

void WebServer::Impl::Checkpoints(httplib::Response& res) const {
  nlohmann::json names = nlohmann::json::array();
  std::error_code ec;
  if (!options.checkpoint_dir.empty()) {
    for (const auto& e : std::filesystem::directory_iterator(options.checkpoint_dir, ec)) {
      const std::string n = e.path().filename().string();
      if (e.is_regular_file(ec) && n.size() > 5 && n.compare(n.size() - 5, 5, ".json") == 0)
        names.push_back(n);
    }
  }
  res.set_content(Json(names), "application/json");
}

WebServer::WebServer(const LabConfig& config, const InstructorOptions& options, SessionWatch* watch,
                     StationViews* views, ControlQueue* controls, Counters* counters)
    : impl_(new Impl{config, options, watch, views, controls, counters, {}, {}, {}, {}, {}, {}}) {
  impl_->map_json = Json(MapJson(config));
  impl_->Routes();
}

WebServer::~WebServer() { Stop(); }

int WebServer::Start() {
  Impl& s = *impl_;
  int port = s.options.port;
  if (port == 0) {
    port = s.server.bind_to_any_port(s.options.bind);
    if (port < 0) port = 0;
  } else if (!s.server.bind_to_port(s.options.bind, port)) {
    port = 0;
  }
  if (port == 0) {
    throw transport::TransportError("cannot serve the page on " + s.options.bind + ":" +
                                    std::to_string(s.options.port) +
                                    " (in use, or not an address of this host): choose another "
                                    "with --instructor PORT");
  }
  s.thread = std::thread([&s] { s.server.listen_after_bind(); });
  return port;
}

void WebServer::Stop() {
  if (!impl_) return;
  impl_->server.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

std::int64_t WebServer::requests() const { return impl_->requests; }
std::int64_t WebServer::refused() const { return impl_->refused; }
std::int64_t WebServer::sent() const { return impl_->sent; }

}  // namespace rms::instructor_station
