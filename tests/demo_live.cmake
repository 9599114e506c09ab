# tools/demo-live.sh on this build: tracker emulator log -> sonocomp --can-replay (FEM, neck-ijv)
# -> UDP display link -> sc-viewer --record-png; no CAN, no privileges (tests/demo_live.sh).
if(TARGET sonocomp AND TARGET sc-tracker-emu AND TARGET sc-viewer AND TARGET sc-casebuild)
  add_test(NAME demo_live
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/demo_live.sh ${PROJECT_SOURCE_DIR}/tools/demo-live.sh
                   ${PROJECT_BINARY_DIR} ${CMAKE_CURRENT_BINARY_DIR}/demo_live)
  set_tests_properties(demo_live PROPERTIES LABELS "hostsim" TIMEOUT 120)
endif()
