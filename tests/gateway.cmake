# The console gateway's client-message parser (tools/gateway/gw_msg.c), a cmocka test.
add_executable(test_gw_msg ${CMAKE_CURRENT_SOURCE_DIR}/gateway/test_gw_msg.c)
target_compile_options(test_gw_msg PRIVATE ${SC_WARN} -Wno-missing-prototypes)
target_link_libraries(test_gw_msg PRIVATE sc_test_support sc_gw_msg)
add_test(NAME test_gw_msg COMMAND test_gw_msg)
set_tests_properties(test_gw_msg PROPERTIES LABELS unit TIMEOUT 60)
# The console's B-scan message (tools/gateway/gw_bscan.c: image, parameters, colour box, spectrum).
add_executable(test_gw_bscan ${CMAKE_CURRENT_SOURCE_DIR}/gateway/test_gw_bscan.c)
target_compile_options(test_gw_bscan PRIVATE ${SC_WARN} -Wno-missing-prototypes)
target_link_libraries(test_gw_bscan PRIVATE sc_test_support sc_gw_bscan)
add_test(NAME test_gw_bscan COMMAND test_gw_bscan)
set_tests_properties(test_gw_bscan PROPERTIES LABELS unit TIMEOUT 60)
