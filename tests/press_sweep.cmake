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
# the robustness script on the largest mesh the limits allow (64x32x32), neck-ijv, the stable
# MSDS: the deepest press with the tracker lost for a frame threw a lumen node there (the step
# clamp, docs/physics.md "The finest meshes"); about 6 minutes under ASan
if(TARGET test_physics_robust)
  add_test(NAME test_physics_robust_64 COMMAND test_physics_robust)
  set_tests_properties(test_physics_robust_64 PROPERTIES TIMEOUT 2400 LABELS hostsim
    ENVIRONMENT "SC_ROBUST_MESH=64,32,32;SC_ROBUST_CASE=neck-ijv;SC_ROBUST_METHOD=msds")
endif()
