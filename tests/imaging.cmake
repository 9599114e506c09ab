# test_bscan_phantoms images the phantom cases generated in memory by the case builder's
# library.
if(TARGET test_bscan_phantoms AND TARGET sc_phantom)
  target_link_libraries(test_bscan_phantoms PRIVATE sc_phantom)
endif()
