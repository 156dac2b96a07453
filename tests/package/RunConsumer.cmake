# The `package_consumer` test: installs the build tree into a fresh prefix (`cmake --install`,
# nothing rebuilt), checks what was installed, then configures, builds and runs the consumer
# project of consumer/ against that prefix, as another project would use evfs. Run as
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DCONSUMER_SOURCE=...
#         -DCXX_COMPILER=... -DBUILD_TYPE=... [-DSANITIZE_FLAGS=...] -P RunConsumer.cmake
cmake_minimum_required(VERSION 3.18)
foreach(variable BUILD_DIR SOURCE_DIR WORK_DIR CONSUMER_SOURCE CXX_COMPILER)
  if(NOT ${variable})
    message(FATAL_ERROR "RunConsumer.cmake needs -D${variable}=...")
  endif()
endforeach()

# Runs a command; on failure stops the test with its output.
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE output
                  ERROR_VARIABLE output)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "${what} failed (${result}):\n${output}")
  endif()
  set(run_output "${output}" PARENT_SCOPE)
endfunction()

set(prefix "${WORK_DIR}/install")
file(REMOVE_RECURSE "${WORK_DIR}")
run("cmake --install" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}")

# What the package is made of.
foreach(path include/evfs/solver/reconstructor.h include/evfs/core/version.h
             include/evfs/cost_functions/event_residual.h lib/libevfs_solver.a
             lib/cmake/evfs/evfsConfig.cmake lib/cmake/evfs/evfsConfigVersion.cmake
             lib/cmake/evfs/evfsTargets.cmake bin/evfs)
  if(NOT EXISTS "${prefix}/${path}")
    message(FATAL_ERROR "not installed: ${prefix}/${path}")
  endif()
endforeach()
# Nothing installed may point back at the sources or the build tree.
file(GLOB package_files "${prefix}/lib/cmake/evfs/*.cmake")
foreach(file IN LISTS package_files)
  file(READ "${file}" text)
  foreach(tree "${SOURCE_DIR}" "${BUILD_DIR}")
    string(FIND "${text}" "${tree}" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "${file} names ${tree}")
    endif()
  endforeach()
endforeach()

# The installed program.
run("installed evfs --version" "${prefix}/bin/evfs" --version)
if(NOT run_output MATCHES "^evfs [0-9]+\\.[0-9]+\\.[0-9]+\n")
  message(FATAL_ERROR "installed evfs --version printed:\n${run_output}")
endif()

# The consumer, with the compiler (and sanitizers) of the build.
run("configuring the consumer" "${CMAKE_COMMAND}" -S "${CONSUMER_SOURCE}" -B "${WORK_DIR}/build"
    "-DCMAKE_PREFIX_PATH=${prefix}" "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}"
    "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}" "-DCMAKE_CXX_FLAGS=${SANITIZE_FLAGS}"
    "-DCMAKE_EXE_LINKER_FLAGS=${SANITIZE_FLAGS}")
message(STATUS "${run_output}")
run("building the consumer" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
run("running the consumer" "${WORK_DIR}/build/consumer")
message(STATUS "consumer: ${run_output}")
