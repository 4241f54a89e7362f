# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors

# cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DGENERATOR=... -DCXX=...
# [-DCXX_FLAGS=... -DLINKER_FLAGS=...] -P this (the flags: the build's, e.g. the sanitizers'):
# installs the build into WORK_DIR/prefix, then configures, builds and runs tests/consumer
# against that prefix only.
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR CXX)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_consumer_test.cmake: ${var} is not set")
  endif()
endforeach()
file(REMOVE_RECURSE "${WORK_DIR}")

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE output
                  ERROR_VARIABLE output)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "failed (${result}): ${ARGN}\n${output}")
  endif()
  message(STATUS "${output}")
endfunction()

run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${WORK_DIR}/build" -G "${GENERATOR}"
    -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}"
    "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}"
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/consumer" "${WORK_DIR}/consumer_sphere.ply")

# The page `pointform view` serves is installed beside the executable (share/pointform/viewer),
# where an installed pointform reads it.
foreach(file web/index.html web/viewer.js web/base_mesh.js web/style.css)
  if(NOT EXISTS "${WORK_DIR}/prefix/share/pointform/viewer/${file}")
    message(FATAL_ERROR "the viewer's ${file} is not installed under share/pointform/viewer")
  endif()
endforeach()
