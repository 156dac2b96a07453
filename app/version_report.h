// `evfs --version`: the version of evfs and of the libraries it was built with.
#ifndef EVFS_APP_VERSION_REPORT_H_
#define EVFS_APP_VERSION_REPORT_H_

#include <string>
#include <utility>
#include <vector>

namespace evfs {

/// The libraries evfs uses, each as {name, version}: Ceres Solver, OpenCV, HDF5, Eigen, LZ4,
/// Zstandard, TinyXML-2. Shared libraries report the version loaded at run time; those
/// compiled in (Ceres is linked statically, Eigen and TinyXML-2's version are headers) the
/// version of their headers.
std::vector<std::pair<std::string, std::string>> LibraryVersions();

/// "evfs VERSION" and a line per library of LibraryVersions(), each ending in '\n'.
std::string VersionReport();

}  // namespace evfs

#endif  // EVFS_APP_VERSION_REPORT_H_
