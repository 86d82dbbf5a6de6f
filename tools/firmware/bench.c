/* bench.c: calls rlg_comp_update on the first N rows of bench_data.h (N = argv[1]; with
 * -DSTUB, linked without rlg_comp.o, it only passes the inputs on: the size of everything but
 * the compensator and the routines it calls).
 * tools/firmware/numbers.sh counts the instructions qemu-arm executes for two values of N. */
#include "rlg_comp.h"

#include "bench_data.h"

volatile RLG_COMP_REAL sink;

#ifdef STUB
/* Stores every input (so that the data stay linked) and computes nothing. */
static RLG_COMP_REAL Stub(const RLG_COMP_REAL *T, RLG_COMP_REAL t_s, RLG_COMP_REAL bias_dph) {
  int c;
  for (c = 0; c < RLG_COMP_CHANNELS; ++c) sink = T[c];
  sink = t_s;
  return bias_dph;
}
#define INIT(s) ((void)(s))
#define UPDATE(s, t, T, b) ((void)(s), Stub((T), (t), (b)))
#else
#define INIT rlg_comp_init
#define UPDATE rlg_comp_update
#endif

static int Atoi(const char *s) {
  int n = 0;
  while (*s >= '0' && *s <= '9') n = 10 * n + (*s++ - '0');
  return n;
}

int main(int argc, char **argv) {
  rlg_comp_state s;
  int n = argc > 1 ? Atoi(argv[1]) : 0, k, c;
  INIT(&s);
  for (k = 0; k < n && k < BENCH_ROWS; ++k) {
    RLG_COMP_REAL T[RLG_COMP_CHANNELS];
    for (c = 0; c < RLG_COMP_CHANNELS; ++c) T[c] = bench_T[k][c];
    sink = UPDATE(&s, bench_t[k], T, bench_b[k]);
  }
  return 0;
}
