// What the fuzz targets share: the input written to a file, and the rule every error message
// must keep (one short line on a terminal, however long or binary the input).
#ifndef EVFS_TESTS_FUZZ_FUZZ_UTIL_H_
#define EVFS_TESTS_FUZZ_FUZZ_UTIL_H_

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "evfs/core/error.h"
#include "evfs/io/data_source.h"

namespace evfs {
namespace fuzzing {

/// A file on tmpfs for readers and writers that take paths (images.txt and exposures.txt,
/// HDF5, the writers' round trips): rewritten per input, named after the process (libFuzzer's
/// -jobs run several at once) and removed at exit.
class FuzzInputFile {
 public:
  explicit FuzzInputFile(const std::string& name) {
    std::error_code error;
    const std::filesystem::path folder = std::filesystem::is_directory("/dev/shm", error)
                                             ? std::filesystem::path("/dev/shm")
                                             : std::filesystem::temp_directory_path();
    path_ = (folder / ("evfs_fuzz_" + std::to_string(::getpid()) + "_" + name)).string();
  }
  ~FuzzInputFile() { std::remove(path_.c_str()); }

  FuzzInputFile(const FuzzInputFile&) = delete;
  FuzzInputFile& operator=(const FuzzInputFile&) = delete;

  /// Replaces the file's content with `size` bytes at `data`; returns its path.
  const std::string& Write(const uint8_t* data, size_t size) const {
    std::FILE* file = std::fopen(path_.c_str(), "wb");
    if (file == nullptr || (size > 0 && std::fwrite(data, 1, size, file) != size) ||
        std::fclose(file) != 0) {
      std::perror(path_.c_str());
      std::abort();  // the fuzzing set-up is broken, not the reader
    }
    return path_;
  }

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// Longest message accepted beyond the file name: input quoted in a message is cut short.
constexpr size_t kMaxMessageBytes = 400;

/// Aborts (a finding) unless `error` reads as one short line: no control characters, and at
/// most kMaxMessageBytes besides the input's path.
inline void CheckMessage(const Error& error, const std::string& input_path) {
  const char* const message = error.what();
  const size_t length = std::strlen(message);
  bool printable = true;
  for (size_t i = 0; i < length; ++i) {
    const unsigned char c = static_cast<unsigned char>(message[i]);
    printable = printable && c >= 0x20 && c != 0x7f;
  }
  if (!printable || length > input_path.size() + kMaxMessageBytes) {
    std::fprintf(stderr, "error message is not one short printable line (%zu bytes): %.600s\n",
                 length, message);
    std::abort();
  }
}

/// t + 1 ns, or t at the largest timestamp (a window end just after the last event).
inline int64_t After(int64_t t_ns) { return t_ns == INT64_MAX ? t_ns : t_ns + 1; }

/// Aborts with `what` when `condition` is false: a reader broke one of its own promises.
inline void Require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "broken promise: %s\n", what);
    std::abort();
  }
}

/// Aborts unless the summary of `source` counts the events of `all` (its full read) and windowed
/// reads between events at the start, the middle and the end, from each or 1 ns after, equal
/// slicing `all`.
inline void CheckSummaryAndWindows(const DataSource& source, const EventStream& all) {
  const EventSummary summary = source.Summarize();
  Require(summary.count == static_cast<int64_t>(all.size()),
          "the summary counts other events than the full read");
  if (all.empty()) return;
  const size_t last = all.size() - 1;
  for (size_t i = 0; i <= 2; ++i) {
    for (size_t j = i; j <= 2; ++j) {
      const int64_t begin = all.t_ns(i * last / 2);
      const int64_t end = j == 2 ? After(all.last_t_ns()) : all.t_ns(j * last / 2);
      for (const int64_t from : {begin, After(begin)}) {
        Require(source.ReadEvents(from, end) == all.Slice(from, end),
                "a windowed read differs from slicing the full read");
      }
    }
  }
}

}  // namespace fuzzing
}  // namespace evfs

#endif  // EVFS_TESTS_FUZZ_FUZZ_UTIL_H_
