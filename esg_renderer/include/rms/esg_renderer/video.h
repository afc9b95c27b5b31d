#pragma once
// The session's video: frames piped raw to ffmpeg (libx264, from Debian) by
// a writer thread, so encoding never holds up the frame loop. The queue holds
// up to kMaxQueueBytes of frames (256 MiB: 85 frames at 1024x768, thousands
// at a small size), so a stall of the encoder (a loaded machine) is ridden
// out; a full queue drops the frame (counted, video.dropped), never blocks
// (docs/esg.md "Video").
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace rms::esg_renderer {

class VideoWriter {
 public:
  // Starts ffmpeg writing `path` (H.264, yuv420p) at `fps`. Throws
  // std::runtime_error when it cannot (odd size, no ffmpeg).
  VideoWriter(const std::string& path, int width, int height, double fps);
  ~VideoWriter();  // finishes the file
  // Queues one frame (RGBA, rows top down), `repeat` times (to keep the
  // video's time when frames were skipped).
  void Add(const std::uint8_t* rgba, int repeat = 1);
  void Close();
  std::int64_t frames_written() const { return written_; }
  std::int64_t frames_dropped() const { return dropped_; }

 private:
  void Run();
  int width_, height_;
  int pipe_fd_ = -1;
  int pid_ = -1;
  std::thread thread_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::pair<std::vector<std::uint8_t>, int>> queue_;
  bool closing_ = false;
  bool closed_ = false;
  std::int64_t written_ = 0, dropped_ = 0;
  std::size_t queued_bytes_ = 0;
  static constexpr std::size_t kMaxQueueBytes = std::size_t{256} << 20;
};

}  // namespace rms::esg_renderer
