#include "lab_processes.h"

#include <signal.h>

#include <filesystem>

namespace rms::testing {

LabProcesses::LabProcesses(std::string dir, std::string url, std::vector<std::string> esg_args)
    : dir_(std::move(dir)), url_(std::move(url)), esg_args_(std::move(esg_args)) {}

LabProcesses::~LabProcesses() = default;  // Subprocess kills what is left

std::unique_ptr<Subprocess> LabProcesses::StartOne(const std::string& name,
                                                   std::vector<std::string> args,
                                                   const std::vector<std::string>& env) {
  std::vector<std::string> argv = {BuildPath(name + "/" + name),
                                   "--lcm-url",
                                   url_,
                                   "--stats",
                                   dir_ + "/" + name + ".json",
                                   "--ready-file",
                                   dir_ + "/" + name + ".ready"};
  argv.insert(argv.end(), args.begin(), args.end());
  return std::make_unique<Subprocess>(argv, dir_ + "/" + name + ".log", env);
}

bool LabProcesses::Start(std::string* error) {
  procs_.emplace_back("esg_renderer", StartOne("esg_renderer", esg_args_, esg_env_));
  procs_.emplace_back("scene_proc", StartOne("scene_proc", {}));
  std::filesystem::create_directories(dir_ + "/checkpoints");
  procs_.emplace_back("dynamics_proc",
                      StartOne("dynamics_proc", {"--checkpoint-dir", dir_ + "/checkpoints"}));
  for (const auto& [name, p] : procs_) {
    if (!WaitForFile(dir_ + "/" + name + ".ready", 15)) {
      *error = name + " did not start:\n" + ReadFile(dir_ + "/" + name + ".log");
      return false;
    }
  }
  return true;
}

int LabProcesses::Fly(transport::UdpLcm& lcm, const std::string& timeline,
                      const std::vector<std::string>& extra) {
  lcm.HandleSubscriptions(0);
  std::vector<std::string> argv = {BuildPath("operator_station/operator_station"),
                                   "--lcm-url",
                                   url_,
                                   "--timeline",
                                   timeline,
                                   "--stats",
                                   dir_ + "/operator_station.json"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  Subprocess op(argv, dir_ + "/operator_station.log");
  while (op.Running()) lcm.HandleSubscriptions(20);
  for (int i = 0; i < 25; ++i) lcm.HandleSubscriptions(20);  // the last frames in flight
  return op.Wait(1);
}

bool LabProcesses::Stop(std::string* error) {
  for (auto& [name, p] : procs_) p->Signal(SIGINT);
  bool ok = true;
  for (auto& [name, p] : procs_) {
    const int rc = p->Wait(10);
    if (rc != 0) {
      ok = false;
      *error +=
          name + " exited " + std::to_string(rc) + ":\n" + ReadFile(dir_ + "/" + name + ".log");
    }
  }
  procs_.clear();
  return ok;
}

}  // namespace rms::testing
