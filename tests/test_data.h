// Where tests find the shared DAVIS snippets and scratch space. EVFS_DATA_DIR comes from CMake
// (-DEVFS_DATA_DIR=...); when it is empty or missing, tests that need it skip with a message.
#ifndef EVFS_TESTS_TEST_DATA_H_
#define EVFS_TESTS_TEST_DATA_H_

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace evfs {
namespace test {

/// The shared data folder, or "" when it is not available.
inline std::string SharedDataDir() {
  const std::string dir = EVFS_DATA_DIR;
  if (dir.empty() || !std::filesystem::is_directory(dir)) return "";
  return dir;
}

/// A fresh, empty scratch folder for one test, under the build tree.
inline std::string ScratchDir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(EVFS_TEST_TMP_DIR) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace test
}  // namespace evfs

/// Skips the current test when the shared data folder is absent, saying why.
#define EVFS_REQUIRE_SHARED_DATA(dir_variable)                                            \
  const std::string dir_variable = ::evfs::test::SharedDataDir();                         \
  if (dir_variable.empty()) {                                                             \
    GTEST_SKIP() << "shared data folder not found (configure with -DEVFS_DATA_DIR=...); " \
                    "skipping a test that reads the real DAVIS snippets";                 \
  }

#endif  // EVFS_TESTS_TEST_DATA_H_
