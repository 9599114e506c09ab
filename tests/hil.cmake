# HIL tests in the small VM of tools/hil/vm.sh (real kernel: bochs DRM/KMS + fbdev, vcan).
# Labelled "hil"; they report SKIPPED (exit 77, with the reason) where qemu is missing.
add_test(NAME hil_display_kms
  COMMAND ${PROJECT_SOURCE_DIR}/tools/hil/ctest-hil.sh display ${PROJECT_BINARY_DIR})
set_tests_properties(hil_display_kms PROPERTIES LABELS hil SKIP_RETURN_CODE 77 TIMEOUT 900
  RESOURCE_LOCK hil_vm)
add_test(NAME hil_can_socketcan
  COMMAND ${PROJECT_SOURCE_DIR}/tools/hil/ctest-hil.sh can ${PROJECT_BINARY_DIR})
set_tests_properties(hil_can_socketcan PROPERTIES LABELS hil SKIP_RETURN_CODE 77 TIMEOUT 900
  RESOURCE_LOCK hil_vm)
add_test(NAME hil_engine_socketcan
  COMMAND ${PROJECT_SOURCE_DIR}/tools/hil/ctest-hil.sh engine ${PROJECT_BINARY_DIR})
set_tests_properties(hil_engine_socketcan PROPERTIES LABELS hil SKIP_RETURN_CODE 77 TIMEOUT 900
  RESOURCE_LOCK hil_vm)
