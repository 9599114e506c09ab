# The host-noise probe's command line and table (tests/host_noise_cli.sh).
if(TARGET sc-host-noise)
  add_test(NAME host_noise_cli COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/host_noise_cli.sh
                                       $<TARGET_FILE:sc-host-noise>)
  set_tests_properties(host_noise_cli PROPERTIES LABELS "integration" TIMEOUT 60)
endif()
