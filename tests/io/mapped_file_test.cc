#include "evfs/io/mapped_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>

#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

TEST(MappedFileTest, MapsTheWholeFile) {
  const std::string path = test::ScratchDir("mapped_whole") + "/data.txt";
  test::WriteFile(path, "0.5 1 2 1\n0.6 3 4 0");
  const MappedFile file(path);
  EXPECT_EQ(file.path(), path);
  EXPECT_EQ(std::string(file.data(), file.size()), "0.5 1 2 1\n0.6 3 4 0");
}

TEST(MappedFileTest, EmptyFileGivesAnEmptyBuffer) {
  const std::string path = test::ScratchDir("mapped_empty") + "/empty.txt";
  test::WriteFile(path, "");
  const MappedFile file(path);
  EXPECT_EQ(file.size(), 0u);
}

TEST(MappedFileTest, MovingTransfersTheMapping) {
  const std::string path = test::ScratchDir("mapped_move") + "/data.txt";
  test::WriteFile(path, "abc");
  MappedFile first(path);
  MappedFile second(std::move(first));
  EXPECT_EQ(std::string(second.data(), second.size()), "abc");
  MappedFile third(path);
  third = std::move(second);
  EXPECT_EQ(std::string(third.data(), third.size()), "abc");
}

TEST(MappedFileTest, FromMemoryWrapsTheBytesWithoutCopying) {
  const std::string bytes = "0.5 1 2 1\n";
  MappedFile file = MappedFile::FromMemory("memory/events.txt", bytes.data(), bytes.size());
  EXPECT_EQ(file.path(), "memory/events.txt");
  EXPECT_EQ(file.data(), bytes.data());
  EXPECT_EQ(file.size(), bytes.size());
  // Moving and destroying must not try to unmap memory that was never mapped.
  MappedFile moved(std::move(file));
  EXPECT_EQ(moved.data(), bytes.data());
}

// This process's resident pages of mapped files, in kB (/proc/self/status RssFile).
long ResidentFileKb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("RssFile:", 0) == 0) return std::stol(line.substr(8));
  }
  return -1;
}

TEST(MappedFileTest, ReleaseDropsTheResidentPagesAndKeepsTheBytes) {
  const std::string path = test::ScratchDir("mapped_release") + "/data.bin";
  // Large enough that its pages stand out from the rest of the process's mapped files.
  constexpr size_t kBytes = 16 << 20;
  std::string content(kBytes, '\0');
  for (size_t i = 0; i < kBytes; ++i) content[i] = static_cast<char>(i * 7 + i / 4096);
  test::WriteFile(path, content);
  const MappedFile file(path);
  const long before_kb = ResidentFileKb();
  ASSERT_GE(before_kb, 0) << "no RssFile in /proc/self/status";
  long sum = 0;
  for (size_t i = 0; i < kBytes; i += 4096) sum += file.data()[i];
  const long touched_kb = ResidentFileKb();
  EXPECT_GE(touched_kb - before_kb, static_cast<long>(kBytes / 1024 / 2)) << sum;
  file.Release(0, kBytes);
  EXPECT_LT(ResidentFileKb(), touched_kb - static_cast<long>(kBytes / 1024 / 2));
  EXPECT_EQ(std::string(file.data(), file.size()), content);
  // A range past the end, or around it, is clamped.
  file.Release(kBytes - 10, 100);
  file.Release(kBytes + 1, 100);
  EXPECT_EQ(std::string(file.data(), file.size()), content);
}

TEST(MappedFileTest, MissingFileOrFolderIsAnInputError) {
  const std::string dir = test::ScratchDir("mapped_missing");
  test::ExpectInputError([&] { MappedFile file(dir + "/nope.txt"); },
                         InputError::Kind::kMissingFile, dir + "/nope.txt", 0);
  test::ExpectInputError([&] { MappedFile file(dir); }, InputError::Kind::kMissingFile, dir, 0);
}

}  // namespace
}  // namespace evfs
