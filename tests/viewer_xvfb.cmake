# sc-viewer in a real SDL2 window on Xvfb, checked through the X server's framebuffer
# (tests/viewer_xvfb.sh, tests/tools/xwd_probe.c). Skipped (77) where Xvfb is missing.
if(TARGET sc-viewer AND TARGET sc-dlink-send)
  add_executable(xwd_probe ${CMAKE_CURRENT_SOURCE_DIR}/tools/xwd_probe.c)
  target_compile_options(xwd_probe PRIVATE ${SC_WARN})
  add_test(NAME viewer_xvfb
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/viewer_xvfb.sh $<TARGET_FILE:sc-viewer>
                   $<TARGET_FILE:sc-dlink-send> $<TARGET_FILE:xwd_probe>
                   ${CMAKE_CURRENT_BINARY_DIR}/viewer_xvfb)
  set_tests_properties(viewer_xvfb PROPERTIES LABELS "integration" TIMEOUT 120
                                              SKIP_RETURN_CODE 77)
endif()
