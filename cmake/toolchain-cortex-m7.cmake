# Bare-metal Cortex-M7 (e.g. STM32H7 class: FPU fpv5-d16, double precision in hardware).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
find_program(SC_ARM_SIZE arm-none-eabi-size REQUIRED)
find_program(SC_ARM_NM arm-none-eabi-nm REQUIRED)
set(CMAKE_NM ${SC_ARM_NM})
# The MCU's engine limits: an 8x6x6 mesh, a 64x128 image, a 16x16 skin and a 256-entry walker
# cache and one tissue slot (a case switch rebuilds in place) keep the whole engine object
# (442 KiB: 452,592 B of .bss, 70 KiB of the 512 KiB AXI SRAM free) inside the SRAM; the link
# fails, naming the region, if they ever do not.
set(SC_MCU_LIMITS "-DSC_MAX_MESH_NX=8u -DSC_MAX_MESH_NY=6u -DSC_MAX_MESH_NZ=6u -DSC_MAX_SCAN_LINES=64u -DSC_MAX_SCAN_SAMPLES=128u -DSC_MAX_SKIN_NX=16u -DSC_MAX_SKIN_NY=16u -DSC_BSCAN_TET_CACHE=256u -DSC_MSDS_CELL_BLOCK=64u -DSC_ENGINE_TISSUE_SLOTS=1u -DSC_STATE_STREAM=0 -DSC_BSCAN_PSF=0 -DSC_BSCAN_RANGES=1u")
set(CMAKE_C_FLAGS_INIT "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb -ffunction-sections -fdata-sections ${SC_MCU_LIMITS}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb --specs=nano.specs -nostartfiles -Wl,--gc-sections")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
