# Bare-metal Cortex-M7 (e.g. STM32H7 class: FPU fpv5-d16, double precision in hardware).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
find_program(SC_ARM_SIZE arm-none-eabi-size REQUIRED)
find_program(SC_ARM_NM arm-none-eabi-nm REQUIRED)
set(CMAKE_NM ${SC_ARM_NM})
# The MCU's engine limits: a 12x8x8 mesh and a 128x256 image fit its SRAM (the link fails,
# naming the region, if they ever do not).
set(SC_MCU_LIMITS "-DSC_MAX_MESH_NX=12u -DSC_MAX_MESH_NY=8u -DSC_MAX_MESH_NZ=8u -DSC_MAX_SCAN_LINES=128u -DSC_MAX_SCAN_SAMPLES=256u")
set(CMAKE_C_FLAGS_INIT "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb -ffunction-sections -fdata-sections ${SC_MCU_LIMITS}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb --specs=nano.specs -nostartfiles -Wl,--gc-sections")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
