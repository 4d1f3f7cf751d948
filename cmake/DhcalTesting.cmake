# dhcal_add_unity_test(<source.c> LABELS <labels...>)
#   One Unity executable per test file, named after it, registered with CTest.
#   Linked with the lib, Unity and the full warning set (tests compare doubles through
#   tolerances, so -Wfloat-equal and friends stay on); tests/support/ is on the include path.
#   Bare metal (DHCAL_BARE_METAL): also links the startup/semihosting runtime and linker
#   script of tests/target/. Cross builds (bare metal, aarch64-linux) add the label `target`;
#   CTest runs the executable through CMAKE_CROSSCOMPILING_EMULATOR (qemu-mps2-an386.sh,
#   qemu-aarch64).
# dhcal_add_unity_executable(<source.c>)
#   The executable alone, for binaries that a wrapper test runs (tests/target/).

function(dhcal_add_unity_executable src)
  get_filename_component(name ${src} NAME_WE)
  add_executable(${name} ${src})
  target_link_libraries(${name} PRIVATE dhcal dhcal_unity dhcal_warnings)
  if(IS_DIRECTORY ${PROJECT_SOURCE_DIR}/tests/support)
    target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/support)
  endif()
  if(DHCAL_BARE_METAL)
    target_link_libraries(${name} PRIVATE dhcal_target_rt)
  endif()
endfunction()

function(dhcal_add_unity_test src)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "LABELS")
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "dhcal_add_unity_test: unexpected ${arg_UNPARSED_ARGUMENTS}")
  endif()
  dhcal_add_unity_executable(${src})
  get_filename_component(name ${src} NAME_WE)
  set(labels ${arg_LABELS})
  # Cross builds (bare metal, aarch64-linux) run their tests on the target through
  # CMAKE_CROSSCOMPILING_EMULATOR: those are the `target` label.
  if(DHCAL_BARE_METAL OR CMAKE_CROSSCOMPILING)
    list(APPEND labels target)
  endif()
  add_test(NAME ${name} COMMAND ${name})
  set_tests_properties(${name} PROPERTIES LABELS "${labels}")
endfunction()
