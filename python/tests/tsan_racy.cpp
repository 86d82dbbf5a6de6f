// The control of python.tsan_threads: a library with a data race (two callers increment one
// global without a lock), instrumented like the module. tsan_control.py calls it from two Python
// threads through ctypes, which releases the GIL; the test passes when ThreadSanitizer, preloaded
// as for the module, reports the race.
#include <unistd.h>

extern "C" {

volatile long rlg_tsan_racy_counter = 0;

void rlg_tsan_racy_bump() {
  for (int i = 0; i < 1000; ++i) {
    rlg_tsan_racy_counter = rlg_tsan_racy_counter + 1;
    usleep(100);  // 0.1 s in all: the two threads' loops overlap
  }
}

}  // extern "C"
