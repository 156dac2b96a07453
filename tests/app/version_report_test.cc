#include "evfs/app/version_report.h"

#include <ceres/version.h>
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cctype>
#include <map>
#include <opencv2/core/version.hpp>
#include <string>

#include "evfs/core/version.h"

namespace evfs {
namespace {

TEST(Version, ComesFromTheProjectVersion) {
  // EVFS_PROJECT_VERSION is ${PROJECT_VERSION} of the top-level CMakeLists.txt.
  EXPECT_STREQ(kVersion, EVFS_PROJECT_VERSION);
  EXPECT_EQ(std::string(kVersion), std::to_string(EVFS_VERSION_MAJOR) + "." +
                                       std::to_string(EVFS_VERSION_MINOR) + "." +
                                       std::to_string(EVFS_VERSION_PATCH));
}

TEST(VersionReport, NamesEvfsAndItsLibraries) {
  const std::string report = VersionReport();
  EXPECT_EQ(report.rfind(std::string("evfs ") + kVersion + "\n", 0), 0u) << report;
  std::map<std::string, std::string> versions;
  for (const auto& [name, version] : LibraryVersions()) {
    EXPECT_FALSE(version.empty()) << name;
    EXPECT_TRUE(std::isdigit(static_cast<unsigned char>(version[0]))) << name << " " << version;
    EXPECT_NE(report.find("  " + name + " " + version + "\n"), std::string::npos) << report;
    versions[name] = version;
  }
  // Against the headers this test was compiled with (the same packages on one machine).
  EXPECT_EQ(versions["Ceres Solver"], CERES_VERSION_STRING);
  EXPECT_EQ(versions["OpenCV"], CV_VERSION);
  EXPECT_EQ(versions["HDF5"], std::to_string(H5_VERS_MAJOR) + "." + std::to_string(H5_VERS_MINOR) +
                                  "." + std::to_string(H5_VERS_RELEASE));
  for (const char* name : {"Eigen", "LZ4", "Zstandard", "TinyXML-2"}) {
    EXPECT_EQ(versions.count(name), 1u) << name;
  }
}

}  // namespace
}  // namespace evfs
