# The installed CMake package: `cmake --install BUILD --prefix PREFIX` puts the libraries in
# PREFIX/lib, their headers in PREFIX/include/evfs/MODULE, the `evfs` program in PREFIX/bin and
# evfsConfig.cmake, evfsConfigVersion.cmake and evfsTargets.cmake in PREFIX/lib/cmake/evfs, so
# that another project's find_package(evfs) gives the evfs:: targets (docs/guide.md, "Use from
# CMake"). Included by the top-level CMakeLists.txt after every module.
include(CMakePackageConfigHelpers)
set(EVFS_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/evfs")

install(EXPORT evfsTargets NAMESPACE evfs:: DESTINATION "${EVFS_INSTALL_CMAKEDIR}")
configure_package_config_file(
  "${PROJECT_SOURCE_DIR}/cmake/evfsConfig.cmake.in" "${PROJECT_BINARY_DIR}/evfsConfig.cmake"
  INSTALL_DESTINATION "${EVFS_INSTALL_CMAKEDIR}")
# Before 1.0 a minor version may change the API: only the same MAJOR.MINOR is compatible.
write_basic_package_version_file("${PROJECT_BINARY_DIR}/evfsConfigVersion.cmake"
                                 VERSION "${PROJECT_VERSION}" COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/evfsConfig.cmake" "${PROJECT_BINARY_DIR}/evfsConfigVersion.cmake"
        DESTINATION "${EVFS_INSTALL_CMAKEDIR}")
