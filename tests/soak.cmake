# The CAN traffic soak (tests/soak/sc_soak_frames.c, tools/soak-frames.sh): under ctest a short
# run (SC_SOAK_CAN_FRAMES, default 60,000 CAN frames; 2 x 20 s CPU with the dev preset's
# sanitizers) twice with the same seed, checkpoints compared; tools/soak-frames.sh runs the
# million.
set(SC_SOAK_CAN_FRAMES 60000 CACHE STRING "CAN frames of the soak test under ctest")
add_executable(sc_soak_frames ${CMAKE_CURRENT_SOURCE_DIR}/soak/sc_soak_frames.c)
target_compile_options(sc_soak_frames PRIVATE ${SC_WARN} -Wno-missing-prototypes)
target_link_libraries(sc_soak_frames PRIVATE sc_test_support)
add_test(NAME soak_can_frames
         COMMAND ${PROJECT_SOURCE_DIR}/tools/soak-frames.sh --bin $<TARGET_FILE:sc_soak_frames>
                 --out ${CMAKE_CURRENT_BINARY_DIR}/soak ${SC_SOAK_CAN_FRAMES})
set_tests_properties(soak_can_frames PROPERTIES LABELS hostsim TIMEOUT 600)
