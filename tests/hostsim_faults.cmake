# Fault injection on the host simulator's command line (tests/hostsim_faults.sh): bus-off,
# silence, a flood at full bus load and a display link down, each counted once and recovered
# from within two frames; duplicates counted but not degrading; heavy loss + corruption +
# duplication + reordering on every case with both methods ends running. No deadline miss.
if(TARGET sc-hostsim AND TARGET cases)
  set(_hf ${CMAKE_CURRENT_SOURCE_DIR}/hostsim_faults.sh)
  set(_hf_args $<TARGET_FILE:sc-hostsim> ${PROJECT_BINARY_DIR}/cases
               ${CMAKE_CURRENT_BINARY_DIR}/hostsim_faults)
  add_test(NAME hostsim_faults_episodes COMMAND ${_hf} ${_hf_args} episodes)
  add_test(NAME hostsim_faults_duplicates_not_degrading COMMAND ${_hf} ${_hf_args} duplicates)
  set(_hf_tests hostsim_faults_episodes hostsim_faults_duplicates_not_degrading)
  foreach(_case neck-ijv femoral femoral-dvt)
    foreach(_method msds fem)
      add_test(NAME hostsim_faults_heavy_${_case}_${_method}
               COMMAND ${_hf} ${_hf_args} heavy ${_case} ${_method})
      list(APPEND _hf_tests hostsim_faults_heavy_${_case}_${_method})
    endforeach()
  endforeach()
  set_tests_properties(${_hf_tests} PROPERTIES LABELS hostsim TIMEOUT 300)
endif()
