# cmake -DNM=<nm> -DARCHIVE=<lib.a> -P check_no_heap_no_stdio.cmake
# Fails when any object in ARCHIVE references the heap or stdio: lib/ promises neither
# (docs/architecture.md, section 3), and on the target either would drag in newlib's
# syscalls and sbrk.
# Reads undefined symbols (nm -u), so it sees what the code calls, whatever the headers.
foreach(v NM ARCHIVE)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "pass -D${v}=...")
  endif()
endforeach()
if(NOT EXISTS "${ARCHIVE}")
  message(FATAL_ERROR "${ARCHIVE}: no such archive")
endif()
execute_process(COMMAND ${NM} -A -u -P ${ARCHIVE}
                OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${NM} failed (${rc}): ${err}")
endif()

# `_?` and `(_r)?` catch newlib's reentrant forms (_malloc_r, _fwrite_r); `[a-z_]*printf`
# and `[a-z_]*scanf` the whole families (vsnprintf, iprintf, __sprintf_chk). _impure_ptr is
# how newlib reaches stdin/stdout/stderr (and errno: a libm wrapper, not lib code, uses that).
string(CONCAT heap "_?(malloc|calloc|realloc|reallocarray|free|aligned_alloc|memalign"
       "|posix_memalign|valloc|sbrk)(_r)?")
string(CONCAT stdio "_*[a-z_]*printf(_r)?|_*[a-z_]*scanf(_r)?"
       "|_?(puts|fputs|putchar|putc|fputc|getchar|getc|fgetc|gets|fgets|ungetc|fopen|fdopen"
       "|freopen|fclose|fflush|fread|fwrite|fseek|ftell|rewind|setbuf|setvbuf|perror|tmpfile"
       "|remove|rename|fileno)(_r)?|__sputc_r|__swbuf_r|__srget_r|_impure_ptr|stdin|stdout|stderr")
string(REGEX MATCHALL "[^\n]+" lines "${out}")
set(bad "")
foreach(line IN LISTS lines)
  # "lib.a[member.o]: symbol U"
  if(line MATCHES "^(.*): ([^ ]+) [Uu]")
    set(where "${CMAKE_MATCH_1}")
    set(sym "${CMAKE_MATCH_2}")
    if(sym MATCHES "^(${heap}|${stdio})$")
      string(APPEND bad "  ${where}: ${sym}\n")
    endif()
  endif()
endforeach()
if(bad)
  message(FATAL_ERROR "${ARCHIVE} references the heap or stdio:\n${bad}")
endif()
list(LENGTH lines n)
message(STATUS "${ARCHIVE}: no heap, no stdio (${n} undefined references checked)")
