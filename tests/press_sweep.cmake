# test_press_sweep reads the phantom cases that the `cases` target builds into the build tree.
if(TARGET test_press_sweep AND TARGET cases)
  add_dependencies(test_press_sweep cases)
endif()
if(TARGET test_physics_robust AND TARGET cases)
  add_dependencies(test_physics_robust cases)
endif()
