#include "evfs/app/version_report.h"

#include <ceres/version.h>
#include <hdf5.h>
#include <lz4.h>
#include <tinyxml2.h>
#include <zstd.h>

#include <Eigen/Core>
#include <opencv2/core/utility.hpp>

#include "evfs/core/version.h"

namespace evfs {

std::vector<std::pair<std::string, std::string>> LibraryVersions() {
  unsigned hdf5_major = 0, hdf5_minor = 0, hdf5_release = 0;
  const bool hdf5_known = H5get_libversion(&hdf5_major, &hdf5_minor, &hdf5_release) >= 0;
  const auto numbers = [](int major, int minor, int patch) {
    return std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(patch);
  };
  return {
      {"Ceres Solver", CERES_VERSION_STRING},
      {"OpenCV", cv::getVersionString()},
      {"HDF5", hdf5_known ? numbers(hdf5_major, hdf5_minor, hdf5_release) : "unknown"},
      {"Eigen", numbers(EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION)},
      {"LZ4", LZ4_versionString()},
      {"Zstandard", ZSTD_versionString()},
      {"TinyXML-2", numbers(TIXML2_MAJOR_VERSION, TIXML2_MINOR_VERSION, TIXML2_PATCH_VERSION)},
  };
}

std::string VersionReport() {
  std::string report = std::string("evfs ") + kVersion + "\n";
  for (const auto& [name, version] : LibraryVersions()) {
    report += "  " + name + " " + version + "\n";
  }
  return report;
}

}  // namespace evfs
