# sonocomp -> UDP display link -> sc-viewer on 127.0.0.1 (tests/engine_loopback.sh).
if(TARGET sonocomp AND TARGET sc-viewer AND TARGET sc-casebuild)
  add_test(NAME engine_loopback
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/engine_loopback.sh $<TARGET_FILE:sonocomp>
                   $<TARGET_FILE:sc-viewer> $<TARGET_FILE:sc-casebuild>
                   ${CMAKE_CURRENT_BINARY_DIR}/engine_loopback)
  set_tests_properties(engine_loopback PROPERTIES LABELS "integration" TIMEOUT 300)
endif()
