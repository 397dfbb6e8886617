/* Minimal Cortex-M4F vector table for running capi_golden under QEMU (mps2-an386):
 * enable the FPU (CPACR), then newlib's semihosting crt0 (_start). */
extern void _start(void);
static void reset(void) {
  *(volatile unsigned int *)0xE000ED88 |= 0xFu << 20; /* CPACR: CP10, CP11 full access */
  __asm volatile("dsb\n isb");
  _start();
}
__attribute__((section(".vectors"), used)) void (*const vectors[2])(void) = {(void (*)(void))0x20400000, reset};
