#include "rms/wire/checkpoint.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sys/stat.h>

#include "rms/base/check.h"
#include "rms/base/text.h"

namespace rms::wire {

namespace {
constexpr const char* kFormat = "rmslab-checkpoint-1";
}  // namespace

std::string CheckpointText(const Checkpoint& c) {
  nlohmann::ordered_json j;
  j["format"] = kFormat;
  j["saved_us"] = c.saved_us;
  j["dcp_frame"] = c.dcp_frame;
  j["input_frame"] = c.input_frame;
  j["config"] = c.config;
  j["operator_inputs"] = InputsJson(c.inputs);
  j["dcp"] = c.dcp;
  return j.dump(2) + "\n";
}

bool TextHoldsDcp(std::string_view text, const nlohmann::json& dcp, const std::string& path) {
  // CheckpointText's last lines: ',\n  "dcp": ...\n}\n', as {"dcp": dcp}
  // dumps them after its "{".
  nlohmann::ordered_json last;
  last["dcp"] = dcp;
  const std::string tail = last.dump(2).substr(1) + "\n";
  if (text.size() <= tail.size() || text.substr(text.size() - tail.size()) != tail ||
      text[text.size() - tail.size() - 1] != ',')
    return false;
  // The rest, with a null in the state's place: the same JSON or not as the
  // whole, and the same members for ParseCheckpoint to check.
  std::string rest(text.substr(0, text.size() - tail.size()));
  rest += "\n  \"dcp\": null\n}\n";
  ParseCheckpoint(rest, path);
  return true;
}

namespace {

// Reads an open file: a regular one of at most kMaxCheckpointBytes, or refused.
std::string ReadOpenFile(int fd, const std::string& path) {
  struct stat st {};
  if (fstat(fd, &st) != 0)
    throw InputError("cannot read checkpoint '" + path + "': " + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw InputError("checkpoint '" + path + "' is not a regular file: refused");
  if (st.st_size > kMaxCheckpointBytes) {
    throw InputError("checkpoint '" + path + "' is " + std::to_string(st.st_size) +
                     " bytes, more than any checkpoint (" + std::to_string(kMaxCheckpointBytes) +
                     "): refused");
  }
  std::string text(static_cast<std::size_t>(st.st_size), '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
  }
  text.resize(got);
  return text;
}

struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) close(fd);
  }
};
}  // namespace

void WriteCheckpoint(const std::string& path, const Checkpoint& c) {
  std::ofstream f(path);
  if (f) f << CheckpointText(c);
  f.close();
  if (!f) throw InputError("cannot write checkpoint '" + path + "' (" + std::strerror(errno) + ")");
}

Checkpoint ReadCheckpoint(const std::string& path) {
  const Fd f{open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK)};
  if (f.fd < 0) throw InputError("cannot read checkpoint '" + path + "': " + std::strerror(errno));
  return ParseCheckpoint(ReadOpenFile(f.fd, path), path);
}

void CheckpointFolder::ValidateName(const std::string& name) {
  bool ok = !name.empty() && name.size() <= 64 && name[0] != '.' && name.size() > 5 &&
            name.compare(name.size() - 5, 5, ".json") == 0;
  for (char ch : name) {
    ok = ok && ((ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') ||
                ch == '_' || ch == '-' || ch == '.');
  }
  if (!ok) {
    std::string shown;  // printable only: a name must not write lines of its own into a log
    for (char ch : name.substr(0, 80)) {
      shown += (ch >= 0x20 && ch < 0x7f) ? std::string(1, ch)
                                         : Sprintf("\\x%02x", static_cast<unsigned char>(ch));
    }
    throw InputError("checkpoint name '" + shown +
                     "' refused: a name (not a path) of 1 to 64 letters, digits, '_', '-' or '.', "
                     "ending in .json, "
                     "not starting with '.'");
  }
}

int CheckpointFolder::OpenDir() const {
  if (dir_.empty())
    throw InputError("no checkpoints folder was given to this process (--checkpoint-dir): refused");
  // The folder itself, never through a link (one planted in its place while
  // the session runs would send checkpoints elsewhere).
  const int fd = open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  struct stat st {};
  if (fd < 0 && (errno == ELOOP || errno == ENOTDIR) && lstat(dir_.c_str(), &st) == 0 &&
      S_ISLNK(st.st_mode)) {
    throw InputError("the checkpoints folder '" + dir_ + "' is a symbolic link: refused");
  }
  if (fd < 0)
    throw InputError("cannot open the checkpoints folder '" + dir_ + "': " + std::strerror(errno));
  return fd;
}

void CheckpointFolder::Write(const std::string& name, const Checkpoint& c) const {
  ValidateName(name);
  const Fd dir{OpenDir()};
  const Fd f{
      openat(dir.fd, name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644)};
  if (f.fd < 0) {
    if (errno == EEXIST)
      throw InputError("checkpoint '" + name + "' exists already in " + dir_ + ": not replaced");
    throw InputError("cannot write checkpoint '" + name + "' in " + dir_ + ": " +
                     std::strerror(errno));
  }
  const std::string text = CheckpointText(c);
  std::size_t put = 0;
  while (put < text.size()) {
    const ssize_t n = write(f.fd, text.data() + put, text.size() - put);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = std::strerror(errno);
      unlinkat(dir.fd, name.c_str(), 0);  // no half-written checkpoint left behind
      throw InputError(Sprintf("cannot write checkpoint '%s' in %s: %s", name.c_str(), dir_.c_str(),
                               why.c_str()));
    }
    put += static_cast<std::size_t>(n);
  }
}

Checkpoint CheckpointFolder::Read(const std::string& name) const {
  ValidateName(name);
  const Fd dir{OpenDir()};
  const Fd f{openat(dir.fd, name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC)};
  if (f.fd < 0) {
    if (errno == ELOOP) throw InputError("checkpoint '" + name + "' is a symbolic link: refused");
    throw InputError("cannot read checkpoint '" + name + "' in " + dir_ + ": " +
                     std::strerror(errno));
  }
  return ParseCheckpoint(ReadOpenFile(f.fd, PathOf(name)), PathOf(name));
}

Checkpoint ParseCheckpoint(std::string_view text, const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    throw InputError("checkpoint '" + path + "' is not JSON: " + e.what());
  }
  if (!j.is_object() || j.value("format", "") != kFormat) {
    throw InputError("checkpoint '" + path + "': not an rmslab checkpoint (\"format\" must be \"" +
                     kFormat + "\")");
  }
  Checkpoint c;
  try {
    c.saved_us = j.at("saved_us").get<std::int64_t>();
    c.dcp_frame = j.at("dcp_frame").get<std::int64_t>();
    c.input_frame = j.at("input_frame").get<std::int64_t>();
    c.config = j.at("config").get<std::string>();
    c.inputs = InputsFromJson(j.at("operator_inputs"));
    c.inputs.reset = false;  // the inputs to carry on from: never a press of the reset button
    c.dcp = j.at("dcp");
  } catch (const std::exception& e) {
    std::string why =
        e.what();  // nlohmann's "[json.exception.out_of_range.403] key 'x' not found" -> the key
    if (why.rfind("[json.exception.", 0) == 0 && why.find("] ") != std::string::npos)
      why = why.substr(why.find("] ") + 2);
    throw InputError("checkpoint '" + path + "': not a valid checkpoint (" + why + ")");
  }
  return c;
}

}  // namespace rms::wire
