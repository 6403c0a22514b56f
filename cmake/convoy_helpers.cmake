# Small helpers so that each component's build file is a few lines.

set(CONVOY_WARNINGS -Wall -Wextra -Wpedantic -Wno-unused-parameter)

# convoy_add_library(name SOURCES ... DEPS ...)
function(convoy_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_compile_options(${name} PRIVATE ${CONVOY_WARNINGS})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS})
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()

# convoy_use_fast_malloc(target): links jemalloc into a program when it was found. For the
# world engine and the programs that measure it: DART allocates its contact constraints every
# physics step. Not for programs that run Python: jemalloc halves the speed of NRP-Core's
# b_image_json benchmark (a list of a million ints per frame).
function(convoy_use_fast_malloc target)
  if(JEMALLOC_FOUND)
    target_link_libraries(${target} PRIVATE PkgConfig::JEMALLOC)
  endif()
endfunction()

# convoy_add_engine(type SOURCES ... DEPS ... [SCHEMA file] [ALIASES a b])
# Builds bin/convoy-engine-<type> from the sources (which register the engine class
# with CONVOY_REGISTER_ENGINE) and installs its config schema under share/convoy/engines.
function(convoy_add_engine type)
  cmake_parse_arguments(ARG "" "SCHEMA" "SOURCES;DEPS;ALIASES" ${ARGN})
  set(target convoy-engine-${type})
  add_executable(${target} ${ARG_SOURCES})
  target_compile_options(${target} PRIVATE ${CONVOY_WARNINGS})
  target_link_libraries(${target} PRIVATE convoy_engine_main ${ARG_DEPS})
  if(ARG_SCHEMA)
    configure_file(${ARG_SCHEMA} ${CONVOY_SHARE_DIR}/engines/${type}.schema.json COPYONLY)
  endif()
  foreach(alias ${ARG_ALIASES})
    file(WRITE ${CONVOY_SHARE_DIR}/engines/${alias}.alias "${type}\n")
  endforeach()
endfunction()

# convoy_add_test(name SOURCES ... DEPS ...)
function(convoy_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_compile_options(${name} PRIVATE ${CONVOY_WARNINGS})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest_main)
  target_include_directories(${name} PRIVATE ${CMAKE_SOURCE_DIR}/tests)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 30)
endfunction()
