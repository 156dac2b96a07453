// Writes HDF5 files the way other tools do, through the HDF5 C API, for the tests that check
// how evfs reads what it did not write. Link ${HDF5_C_LIBRARIES} and add ${HDF5_INCLUDE_DIRS}.
#ifndef EVFS_TESTS_IO_HDF5_TEST_UTIL_H_
#define EVFS_TESTS_IO_HDF5_TEST_UTIL_H_

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstdint>
#include <string>

namespace evfs {
namespace test {

/// Rewrites the root attribute sensor_resolution of the HDF5 file `path` as [height, width].
inline void DeclareSensorResolution(const std::string& path, int64_t height, int64_t width) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(file, 0) << path;
  if (H5Aexists(file, "sensor_resolution") > 0) H5Adelete(file, "sensor_resolution");
  const hsize_t two = 2;
  const int64_t resolution[2] = {height, width};
  const hid_t space = H5Screate_simple(1, &two, nullptr);
  const hid_t attribute =
      H5Acreate2(file, "sensor_resolution", H5T_NATIVE_INT64, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attribute, H5T_NATIVE_INT64, resolution);
  H5Aclose(attribute);
  H5Sclose(space);
  H5Fclose(file);
}

}  // namespace test
}  // namespace evfs

#endif  // EVFS_TESTS_IO_HDF5_TEST_UTIL_H_
