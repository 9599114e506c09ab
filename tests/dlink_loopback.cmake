# Display link end to end over 127.0.0.1 with the real sender and viewer programs
# (tests/dlink_loopback.sh): no line lost when nothing is injected, exactly the injected lines
# counted lost otherwise, recordings written.
if(TARGET sc-viewer AND TARGET sc-dlink-send)
  add_test(NAME dlink_loopback
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/dlink_loopback.sh $<TARGET_FILE:sc-viewer>
                   $<TARGET_FILE:sc-dlink-send> ${CMAKE_CURRENT_BINARY_DIR}/dlink_loopback)
  set_tests_properties(dlink_loopback PROPERTIES LABELS "integration" TIMEOUT 180)
endif()
