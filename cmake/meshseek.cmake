# One helper per kind of target, COLMAP-style.
#
#   meshseek_add_library(NAME geometry SRCS a.cc b.cc DEPS ...)
#     -> static library target meshseek_geometry (alias meshseek::geometry), include root = repo root
#   meshseek_add_test(MODULE geometry NAME sobol DEPS ...)
#     -> executable geometry_sobol_test from sobol_test.cc, registered in CTest as
#        "geometry/sobol_test" so that `ctest -R geometry/` runs one module.

function(meshseek_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;DEPS" ${ARGN})
  add_library(meshseek_${ARG_NAME} STATIC ${ARG_SRCS})
  add_library(meshseek::${ARG_NAME} ALIAS meshseek_${ARG_NAME})
  target_include_directories(meshseek_${ARG_NAME} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(meshseek_${ARG_NAME} PUBLIC ${ARG_DEPS})
endfunction()

function(meshseek_add_test)
  if(NOT MESHSEEK_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "MODULE;NAME;TIMEOUT" "DEPS;SRCS" ${ARGN})
  set(target ${ARG_MODULE}_${ARG_NAME}_test)
  add_executable(${target} ${ARG_NAME}_test.cc ${ARG_SRCS})
  target_link_libraries(${target} PRIVATE ${ARG_DEPS} meshseek::test_main)
  add_test(NAME ${ARG_MODULE}/${ARG_NAME}_test COMMAND ${target}
           WORKING_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR})
  if(ARG_TIMEOUT)
    set_tests_properties(${ARG_MODULE}/${ARG_NAME}_test PROPERTIES TIMEOUT ${ARG_TIMEOUT})
  endif()
  set_tests_properties(${ARG_MODULE}/${ARG_NAME}_test PROPERTIES
    ENVIRONMENT "MESHSEEK_SOURCE_DIR=${PROJECT_SOURCE_DIR};MESHSEEK_BINARY_DIR=${PROJECT_BINARY_DIR}")
endfunction()
