# The console in a real browser (tests/browser/console_test.mjs): Debian's chromium driven by
# playwright-core (tools/console/package.json) against sc-gateway and sc-hostsim --live. They
# report SKIPPED (77) only when chromium is not installed; a missing node, playwright-core or
# program is a failure (CI installs them: tools/install-deps.sh base). About 20-40 s each.
if(TARGET sc-gateway AND TARGET sc-hostsim AND TARGET sc-tracker-emu)
  find_program(SC_NODE node)
  foreach(_scenario controls press sessions doppler material)
    if(SC_NODE)
      add_test(NAME browser_console_${_scenario}
               COMMAND ${SC_NODE} ${CMAKE_CURRENT_SOURCE_DIR}/browser/console_test.mjs ${_scenario})
    else()
      add_test(NAME browser_console_${_scenario}
               COMMAND ${CMAKE_COMMAND} -E echo "node (nodejs) not found: tools/install-deps.sh")
      set_tests_properties(browser_console_${_scenario} PROPERTIES WILL_FAIL TRUE)
    endif()
    set_tests_properties(browser_console_${_scenario} PROPERTIES
      LABELS "integration;browser" TIMEOUT 180 SKIP_RETURN_CODE 77 RUN_SERIAL TRUE
      ENVIRONMENT "SC_BUILD_DIR=${PROJECT_BINARY_DIR};SC_CONSOLE_SRC=${PROJECT_SOURCE_DIR}/tools/console;SC_OUT_DIR=${CMAKE_CURRENT_BINARY_DIR}/browser")
  endforeach()
endif()
