// Synthetic recordings and small helpers shared by the io tests.
#ifndef EVFS_TESTS_IO_IO_TEST_UTIL_H_
#define EVFS_TESTS_IO_IO_TEST_UTIL_H_

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"

namespace evfs {
namespace test {

/// Random events in time order: gaps uniform in [0, max_gap_ns] (so equal timestamps occur),
/// starting at t_first_ns, on a width x height sensor.
inline EventStream MakeRandomEvents(uint32_t seed, int count, int width, int height,
                                    int64_t t_first_ns, int64_t max_gap_ns) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int64_t> gap(0, max_gap_ns);
  std::uniform_int_distribution<int> x(0, width - 1);
  std::uniform_int_distribution<int> y(0, height - 1);
  std::bernoulli_distribution positive(0.5);
  EventStream events(width, height);
  int64_t t_ns = t_first_ns;
  for (int i = 0; i < count; ++i) {
    t_ns += gap(random);
    events.push_back(t_ns, static_cast<uint16_t>(x(random)), static_cast<uint16_t>(y(random)),
                     positive(random) ? 1 : -1);
  }
  return events;
}

/// Checks windowed reads on runs of equal timestamps (DAVIS bursts): a window starting at a
/// run must hold the whole run even when the binary search probes land inside it.
/// `write(events)` stores the events; `read(t_begin_ns, t_end_ns)` reads a window back.
template <typename Write, typename Read>
void ExpectWindowsKeepWholeRuns(int width, int height, Write&& write, Read&& read) {
  // 4000 lines of events.txt are ~48 KB, beyond the text reader's linear-scan range.
  constexpr int kRuns = 10;
  constexpr int kRunLength = 4000;
  constexpr int64_t kRunSpacingNs = 1000;
  EventStream events(width, height);
  for (int run = 0; run < kRuns; ++run) {
    for (int i = 0; i < kRunLength; ++i) {
      events.push_back(kRunSpacingNs * run, static_cast<uint16_t>(i % width),
                       static_cast<uint16_t>(run % height), static_cast<int8_t>(i % 2 ? -1 : 1));
    }
  }
  write(events);
  for (int run = 0; run < kRuns; ++run) {
    const int64_t begin = kRunSpacingNs * run;
    EXPECT_EQ(read(begin, begin + 1).size(), static_cast<size_t>(kRunLength)) << "run " << run;
    EXPECT_EQ(read(begin, begin + 2 * kRunSpacingNs),
              events.Slice(begin, begin + 2 * kRunSpacingNs))
        << "run " << run;
  }
}

/// A random image whose values are exactly k / (2^bit_depth - 1), as a PNG of that depth reads.
inline Image MakeRandomImage(uint32_t seed, int width, int height, int bit_depth) {
  std::mt19937 random(seed);
  const int max_value = (1 << bit_depth) - 1;
  std::uniform_int_distribution<int> level(0, max_value);
  Image image(height, width);
  for (Eigen::Index i = 0; i < image.size(); ++i) {
    image.data()[i] = static_cast<double>(level(random)) / max_value;
  }
  return image;
}

/// Writes `content` to `path` byte for byte.
inline void WriteFile(const std::string& path, const std::string& content) {
  std::ofstream stream(path, std::ios::binary);
  stream << content;
  ASSERT_TRUE(stream.good()) << path;
}

/// The whole file as a string.
inline std::string ReadFile(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
}

/// Runs `body`, which must throw InputError, and returns the error. When it does not throw, the
/// test fails and a sentinel error naming "<none thrown>" is returned so that callers can go on.
template <typename Body>
InputError CatchInputError(Body&& body) {
  try {
    body();
  } catch (const InputError& error) {
    return error;
  }
  ADD_FAILURE() << "expected an InputError";
  return InputError(InputError::Kind::kMalformed, "<none thrown>", -1, "");
}

/// Expects `body` to throw InputError of `kind` whose message names `file` and, when `line` is
/// positive, "file:line".
template <typename Body>
void ExpectInputError(Body&& body, InputError::Kind kind, const std::string& file, int64_t line) {
  const InputError error = CatchInputError(body);
  EXPECT_EQ(static_cast<int>(error.kind()), static_cast<int>(kind)) << error.what();
  const std::string message = error.what();
  EXPECT_NE(message.find(file), std::string::npos) << message;
  if (line > 0) {
    EXPECT_EQ(error.line(), line) << message;
    EXPECT_NE(message.find(file + ":" + std::to_string(line) + ":"), std::string::npos) << message;
  }
}

/// An error message must be one short printable line however long or binary the input was: it
/// quotes input cut short (io/message_excerpt.h), so it holds the file name and at most this
/// many other bytes.
constexpr size_t kMaxMessageBytesBesidesPath = 200;

inline void ExpectShortPrintableMessage(const InputError& error) {
  const std::string message = error.what();
  EXPECT_LT(message.size(), error.file().size() + kMaxMessageBytesBesidesPath) << message;
  for (const char c : message) {
    ASSERT_FALSE(static_cast<unsigned char>(c) < 0x20 || c == 0x7f) << message;
  }
}

}  // namespace test
}  // namespace evfs

#endif  // EVFS_TESTS_IO_IO_TEST_UTIL_H_
