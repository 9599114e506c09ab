# Session bundles on sc-hostsim's command line (tests/hostsim_bundle.sh): record then replay
# with identical per-frame image hashes; a bundle whose case is missing or different, or that
# is truncated or corrupt, is refused.
if(TARGET sc-hostsim AND TARGET cases)
  set(_hb ${CMAKE_CURRENT_SOURCE_DIR}/hostsim_bundle.sh)
  set(_hb_args $<TARGET_FILE:sc-hostsim> ${PROJECT_BINARY_DIR}/cases
               ${CMAKE_CURRENT_BINARY_DIR}/hostsim_bundle)
  add_test(NAME hostsim_bundle_record_replay_identical COMMAND ${_hb} ${_hb_args} replay)
  add_test(NAME hostsim_bundle_bad_bundles_refused COMMAND ${_hb} ${_hb_args} refuse)
  set_tests_properties(hostsim_bundle_record_replay_identical hostsim_bundle_bad_bundles_refused
                       PROPERTIES LABELS hostsim TIMEOUT 300)
endif()
