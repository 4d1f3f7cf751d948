# Warning set of docs/conventions.md, section 10, as an interface target every dhcal target links.
add_library(dhcal_warnings INTERFACE)
target_compile_options(dhcal_warnings INTERFACE
  -Wall -Wextra -pedantic -Wconversion -Wsign-conversion -Wdouble-promotion -Wfloat-equal
  -Wshadow -Wcast-qual -Wmissing-prototypes -Wundef -Wstrict-prototypes -Wvla)
if(DHCAL_WERROR)
  target_compile_options(dhcal_warnings INTERFACE -Werror)
endif()
