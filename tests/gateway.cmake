# The console gateway's client-message parser (tools/gateway/gw_msg.c), a cmocka test.
add_executable(test_gw_msg ${CMAKE_CURRENT_SOURCE_DIR}/gateway/test_gw_msg.c)
target_compile_options(test_gw_msg PRIVATE ${SC_WARN} -Wno-missing-prototypes)
target_link_libraries(test_gw_msg PRIVATE sc_test_support sc_gw_msg)
add_test(NAME test_gw_msg COMMAND test_gw_msg)
set_tests_properties(test_gw_msg PROPERTIES LABELS unit TIMEOUT 60)
