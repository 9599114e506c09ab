# The engine binary's command line, configuration errors, exit codes and clean stop
# (tests/sonocomp_cli.sh).
if(TARGET sonocomp)
  add_test(NAME sonocomp_cli
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/sonocomp_cli.sh $<TARGET_FILE:sonocomp>
                   ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/sonocomp_cli
                   ${CMAKE_BINARY_DIR}/cases/neck-ijv.scase)
  set_tests_properties(sonocomp_cli PROPERTIES LABELS "integration" TIMEOUT 120)
endif()
