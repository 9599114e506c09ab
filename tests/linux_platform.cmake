# Unit tests of platform/linux pieces link the Linux platform library too (they are registered
# by the tests/unit glob like every other unit test).
foreach(_t test_sc_udp_display test_sc_png_write test_sc_png_sink test_sc_log_linux test_sc_rt
           test_sc_can_replay)
  if(TARGET ${_t} AND TARGET sc_linux)
    target_link_libraries(${_t} PRIVATE sc_linux)
    target_compile_definitions(${_t} PRIVATE _GNU_SOURCE)
  endif()
endforeach()

# The viewer's GIF writer is tested against an independent decoder.
if(TARGET test_sc_viewer_cine)
  target_link_libraries(test_sc_viewer_cine PRIVATE sc_viewer_parts)
endif()
if(TARGET test_sc_viewer_gif)
  target_link_libraries(test_sc_viewer_gif PRIVATE sc_viewer_parts)
endif()
