#include "evfs/runtime/signal_cleanup.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <mutex>

namespace evfs {
namespace {

namespace fs = std::filesystem;

// A report is one byte ('+' registered, '-' released), the path, and a NUL, which no path holds.
constexpr char kRegistered = '+';
constexpr char kReleased = '-';

std::mutex report_mutex;
int report_fd = -1;  // the worker's end of the channel, -1 when there is none

// Writes the whole message, retrying short writes and EINTR.
void WriteAll(int fd, const std::string& message) {
  size_t written = 0;
  while (written < message.size()) {
    const ssize_t n = ::write(fd, message.data() + written, message.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the parent is gone: nobody is left to clean up for
    written += static_cast<size_t>(n);
  }
}

void Report(char what, const std::string& path) {
  std::lock_guard<std::mutex> lock(report_mutex);
  if (report_fd < 0) return;
  std::string message(1, what);
  message += path;
  message += '\0';
  WriteAll(report_fd, message);
}

}  // namespace

CleanupChannel::CleanupChannel() {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) == 0) {
    read_fd_ = fds[0];
    write_fd_ = fds[1];
  }
}

CleanupChannel::~CleanupChannel() {
  if (read_fd_ >= 0) ::close(read_fd_);
  if (write_fd_ >= 0 && write_fd_ != report_fd) ::close(write_fd_);
}

void CleanupChannel::AttachWorker() {
  if (!valid()) return;
  ::close(read_fd_);
  read_fd_ = -1;
  std::lock_guard<std::mutex> lock(report_mutex);
  report_fd = write_fd_;
}

void CleanupChannel::AttachSupervisor() {
  if (!valid()) return;
  ::close(write_fd_);
  write_fd_ = -1;
}

void CleanupChannel::ReadUntilWorkerEnds() {
  if (read_fd_ < 0) return;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(read_fd_, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    reports_.append(buffer, static_cast<size_t>(n));
  }
  ::close(read_fd_);
  read_fd_ = -1;
}

std::vector<std::string> CleanupChannel::RemoveLeftovers() {
  ReadUntilWorkerEnds();
  std::vector<std::string> open_paths;
  for (size_t begin = 0; begin < reports_.size();) {
    const size_t end = reports_.find('\0', begin);
    if (end == std::string::npos) break;  // cut short by the worker's death
    const std::string path = reports_.substr(begin + 1, end - begin - 1);
    if (reports_[begin] == kRegistered) {
      open_paths.push_back(path);
    } else {
      const auto it = std::find(open_paths.rbegin(), open_paths.rend(), path);
      if (it != open_paths.rend()) open_paths.erase(std::next(it).base());
    }
    begin = end + 1;
  }
  reports_.clear();
  for (auto it = open_paths.rbegin(); it != open_paths.rend(); ++it) {
    std::error_code error;
    fs::remove_all(*it, error);
  }
  return open_paths;
}

ScopedCleanupPath::ScopedCleanupPath(std::string path) : path_(std::move(path)) {
  Report(kRegistered, path_);
  registered_ = true;
}

ScopedCleanupPath::~ScopedCleanupPath() { Release(); }

void ScopedCleanupPath::Release() {
  if (!registered_) return;
  Report(kReleased, path_);
  registered_ = false;
}

}  // namespace evfs
