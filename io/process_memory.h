#pragma once
/// How a process that simulates many runs keeps its memory (glibc's malloc; a no-op elsewhere).
///
/// Every simulated run allocates its columns afresh, and the suites, evaluations and Allan
/// deviations after it their own arrays. glibc's defaults hand blocks above 128 kB back to the
/// system when freed (mmap threshold, heap trim), so the next gyro page-faults them back in,
/// zeroed: a population of 200 gyros of scenarios/paper-population.toml on one thread took 5.3 s
/// user + 2.2 s system CPU so, and 2.6 s + 0.03 s with KeepFreedMemory (the same peak, 18 MB:
/// what is kept is what a gyro uses anyway). Outputs do not change.
///
/// The CLI calls it at start; the Python module offers it as rlgtherm.keep_freed_memory() (the
/// Dask shards call it), since it changes the whole process's allocator, which a library must
/// not do behind its host's back.

namespace rlg::io {

/// Sets glibc's mmap threshold to 512 MiB and its trim threshold to 1 GiB (mallopt).
void KeepFreedMemory();

}  // namespace rlg::io
