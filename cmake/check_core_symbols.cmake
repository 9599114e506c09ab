# Fails when an archive or object (LIB) references heap, stdio or OS symbols.
# Usage: cmake -DNM=<nm> -DLIB=<file> [-DEXPECT_FAIL=1] -P check_core_symbols.cmake
execute_process(COMMAND ${NM} -u ${LIB} OUTPUT_VARIABLE _out RESULT_VARIABLE _rc)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${LIB}")
endif()
set(_forbidden
  malloc calloc realloc free aligned_alloc posix_memalign memalign valloc strdup strndup
  printf fprintf sprintf snprintf vprintf vfprintf vsnprintf puts fputs putchar fputc
  fopen fclose fread fwrite fflush fseek ftell perror getenv
  open close read write lseek mmap munmap ioctl socket bind sendto recvfrom recv send
  clock_gettime clock_nanosleep nanosleep usleep sleep time gettimeofday
  pthread_create pthread_mutex_lock sched_setscheduler
  exit _exit abort __assert_fail __stack_chk_fail_local_unused)
string(REPLACE "\n" ";" _lines "${_out}")
set(_hits "")
foreach(_l IN LISTS _lines)
  string(STRIP "${_l}" _l)
  string(REGEX REPLACE "^U[ \t]+" "" _sym "${_l}")
  string(REGEX REPLACE "@.*$" "" _sym "${_sym}")
  # glibc fortify and ISO C23 aliases map to the same calls.
  string(REGEX REPLACE "^__(.*)_chk$" "\\1" _base "${_sym}")
  string(REGEX REPLACE "^__isoc99_" "" _base "${_base}")
  list(FIND _forbidden "${_base}" _idx)
  if(NOT _idx EQUAL -1)
    list(APPEND _hits "${_sym}")
  endif()
endforeach()
if(_hits)
  list(REMOVE_DUPLICATES _hits)
  message(FATAL_ERROR "core references forbidden symbols: ${_hits} (in ${LIB})")
endif()
message(STATUS "symbol check: ${LIB} references no heap, stdio or OS symbols")
