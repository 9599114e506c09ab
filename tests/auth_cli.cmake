# Authenticated commands end to end: sc-tracker-emu signs (Mbed TLS), sonocomp verifies (the
# core's AES-CMAC) from a replayed candump log (tests/auth_cli.sh).
if(TARGET sonocomp AND TARGET sc-tracker-emu)
  add_test(NAME auth_cli
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/auth_cli.sh $<TARGET_FILE:sonocomp>
                   $<TARGET_FILE:sc-tracker-emu> ${CMAKE_CURRENT_BINARY_DIR}/auth_cli)
  set_tests_properties(auth_cli PROPERTIES LABELS "integration" TIMEOUT 120)
endif()
