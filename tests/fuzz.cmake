# Fuzz targets: every tests/fuzz/fuzz_<name>.c builds
#  - always as <target>_smoke, a ctest test (label "fuzz", the dev preset's sanitizers): it
#    replays the checked-in corpus tests/fuzz/corpus/<name>/ and the crash regressions
#    tests/fuzz/regress/<name>/, then 20,000 deterministic mutations of the target's seeds;
#  - with the fuzz preset (clang, -DSC_FUZZ=ON: every library built with
#    -fsanitize=fuzzer-no-link, so coverage is the project's, not the harness's) as
#    <target>_libfuzzer, all of them under the custom target fuzz_all (tools/fuzz.sh,
#    tools/check-fuzz.sh).
# <target> is the file's name (fuzz_sc_case), <name> the same without "fuzz_" (sc_case). An
# optional tests/fuzz/<target>.libs lists the libraries it links besides sc_hostsim.
file(GLOB _fuzz_srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_*.c)
if(SC_FUZZ)
  add_custom_target(fuzz_all)
endif()
foreach(_src ${_fuzz_srcs})
  get_filename_component(_name ${_src} NAME_WE)
  string(REGEX REPLACE "^fuzz_" "" _short ${_name})
  set(_libs "")
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/${_name}.libs)
    file(READ ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/${_name}.libs _libs)
    string(STRIP "${_libs}" _libs)
    string(REGEX REPLACE "[ \t\r\n]+" ";" _libs "${_libs}")
  endif()
  add_executable(${_name}_smoke ${_src} ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/sc_fuzz_main.c)
  target_include_directories(${_name}_smoke PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/fuzz)
  target_compile_options(${_name}_smoke PRIVATE ${SC_WARN} -Wno-missing-prototypes)
  target_compile_definitions(${_name}_smoke PRIVATE SC_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  target_link_libraries(${_name}_smoke PRIVATE sc_hostsim ${_libs})
  set(_replay "")
  foreach(_dir corpus regress)
    if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/${_dir}/${_short})
      list(APPEND _replay ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/${_dir}/${_short})
    endif()
  endforeach()
  add_test(NAME ${_name} COMMAND ${_name}_smoke 20000 ${_replay})
  set_tests_properties(${_name} PROPERTIES LABELS fuzz TIMEOUT 600)
  if(SC_FUZZ)
    add_executable(${_name}_libfuzzer ${_src})
    target_include_directories(${_name}_libfuzzer PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/fuzz)
    target_compile_options(${_name}_libfuzzer PRIVATE ${SC_WARN} -Wno-missing-prototypes)
    target_compile_definitions(${_name}_libfuzzer PRIVATE SC_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
    target_link_options(${_name}_libfuzzer PRIVATE -fsanitize=fuzzer)
    target_link_libraries(${_name}_libfuzzer PRIVATE sc_hostsim ${_libs})
    add_dependencies(fuzz_all ${_name}_libfuzzer ${_name}_smoke)
  endif()
endforeach()
