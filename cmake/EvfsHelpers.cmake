include("${CMAKE_CURRENT_LIST_DIR}/EvfsLayers.cmake")
include(GNUInstallDirs)
# Installed headers keep their module folders under one evfs folder, and every source names them
# with that folder: #include "evfs/solver/reconstructor.h", so a consumer's own core/error.h
# cannot collide with evfs's. The build tree resolves the same paths (evfs_module_include_dir).
set(EVFS_INSTALL_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}/evfs")
evfs_read_layers("${PROJECT_SOURCE_DIR}/cmake/layers.txt" EVFS_MODULES)

# evfs_module_include_dir(MODULE OUT_VAR)
#   The include directory of a module: a folder in the build tree whose evfs/ folder holds links
#   to the module's own folder and to the folders cmake/layers.txt lets it use, and nothing else.
#   So code includes "evfs/core/video.h" as it would the installed header, but a module that
#   includes a header above its layer does not build.
function(evfs_module_include_dir module out_var)
  if(NOT module IN_LIST EVFS_MODULES)
    message(FATAL_ERROR "${module} is not a module of cmake/layers.txt")
  endif()
  set(dir "${PROJECT_BINARY_DIR}/include/${module}")
  foreach(used IN LISTS module EVFS_LAYER_${module})
    if(IS_SYMLINK "${dir}/${used}")
      file(REMOVE "${dir}/${used}")  # the links of a build tree from before the evfs/ prefix
    endif()
    if(NOT IS_SYMLINK "${dir}/evfs/${used}")
      file(MAKE_DIRECTORY "${dir}/evfs")
      file(CREATE_LINK "${PROJECT_SOURCE_DIR}/${used}" "${dir}/evfs/${used}" SYMBOLIC)
    endif()
  endforeach()
  set(${out_var} "${dir}" PARENT_SCOPE)
endfunction()

# evfs_source_include_dir(OUT_VAR)
#   An include directory whose evfs/ links to the repository root, for what may see every module
#   (tests, plug-ins, fuzzers): "evfs/tests/test_data.h" as "evfs/core/video.h".
function(evfs_source_include_dir out_var)
  set(dir "${PROJECT_BINARY_DIR}/include/all")
  if(NOT IS_SYMLINK "${dir}/evfs")
    file(MAKE_DIRECTORY "${dir}")
    file(CREATE_LINK "${PROJECT_SOURCE_DIR}" "${dir}/evfs" SYMBOLIC)
  endif()
  set(${out_var} "${dir}" PARENT_SCOPE)
endfunction()

# The module a CMakeLists.txt belongs to: the first folder of its path in the repository.
function(evfs_current_module out_var)
  file(RELATIVE_PATH relative "${PROJECT_SOURCE_DIR}" "${CMAKE_CURRENT_SOURCE_DIR}")
  string(REGEX REPLACE "/.*" "" module "${relative}")
  set(${out_var} "${module}" PARENT_SCOPE)
endfunction()

# evfs_add_library(NAME [INTERNAL] SRCS a.cc ... DEPS lib ...)
#   One static library per module folder (INTERFACE when SRCS holds no source), seeing only the
#   modules it may use (evfs_module_include_dir). Unless INTERNAL (a helper of the benchmarks or
#   tools), it is installed with the module's headers (include/evfs/MODULE/*.h) and exported as
#   evfs::MODULE (evfs_solver → evfs::solver) by cmake/EvfsPackage.cmake; installed, consumers
#   include them as "evfs/MODULE/NAME.h" from include/.
function(evfs_add_library name)
  cmake_parse_arguments(ARG "INTERNAL" "" "SRCS;DEPS" ${ARGN})
  evfs_current_module(module)
  evfs_module_include_dir(${module} include_dir)
  set(include_dirs "$<BUILD_INTERFACE:${include_dir}>"
                   "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  if(ARG_SRCS)
    add_library(${name} STATIC ${ARG_SRCS})
    target_include_directories(${name} PUBLIC ${include_dirs})
    target_link_libraries(${name} PUBLIC ${ARG_DEPS})
  else()
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE ${include_dirs})
    target_link_libraries(${name} INTERFACE ${ARG_DEPS})
  endif()
  if(ARG_INTERNAL)
    return()
  endif()
  string(REGEX REPLACE "^evfs_" "" export_name "${name}")
  set_target_properties(${name} PROPERTIES EXPORT_NAME ${export_name})
  install(TARGETS ${name} EXPORT evfsTargets
          ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
          LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}")
  file(GLOB headers CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/*.h")
  if(headers)
    install(FILES ${headers} DESTINATION "${EVFS_INSTALL_INCLUDEDIR}/${module}")
  endif()
endfunction()

# evfs_add_executable(NAME SRCS a.cc ... LINK_LIBS lib ...)
#   A program of a module (the CLI, a benchmark, a tool), seeing only the modules it may use.
function(evfs_add_executable name)
  cmake_parse_arguments(ARG "" "" "SRCS;LINK_LIBS" ${ARGN})
  evfs_current_module(module)
  evfs_module_include_dir(${module} include_dir)
  add_executable(${name} ${ARG_SRCS})
  target_include_directories(${name} PRIVATE "${include_dir}")
  target_link_libraries(${name} PRIVATE ${ARG_LINK_LIBS})
endfunction()

# evfs_add_test(NAME SRCS a_test.cc ... LINK_LIBS lib ...)
#   Adds a GoogleTest executable and registers each of its tests with CTest. EVFS_DATA_DIR is
#   compiled in so that tests reading the shared snippets can find them (or skip when it is empty).
function(evfs_add_test name)
  cmake_parse_arguments(ARG "" "" "SRCS;LINK_LIBS" ${ARGN})
  add_executable(${name} ${ARG_SRCS})
  # Tests may use every module, and their own helpers under tests/.
  evfs_source_include_dir(source_include_dir)
  target_include_directories(${name} PRIVATE "${source_include_dir}")
  target_link_libraries(${name} PRIVATE ${ARG_LINK_LIBS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE EVFS_DATA_DIR="${EVFS_DATA_DIR}"
                             EVFS_TEST_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
                             EVFS_TEST_TMP_DIR="${CMAKE_CURRENT_BINARY_DIR}/tmp_${name}")
  # One ctest entry per test case, listed when ctest runs (so a build never runs a binary).
  gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60 NO_PRETTY_VALUES)
endfunction()

# evfs_add_benchmark(NAME SRCS a.cc ... LINK_LIBS lib ...)
function(evfs_add_benchmark name)
  cmake_parse_arguments(ARG "" "" "SRCS;LINK_LIBS" ${ARGN})
  evfs_add_executable(${name} SRCS ${ARG_SRCS} LINK_LIBS ${ARG_LINK_LIBS})
  target_compile_definitions(${name} PRIVATE EVFS_DATA_DIR="${EVFS_DATA_DIR}")
endfunction()

# evfs_add_plugin(NAME SRCS a.cc ... LINK_LIBS lib ...)
#   A plug-in module that evfs opens with dlopen on first use (core/plugin.h), libNAME.so in the
#   build tree's plugins/ folder and installed in lib/evfs/; only its C functions are visible.
function(evfs_add_plugin name)
  cmake_parse_arguments(ARG "" "" "SRCS;LINK_LIBS" ${ARGN})
  add_library(${name} MODULE ${ARG_SRCS})
  evfs_source_include_dir(source_include_dir)
  target_include_directories(${name} PRIVATE "${source_include_dir}")
  target_link_libraries(${name} PRIVATE ${ARG_LINK_LIBS})
  set_target_properties(${name} PROPERTIES PREFIX "lib" OUTPUT_NAME ${name}
                        CXX_VISIBILITY_PRESET hidden
                        LIBRARY_OUTPUT_DIRECTORY "${EVFS_PLUGIN_OUTPUT_DIR}")
  include(GNUInstallDirs)
  install(TARGETS ${name} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/evfs)
endfunction()
