# test_press_sweep(_fine) and test_physics_robust read the phantom cases that the `cases`
# target builds into the build tree.
foreach(_t test_press_sweep test_press_sweep_fine test_physics_robust test_physics_robust_fine
           test_bscan_flat_press)
  if(TARGET ${_t} AND TARGET cases)
    add_dependencies(${_t} cases)
  endif()
endforeach()
if(TARGET test_press_sweep_fine)
  # six sweeps on the 32x16x16 mesh: minutes under ASan on a shared machine
  set_tests_properties(test_press_sweep_fine PROPERTIES TIMEOUT 2400)
endif()
if(TARGET test_physics_robust_fine)
  # the robustness script six times on the 32x16x16 mesh
  set_tests_properties(test_physics_robust_fine PROPERTIES TIMEOUT 2400)
endif()
# test_assess presses the phantom cases too
if(TARGET test_assess AND TARGET cases)
  add_dependencies(test_assess cases)
endif()
# test_press_pulse presses the phantom cases with their drive on (both meshes, both methods)
if(TARGET test_press_pulse AND TARGET cases)
  add_dependencies(test_press_pulse cases)
  set_tests_properties(test_press_pulse PROPERTIES TIMEOUT 2400)
endif()
