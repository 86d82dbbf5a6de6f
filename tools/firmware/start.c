/* start.c: the entry point of bench.c as a static Linux program, so that qemu-arm runs code
 * compiled for the Cortex-M4 (Thumb-2 and the single-precision FPU, a subset of what its
 * Cortex-A15 executes): argc and argv from the stack, exit by system call. */
extern int main(int argc, char **argv);
void start_c(long *sp);
void start_c(long *sp) {
  register long r0 __asm__("r0") = main((int)sp[0], (char **)(sp + 1));
  register long r7 __asm__("r7") = 1; /* exit */
  __asm__ volatile("svc 0" : : "r"(r0), "r"(r7));
  for (;;) {
  }
}
__attribute__((naked)) void _start(void) { __asm__ volatile("mov r0, sp\n bl start_c\n"); }
