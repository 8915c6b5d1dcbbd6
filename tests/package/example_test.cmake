# ctest package.example: installs the build tree into a temporary prefix, checks the installed
# layout, builds examples/ against the installed CMake package (find_package(pathex), target
# pathex::pathex, nothing from the source tree on its include path) and compares the program's
# output with example.expected.
#   cmake -DBUILD_DIR=… -DSOURCE_DIR=… -DWORK_DIR=… [-DLAUNCHER=ccache] -P example_test.cmake
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

foreach(f bin/pathex include/pathex/pathex.h lib/libpathex.a lib/cmake/pathex/pathexConfig.cmake
          lib/cmake/pathex/pathexConfigVersion.cmake lib/cmake/pathex/pathexTargets.cmake
          share/man/man1/pathex.1 share/bash-completion/completions/pathex)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "cmake --install did not install ${f}")
  endif()
endforeach()
# Only the API header is public: the library's internal folders stay out of include/.
file(GLOB_RECURSE headers RELATIVE ${prefix}/include ${prefix}/include/*)
if(NOT headers STREQUAL "pathex/pathex.h")
  message(FATAL_ERROR "installed headers are '${headers}', expected pathex/pathex.h alone")
endif()
run(${prefix}/bin/pathex --version)
if(NOT out MATCHES "^pathex [0-9]+\\.[0-9]+\\.[0-9]+\n$")
  message(FATAL_ERROR "installed pathex --version printed '${out}'")
endif()

set(configure ${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${prefix})
if(LAUNCHER)
  list(APPEND configure -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
run(${configure})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/pathex_example ${SOURCE_DIR}/samples/scenes/point-mirror-caustic.json)
file(READ ${CMAKE_CURRENT_LIST_DIR}/example.expected expected)
if(NOT out STREQUAL expected)
  message(FATAL_ERROR "examples/example.cpp printed\n${out}\nexpected\n${expected}")
endif()
message(STATUS "installed, built the example against the package, output as expected")
