# evfs_add_library(NAME SRCS a.cc ... DEPS lib ...)
#   One static library per module folder; the repository root is the include root, so code
#   includes "core/video.h", "io/event_reader.h", ...
function(evfs_add_library name)
  cmake_parse_arguments(ARG "" "" "SRCS;DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SRCS})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS})
endfunction()

# evfs_add_test(NAME SRCS a_test.cc ... LINK_LIBS lib ...)
#   Adds a GoogleTest executable and registers it with CTest. EVFS_DATA_DIR is compiled in
#   so that tests reading the shared snippets can find them (or skip when it is empty).
function(evfs_add_test name)
  cmake_parse_arguments(ARG "" "" "SRCS;LINK_LIBS" ${ARGN})
  add_executable(${name} ${ARG_SRCS})
  target_link_libraries(${name} PRIVATE ${ARG_LINK_LIBS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE EVFS_DATA_DIR="${EVFS_DATA_DIR}"
                             EVFS_TEST_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}"
                             EVFS_TEST_TMP_DIR="${CMAKE_CURRENT_BINARY_DIR}/tmp_${name}")
  add_test(NAME ${name} COMMAND ${name})
endfunction()

# evfs_add_benchmark(NAME SRCS a.cc ... LINK_LIBS lib ...)
function(evfs_add_benchmark name)
  cmake_parse_arguments(ARG "" "" "SRCS;LINK_LIBS" ${ARGN})
  add_executable(${name} ${ARG_SRCS})
  target_link_libraries(${name} PRIVATE ${ARG_LINK_LIBS})
  target_compile_definitions(${name} PRIVATE EVFS_DATA_DIR="${EVFS_DATA_DIR}")
endfunction()
