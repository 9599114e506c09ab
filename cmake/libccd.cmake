# libccd for the core's collider. One precision everywhere: Debian's libccd-dev is built with
# CCD_DOUBLE, and the cortex-m7 (fpv5-d16, a double-precision FPU) builds the same precision
# from Debian's own source package, so collision results agree across targets.
# The core calls only the MPR functions; mpr.c, support.c and vec3.c reference no heap.
if(SC_LIBCCD_SOURCE_DIR)
  set(_ccd ${SC_LIBCCD_SOURCE_DIR}/src)
  foreach(f mpr.c support.c vec3.c)
    if(NOT EXISTS ${_ccd}/${f})
      message(FATAL_ERROR "SC_LIBCCD_SOURCE_DIR=${SC_LIBCCD_SOURCE_DIR} has no src/${f}; "
                          "run tools/fetch-libccd-source.sh")
    endif()
  endforeach()
  set(_cfg ${CMAKE_BINARY_DIR}/libccd-config)
  file(WRITE ${_cfg}/ccd/config.h "#ifndef __CCD_CONFIG_H__\n#define __CCD_CONFIG_H__\n#define CCD_DOUBLE\n#endif\n")
  file(WRITE ${_cfg}/ccd/ccd_export.h "#ifndef CCD_EXPORT_H\n#define CCD_EXPORT_H\n#define CCD_EXPORT\n#endif\n")
  add_library(sc_ccd STATIC ${_ccd}/mpr.c ${_ccd}/support.c ${_ccd}/vec3.c)
  target_include_directories(sc_ccd SYSTEM PUBLIC ${_cfg} ${_ccd} ${_ccd}/../src)
  target_compile_options(sc_ccd PRIVATE -w -fno-math-errno)
else()
  find_path(SC_CCD_INCLUDE ccd/ccd.h REQUIRED)
  find_library(SC_CCD_LIB ccd REQUIRED)
  add_library(sc_ccd INTERFACE)
  target_include_directories(sc_ccd SYSTEM INTERFACE ${SC_CCD_INCLUDE})
  target_link_libraries(sc_ccd INTERFACE ${SC_CCD_LIB})
endif()
