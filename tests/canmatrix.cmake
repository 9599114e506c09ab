# CAN protocol checks beyond the cmocka glob (included by tests/CMakeLists.txt).
#
# 1. The unit tests of the Linux CAN pieces link the Linux platform library.
foreach(_t test_sc_candump test_sc_socketcan)
  if(TARGET ${_t} AND TARGET sc_linux)
    target_link_libraries(${_t} PRIVATE sc_linux)
    target_compile_definitions(${_t} PRIVATE _GNU_SOURCE)
  endif()
endforeach()
#    The tracker emulator's generator (tools/tracker_emu) against the tracker.
foreach(_t test_sc_trkemu test_can_tracker_bus)
  if(TARGET ${_t} AND TARGET sc_trkemu)
    target_link_libraries(${_t} PRIVATE sc_trkemu)
    target_compile_definitions(${_t} PRIVATE _GNU_SOURCE)
  endif()
endforeach()
if(TARGET test_can_tracker_bus AND TARGET sc_linux)
  target_link_libraries(test_can_tracker_bus PRIVATE sc_linux m)
endif()

# 2. An independent reader of config/sonocomp.dbc: Debian's python3-canmatrix loads the DBC and
#    decodes frames that the core codec encoded (tests/can/sc_canproto_dump prints them with the
#    physical values the core decoded). Skipped (ctest SKIP) when canmatrix is not installed.
add_executable(sc_canproto_dump ${CMAKE_CURRENT_SOURCE_DIR}/can/sc_canproto_dump.c)
target_compile_options(sc_canproto_dump PRIVATE ${SC_WARN})
target_link_libraries(sc_canproto_dump PRIVATE sc_core sc_host_assert)
# Debian's interpreter first: canmatrix is a Debian package, a pyenv python may not see it.
find_program(SC_DEBIAN_PYTHON3 NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
find_program(SC_DEBIAN_PYTHON3 NAMES python3)
if(SC_DEBIAN_PYTHON3)
  add_test(NAME canmatrix_dbc_check
           COMMAND ${SC_DEBIAN_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/can/canmatrix_check.py
                   ${PROJECT_SOURCE_DIR}/config/sonocomp.dbc $<TARGET_FILE:sc_canproto_dump>)
  set_tests_properties(canmatrix_dbc_check PROPERTIES LABELS unit SKIP_RETURN_CODE 77
                       TIMEOUT 120)
endif()
