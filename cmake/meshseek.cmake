# One helper per kind of target, COLMAP-style.
#
#   meshseek_add_library(NAME geometry SRCS a.cc b.cc DEPS ...)
#     -> static library target meshseek_geometry (alias meshseek::geometry), include root = repo root
#   meshseek_add_test(MODULE geometry NAME sobol DEPS ...)
#     -> executable geometry_sobol_test from sobol_test.cc whose every GoogleTest
#        case is its own CTest test, "geometry/sobol_test.Suite.Case", so that
#        `ctest -R geometry/` runs one module and `ctest -R sobol_test.` one binary
#        (docs/operations.md, "Continuous integration").

include(GoogleTest)

# Every test's timeout is multiplied by this: 1 in a release build; the
# sanitizer builds of scripts/sanitize.sh set it to what their slowdown needs.
set(MESHSEEK_TEST_TIMEOUT_SCALE 1 CACHE STRING
    "Factor on every test's timeout (scripts/sanitize.sh sets it per sanitizer)")

# Compile options of the tests' own sources only (not of the code they test).
# A test's source is mostly GoogleTest macros, whose code gcc optimises slowly
# while the work it calls runs in the libraries, optimised as the build says:
# the release build compiles tests at -O1 (class_file_test 10.5 s at -O3,
# 4.8 s at -O1; 440 of a cold build's 1,110 CPU seconds were tests at -O3),
# the sanitizer builds at -O0 (scripts/sanitize.sh; a unit test 12 s at -O2,
# 5 s at -O0 under ASan + UBSan).
set(MESHSEEK_TEST_COMPILE_OPTIONS "-O1" CACHE STRING
    "Compile options of the test sources (release -O1; scripts/sanitize.sh: -O0)")

# Compile options of the code protoc and its gRPC plugin generate
# (proto/CMakeLists.txt). The sanitizer builds set -fno-sanitize=all: the
# generated code is not ours, the protobuf and gRPC runtimes it calls are
# Debian's uninstrumented libraries anyway, and instrumented it took 224 of
# the ASan build's CPU seconds against 83 uninstrumented. The fuzz build
# keeps it instrumented (its harnesses parse messages in that code).
set(MESHSEEK_GENERATED_COMPILE_OPTIONS "" CACHE STRING
    "Compile options of the generated protobuf/gRPC code (scripts/sanitize.sh: -fno-sanitize=all)")

# The headers nearly every test parses, precompiled once a build (with the
# tests' options, by meshseek_test_main) and used by every test: parsing them
# was ~3 of a test's 5 to 9 seconds of compilation (class_file_test at -O1:
# 8.5 s without, 5.5 s with). Only headers that need no library beyond the
# test main's (GoogleTest, OpenCV's core, Abseil's status and strings): a
# header with static initialisers (gRPC's) would tie every test to its library.
# gcc checks a precompiled header against each compilation's macros and
# options and parses the headers as text where it does not match
# (-Winvalid-pch says so), so it can make a build slower, never wrong.
set(MESHSEEK_TEST_PRECOMPILED_HEADERS
    <gtest/gtest.h> <gmock/gmock.h> <opencv2/core.hpp>
    <algorithm> <cmath> <cstdint> <filesystem> <fstream> <limits> <map> <memory>
    <random> <set> <sstream> <string> <vector>
    [["absl/status/status.h"]] [["absl/status/statusor.h"]] [["absl/strings/str_cat.h"]]
    [["absl/strings/string_view.h"]])

# The headers of the RPC edge (gRPC, protobuf, the generated services),
# precompiled once a build by meshseek_rpc and used by the services and the
# CLI (meshseek_use_rpc_precompiled_header): they were most of those files'
# compilation (the coordinator's 20-line main.cc 7.3 s, ranking.cc 14.7 s
# without, 7.4 s with, under load).
set(MESHSEEK_RPC_PRECOMPILED_HEADERS
    <grpcpp/grpcpp.h> <google/protobuf/message.h>
    [["meshseek/v1/codebook.grpc.pb.h"]] [["meshseek/v1/coordinator.grpc.pb.h"]]
    [["meshseek/v1/extract.grpc.pb.h"]] [["meshseek/v1/index.grpc.pb.h"]]
    [["meshseek/v1/resample.grpc.pb.h"]]
    <algorithm> <cmath> <cstdint> <functional> <map> <memory> <string> <vector>
    [["absl/container/flat_hash_map.h"]] [["absl/status/statusor.h"]]
    [["absl/strings/str_cat.h"]] [["absl/synchronization/mutex.h"]])

# Compiles a target that links meshseek::rpc with its precompiled header.
function(meshseek_use_rpc_precompiled_header target)
  target_precompile_headers(${target} REUSE_FROM meshseek_rpc)
endfunction()

function(meshseek_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;DEPS" ${ARGN})
  add_library(meshseek_${ARG_NAME} STATIC ${ARG_SRCS})
  add_library(meshseek::${ARG_NAME} ALIAS meshseek_${ARG_NAME})
  target_include_directories(meshseek_${ARG_NAME} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(meshseek_${ARG_NAME} PUBLIC ${ARG_DEPS})
endfunction()

# meshseek_add_test(MODULE m NAME n DEPS ... [SRCS ...]
#                   [TIMEOUT s] [CASE_TIMEOUTS "regex=s" ...] [THREADED regex])
#
#   TIMEOUT        seconds each case may take in a release build (default 60);
#   CASE_TIMEOUTS  the cases whose "Suite.Case" name matches a regex get its
#                  seconds instead (the first match wins): a slow case is sized
#                  on its own and never takes its neighbours' time;
#   THREADED       the cases matching this regex ("." for all) exercise the
#                  multi-threaded paths (servers, dispatcher, ingest stream):
#                  they get the CTest label `threads`, the ThreadSanitizer step
#                  runs `ctest -L threads`, and the target joins the
#                  `threaded_tests` target that step builds.
# Timeouts are multiplied by MESHSEEK_TEST_TIMEOUT_SCALE. A case's timeout is
# also its COST, so that a run without CTest's timing history (a fresh clone)
# starts the slow cases first instead of ending on them one at a time.
function(meshseek_add_test)
  if(NOT MESHSEEK_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "MODULE;NAME;TIMEOUT;THREADED" "DEPS;SRCS;CASE_TIMEOUTS" ${ARGN})
  set(target ${ARG_MODULE}_${ARG_NAME}_test)
  add_executable(${target} ${ARG_NAME}_test.cc ${ARG_SRCS})
  target_link_libraries(${target} PRIVATE ${ARG_DEPS} meshseek::test_main)
  target_compile_options(${target} PRIVATE ${MESHSEEK_TEST_COMPILE_OPTIONS})
  target_precompile_headers(${target} REUSE_FROM meshseek_test_main)
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 60)
  endif()

  # The cases are listed when ctest runs (PRE_TEST), not at build time, so a
  # build folder that compiles only some tests (the TSan one) still works.
  gtest_discover_tests(${target}
    TEST_PREFIX "${ARG_MODULE}/${ARG_NAME}_test."
    WORKING_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}
    DISCOVERY_MODE PRE_TEST
    DISCOVERY_TIMEOUT 60)

  # What gtest_discover_tests cannot say (a list-valued ENVIRONMENT, a
  # property per case) is set by a script CTest runs after the discovery,
  # over the cases it found (${target}_TESTS).
  set(script "set(_scale ${MESHSEEK_TEST_TIMEOUT_SCALE})\n")
  string(APPEND script "foreach(_test IN LISTS ${target}_TESTS)\n"
                       "  string(REPLACE [==[${ARG_MODULE}/${ARG_NAME}_test.]==] \"\" _case \"\${_test}\")\n"
                       "  set(_timeout ${ARG_TIMEOUT})\n")
  set(keyword "if")
  foreach(entry IN LISTS ARG_CASE_TIMEOUTS)
    if(NOT entry MATCHES "^(.+)=([0-9]+)$")
      message(FATAL_ERROR "${target}: CASE_TIMEOUTS entry '${entry}' is not regex=seconds")
    endif()
    string(APPEND script "  ${keyword}(_case MATCHES [==[${CMAKE_MATCH_1}]==])\n"
                         "    set(_timeout ${CMAKE_MATCH_2})\n")
    set(keyword "elseif")
  endforeach()
  if(ARG_CASE_TIMEOUTS)
    string(APPEND script "  endif()\n")
  endif()
  string(APPEND script "  math(EXPR _timeout \"\${_timeout} * \${_scale}\")\n"
                       "  set(_labels \"\")\n")
  if(DEFINED ARG_THREADED)
    string(APPEND script "  if(_case MATCHES [==[${ARG_THREADED}]==])\n"
                         "    set(_labels threads)\n"
                         "  endif()\n")
    set_property(GLOBAL APPEND PROPERTY MESHSEEK_THREADED_TESTS ${target})
  endif()
  string(APPEND script
    "  set_tests_properties(\"\${_test}\" PROPERTIES TIMEOUT \${_timeout} COST \${_timeout}\n"
    "    LABELS \"\${_labels}\"\n"
    "    ENVIRONMENT \"MESHSEEK_SOURCE_DIR=${PROJECT_SOURCE_DIR};MESHSEEK_BINARY_DIR=${PROJECT_BINARY_DIR}\")\n"
    "endforeach()\n")
  set(script_file "${CMAKE_CURRENT_BINARY_DIR}/${target}_case_properties.cmake")
  file(WRITE "${script_file}" "${script}")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${script_file}")
endfunction()

# A script test's (not a GoogleTest binary's) timeout: `seconds` in a release
# build, times MESHSEEK_TEST_TIMEOUT_SCALE; its COST too, as above.
function(meshseek_set_test_timeout test seconds)
  math(EXPR scaled "${seconds} * ${MESHSEEK_TEST_TIMEOUT_SCALE}")
  set_tests_properties(${test} PROPERTIES TIMEOUT ${scaled} COST ${scaled})
endfunction()
