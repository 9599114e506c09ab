/* startup.c: Cortex-M7 reset: copy .data, zero .bss, enable the FPU, call main. */
#include <stdint.h>
#include <string.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void sc_reset_handler(void);
void sc_default_handler(void);

void sc_default_handler(void)
{
    for (;;) {
    }
}

void sc_reset_handler(void)
{
    /* CPACR: full access to CP10/CP11 (the FPU) before any float instruction */
    volatile uint32_t *cpacr = (volatile uint32_t *)0xE000ED88u;
    *cpacr |= (0xFu << 20);
    __asm volatile("dsb\n isb" ::: "memory");
    memcpy(&_sdata, &_sidata, (size_t)((uintptr_t)&_edata - (uintptr_t)&_sdata));
    memset(&_sbss, 0, (size_t)((uintptr_t)&_ebss - (uintptr_t)&_sbss));
    (void)main();
    sc_default_handler();
}

__attribute__((section(".isr_vector"), used)) static const uintptr_t vectors[16] = {
    (uintptr_t)&_estack,            (uintptr_t)sc_reset_handler,   (uintptr_t)sc_default_handler,
    (uintptr_t)sc_default_handler,  (uintptr_t)sc_default_handler, (uintptr_t)sc_default_handler,
    (uintptr_t)sc_default_handler,  0u, 0u, 0u, 0u,
    (uintptr_t)sc_default_handler,  (uintptr_t)sc_default_handler, 0u,
    (uintptr_t)sc_default_handler,  (uintptr_t)sc_default_handler,
};
