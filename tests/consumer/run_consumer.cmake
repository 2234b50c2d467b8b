# Installs a built libmorph into a temporary prefix, then configures, builds and runs the
# outside project in this folder against it: the test that find_package(morph) and
# morph::morph work for a user. Run by ctest (see tests/CMakeLists.txt) as
#   cmake -DMORPH_BUILD_DIR=<build> -DWORK_DIR=<scratch> [-DCONFIG=Release]
#         [-DCXX_COMPILER=<c++>] [-DLINK_FLAGS=<flags>] -P run_consumer.cmake
foreach(var MORPH_BUILD_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_consumer.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT CONFIG)
  set(CONFIG Release)
endif()

set(prefix ${WORK_DIR}/prefix)
set(build ${WORK_DIR}/build)
file(REMOVE_RECURSE ${WORK_DIR})

function(step what)
  message(STATUS "consumer: ${what}")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "consumer: ${what} failed (${rc})")
  endif()
endfunction()

# Only the library's install rules (libmorph/): the apps need not be built for this test.
step("install libmorph into ${prefix}"
     ${CMAKE_COMMAND} --install ${MORPH_BUILD_DIR}/libmorph --prefix ${prefix} --config ${CONFIG})

set(configure_args -S ${CMAKE_CURRENT_LIST_DIR} -B ${build} -DCMAKE_BUILD_TYPE=${CONFIG}
                   -DCMAKE_PREFIX_PATH=${prefix})
if(CXX_COMPILER)
  list(APPEND configure_args -DCMAKE_CXX_COMPILER=${CXX_COMPILER})
endif()
if(LINK_FLAGS)  # e.g. the sanitizers the library was built with
  list(APPEND configure_args "-DCMAKE_EXE_LINKER_FLAGS=${LINK_FLAGS}")
endif()
step("configure the consumer against the installed package" ${CMAKE_COMMAND} ${configure_args})
step("build the consumer" ${CMAKE_COMMAND} --build ${build} --config ${CONFIG})

find_program(consumer morph_consumer PATHS ${build} ${build}/${CONFIG} NO_DEFAULT_PATH REQUIRED)
step("run ${consumer}" ${consumer})
