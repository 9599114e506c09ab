# The build's symbol check passes on the core and fails on objects that touch the heap or stdio.
add_library(sc_fixture_bad_alloc STATIC ${CMAKE_CURRENT_SOURCE_DIR}/fixtures/core_bad_alloc.c)
add_library(sc_fixture_bad_stdio STATIC ${CMAKE_CURRENT_SOURCE_DIR}/fixtures/core_bad_stdio.c)
add_test(NAME build_symbol_check_accepts_core
  COMMAND ${CMAKE_COMMAND} -DNM=${CMAKE_NM} -DLIB=$<TARGET_FILE:sc_core>
          -P ${PROJECT_SOURCE_DIR}/cmake/check_core_symbols.cmake)
add_test(NAME build_symbol_check_rejects_malloc
  COMMAND ${CMAKE_COMMAND} -DNM=${CMAKE_NM} -DLIB=$<TARGET_FILE:sc_fixture_bad_alloc>
          -P ${PROJECT_SOURCE_DIR}/cmake/check_core_symbols.cmake)
add_test(NAME build_symbol_check_rejects_stdio
  COMMAND ${CMAKE_COMMAND} -DNM=${CMAKE_NM} -DLIB=$<TARGET_FILE:sc_fixture_bad_stdio>
          -P ${PROJECT_SOURCE_DIR}/cmake/check_core_symbols.cmake)
set_tests_properties(build_symbol_check_accepts_core build_symbol_check_rejects_malloc
  build_symbol_check_rejects_stdio PROPERTIES LABELS build)
set_tests_properties(build_symbol_check_rejects_malloc PROPERTIES
  PASS_REGULAR_EXPRESSION "forbidden symbols: malloc")
set_tests_properties(build_symbol_check_rejects_stdio PROPERTIES
  PASS_REGULAR_EXPRESSION "forbidden symbols: printf")
