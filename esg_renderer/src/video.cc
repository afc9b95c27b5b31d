#include "rms/esg_renderer/video.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <sys/wait.h>

extern char** environ;

namespace rms::esg_renderer {

VideoWriter::VideoWriter(const std::string& path, int width, int height, double fps)
    : width_(width), height_(height) {
  if (width % 2 || height % 2) throw std::runtime_error("video needs an even width and height");
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  const std::string rate = std::to_string(fps);
  std::vector<std::string> args = {
      "ffmpeg", "-loglevel", "error",   "-y",        "-f",       "rawvideo", "-pix_fmt",
      "rgba",   "-s",        size,      "-r",        rate,       "-i",       "-",
      "-c:v",   "libx264",   "-preset", "ultrafast", "-pix_fmt", "yuv420p",  path};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, fds[0], 0);
  posix_spawn_file_actions_addclose(&fa, fds[1]);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, "ffmpeg", &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  close(fds[0]);
  if (rc != 0) {
    close(fds[1]);
    throw std::runtime_error("cannot start ffmpeg (install the Debian package ffmpeg)");
  }
  pid_ = pid;
  pipe_fd_ = fds[1];
  thread_ = std::thread([this] { Run(); });
}

VideoWriter::~VideoWriter() { Close(); }

void VideoWriter::Add(const std::uint8_t* rgba, int repeat) {
  std::lock_guard<std::mutex> lock(mu_);
  if (closing_) return;
  const std::size_t bytes = static_cast<std::size_t>(width_) * height_ * 4;
  if (!queue_.empty() && queued_bytes_ + bytes > kMaxQueueBytes) {
    dropped_ += repeat;
    return;
  }
  queue_.emplace_back(std::vector<std::uint8_t>(rgba, rgba + bytes), repeat);
  queued_bytes_ += bytes;
  cv_.notify_one();
}

void VideoWriter::Run() {
  for (;;) {
    std::pair<std::vector<std::uint8_t>, int> item;
    {
      std::unique_lock<std::mutex> lock(mu_);
      cv_.wait(lock, [&] { return closing_ || !queue_.empty(); });
      if (queue_.empty()) return;
      item = std::move(queue_.front());
      queue_.pop_front();
      queued_bytes_ -= item.first.size();
    }
    for (int r = 0; r < item.second; ++r) {
      const std::uint8_t* p = item.first.data();
      std::size_t left = item.first.size();
      while (left > 0) {
        const ssize_t n = write(pipe_fd_, p, left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return;  // ffmpeg went away
        p += n;
        left -= static_cast<std::size_t>(n);
      }
      ++written_;
    }
  }
}

void VideoWriter::Close() {
  if (closed_) return;
  closed_ = true;
  {
    std::lock_guard<std::mutex> lock(mu_);
    closing_ = true;
    cv_.notify_one();
  }
  if (thread_.joinable()) thread_.join();
  if (pipe_fd_ >= 0) close(pipe_fd_);
  if (pid_ > 0) {
    int status = 0;
    waitpid(pid_, &status, 0);
  }
}

}  // namespace rms::esg_renderer
