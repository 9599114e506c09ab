# Compiler workarounds, each with the reason it exists.
# GCC 12.2 (Debian 12) for aarch64 stops with an internal compiler error in the vectoriser
# (vect_transform_reduction, tree-vect-loop.cc:7457) on a reduction loop of test_sc_fem.c at
# -O2. The test needs no vectorisation; the FEM code under test is compiled as usual.
if(CMAKE_SYSTEM_PROCESSOR STREQUAL "aarch64" AND CMAKE_C_COMPILER_ID STREQUAL "GNU"
   AND TARGET test_sc_fem)
  target_compile_options(test_sc_fem PRIVATE -fno-tree-vectorize)
endif()
