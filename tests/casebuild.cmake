# Tests of the case builder libraries (tools/casebuild) and the Linux case storage: each
# tests/casebuild/test_*.c is one cmocka executable and one ctest test, label "casebuild".
file(GLOB _casebuild_tests CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/casebuild/test_*.c)
foreach(_src ${_casebuild_tests})
  get_filename_component(_name ${_src} NAME_WE)
  add_executable(${_name} ${_src})
  target_compile_options(${_name} PRIVATE ${SC_WARN} -Wno-missing-prototypes)
  target_compile_definitions(${_name} PRIVATE _GNU_SOURCE SC_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                              SC_BINARY_DIR="${PROJECT_BINARY_DIR}")
  target_link_libraries(${_name} PRIVATE sc_phantom sc_caseimport sc_linux sc_test_support)
  add_dependencies(${_name} sc-casebuild) # some run the program (reconstruct, CLI paths)
  add_test(NAME ${_name} COMMAND ${_name})
  set_tests_properties(${_name} PROPERTIES LABELS casebuild TIMEOUT 600)
endforeach()

# The phantom cases the build ships (target `cases`) must pass the loader.
add_test(NAME casebuild_cases_verify
         COMMAND sc-casebuild verify ${CMAKE_BINARY_DIR}/cases/neck-ijv.scase
                 ${CMAKE_BINARY_DIR}/cases/femoral.scase ${CMAKE_BINARY_DIR}/cases/femoral-dvt.scase)
set_tests_properties(casebuild_cases_verify PROPERTIES LABELS casebuild TIMEOUT 120)

# End to end: a volume in every format by an independent writer (teem's unu, Python, pydicom)
# -> import -> the engine pressing on the host simulator: the vein collapses, the artery holds.
if(TARGET sc-hostsim)
  add_test(NAME casebuild_e2e_import_press
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/casebuild/e2e_import_press.sh
                   $<TARGET_FILE:sc-casebuild> $<TARGET_FILE:sc-hostsim> ${PROJECT_SOURCE_DIR}
                   ${CMAKE_CURRENT_BINARY_DIR}/casebuild_e2e)
  set_tests_properties(casebuild_e2e_import_press PROPERTIES LABELS "casebuild;integration"
                                                             TIMEOUT 300)
endif()

# The command line: strict numbers, named refusals, exit status 2.
add_test(NAME casebuild_cli
         COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/casebuild/casebuild_cli.sh $<TARGET_FILE:sc-casebuild>
                 ${CMAKE_BINARY_DIR}/cases/neck-ijv.scase ${CMAKE_CURRENT_BINARY_DIR}/casebuild_cli)
set_tests_properties(casebuild_cli PROPERTIES LABELS casebuild TIMEOUT 300)
