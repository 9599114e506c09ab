# bench-paper's smoke test (tests/bench_paper_smoke.sh): the smallest settings (two tiny meshes,
# 2 frames x 2 runs, 1 and 2 workers, the PNG sink) in seconds; checks that it exits 0, prints
# both tables, writes a well-formed CSV with every row and a decodable Fig. 9 PNG with bars
# (bench-paper-check), Bullet's rows when Bullet was built in, and the sink's B-scan PNGs.
# No timing is asserted.
if(TARGET bench-paper AND TARGET bench-paper-check)
  add_test(NAME bench_paper_smoke
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/bench_paper_smoke.sh $<TARGET_FILE:bench-paper>
                   $<TARGET_FILE:bench-paper-check> ${CMAKE_CURRENT_BINARY_DIR}/bench_paper_smoke)
  set_tests_properties(bench_paper_smoke PROPERTIES LABELS "integration" TIMEOUT 300)
endif()
