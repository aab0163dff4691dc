# delineo_set_warnings(target): the project's warning set; errors in CI builds.
function(delineo_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow=local
    -Wnon-virtual-dtor -Wcast-align -Woverloaded-virtual -Wno-deprecated-enum-enum-conversion)
  if(DELINEO_WARNINGS_AS_ERRORS)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# delineo_add_library(name SOURCES ... DEPS ...): one algorithm domain as a static library
# with public headers under algorithms/<domain>/include/delineo/<domain>/.
function(delineo_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(delineo_${name} STATIC ${ARG_SOURCES})
  add_library(delineo::${name} ALIAS delineo_${name})
  target_include_directories(delineo_${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(delineo_${name} PUBLIC ${ARG_DEPS})
  delineo_set_warnings(delineo_${name})
endfunction()

# delineo_add_gtest(name LABEL unit SOURCES ... DEPS ...)
function(delineo_add_gtest name)
  cmake_parse_arguments(ARG "" "LABEL;TIMEOUT" "SOURCES;DEPS" ${ARGN})
  if(NOT ARG_LABEL)
    set(ARG_LABEL unit)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  delineo_set_warnings(${name})
  gtest_discover_tests(${name} PROPERTIES LABELS ${ARG_LABEL} DISCOVERY_TIMEOUT 60
    WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
endfunction()
