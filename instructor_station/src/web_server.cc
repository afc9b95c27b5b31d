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
  return {{"outlines", outlines},
          {"payload_ft", {config.payload.p_RoPo_R_ft.x(), config.payload.p_RoPo_R_ft.y()}},
          {"stations", stations}};
}

namespace {

bool Loopback(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "::1";
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
  throw InputError("command '" + c.substr(0, 32) +
                   "': freeze, run, step, checkpoint, restore or reset");
}

}  // namespace

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

  // Which requests need the token: every one when served beyond loopback;
  // on loopback the commands (a page elsewhere in the browser cannot send
  // them: it does not know the token).
  bool Allowed(const httplib::Request& req) const {
    if (options.token.empty()) return true;
    const bool needs = !Loopback(options.bind) || req.method != "GET";
    if (!needs) return true;
    std::string t = req.get_header_value("X-Rmslab-Token");
    if (t.empty() && req.has_param("token")) t = req.get_param_value("token");
    return SameToken(t, options.token);
  }

  void Routes();
  void Control(const httplib::Request& req, httplib::Response& res);
  void Checkpoints(httplib::Response& res) const;
};

void WebServer::Impl::Routes() {
  server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    ++requests;
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
        res.set_content(nlohmann::json{{"error", what}}.dump(), "application/json");
      });
  server.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(kPageHtml, "text/html; charset=utf-8");
  });
  server.Get("/api/status", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(watch->StatusJson().dump(), "application/json");
  });
  server.Get("/api/events", [this](const httplib::Request& req, httplib::Response& res) {
    const std::int64_t since = IntParam(req, "since", 0, 0, std::int64_t{1} << 40);
    res.set_content(watch->EventsJson(since, 1000).dump(), "application/json");
  });
  server.Get("/api/path", [this](const httplib::Request& req, httplib::Response& res) {
    const auto since =
        static_cast<std::size_t>(IntParam(req, "since", 0, 0, std::int64_t{1} << 40));
    res.set_content(watch->PathJson(since).dump(), "application/json");
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
  const int steps =
      r.command == session_control_t::STEP ? static_cast<int>(IntParam(req, "n", 1, 1, 300)) : 1;
  for (int i = 0; i < steps; ++i) controls->Push(r);
  sent += steps;
  res.set_content(nlohmann::json{{"sent", command}, {"name", r.name}, {"times", steps}}.dump(),
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
  res.set_content(names.dump(), "application/json");
}

WebServer::WebServer(const LabConfig& config, const InstructorOptions& options, SessionWatch* watch,
                     StationViews* views, ControlQueue* controls, Counters* counters)
    : impl_(new Impl{config, options, watch, views, controls, counters, {}, {}, {}, {}, {}, {}}) {
  impl_->map_json = MapJson(config).dump();
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
