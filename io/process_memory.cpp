#include "io/process_memory.h"

#include <cstdlib>  // defines __GLIBC__ on glibc (through <features.h>)
#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace rlg::io {

void KeepFreedMemory() {
#ifdef __GLIBC__
  mallopt(M_MMAP_THRESHOLD, 512 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

}  // namespace rlg::io
