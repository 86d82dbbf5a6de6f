"""The module's threaded paths on two Python threads at once, for ThreadSanitizer: ctest
`python.tsan_threads` (label tsan) in build-tsan runs it on the instrumented module, in Debian's
interpreter with TSan's runtime preloaded (python/CMakeLists.txt). The interpreter is not
instrumented; TSan sees the module's and the libraries' memory accesses and the GIL's mutex and
condition variable, whose hand-overs order them. A race halts the run with exit 66 and both
threads' stacks. Every call below releases the GIL while the library works; each pair runs the
same call on both threads, on shared inputs (read only) and separate outputs.

Not a pytest file (no test_ prefix): `python3 tsan_threads.py` with RLG_SOURCE_DIR set."""
import os
import sys
import tempfile
import threading
import warnings

import numpy as np

import rlgtherm

SOURCE = os.environ["RLG_SOURCE_DIR"]
SHORT = os.path.join(SOURCE, "tests/cli/data/short.toml")  # two 600 s runs of the default gyro
SMALL = os.path.join(SOURCE, "tests/data/population/small.toml")  # a population suite of 24 gyros


def both(name, work):
    """work(i) on threads i = 0 and 1 at once; both must return."""
    results = [None, None]
    errors = []

    def run(i):
        try:
            results[i] = work(i)
        except BaseException as e:  # reported below, the other thread still joins
            errors.append(e)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
    print(f"{name}: both threads done", flush=True)
    return results


def main():
    tmp = tempfile.mkdtemp(prefix="rlg_tsan_")
    trace = rlgtherm.simulate(SHORT, seed=1)
    csv = os.path.join(tmp, "short.csv")
    rlgtherm.write_csv(trace, csv)

    both("simulate", lambda i: rlgtherm.simulate(SHORT, seed=i))
    # write_csv: the signal handler's list of temporaries is shared by both writers.
    both("write_csv", lambda i: rlgtherm.write_csv(trace, os.path.join(tmp, f"out{i}.csv")))
    both("read_csv", lambda i: rlgtherm.read_csv(csv))
    coeffs = both("fit", lambda i: rlgtherm.fit(trace, model="poly", order=2))[0]
    run = trace[0]
    T = np.ascontiguousarray(run["T1"])

    def compensate(i):
        c = rlgtherm.Compensator(coeffs)
        return c.update_many(run.t_s, T, run["bias_dph"]), c.compensate_run(run)

    both("Compensator", compensate)
    both("evaluate", lambda i: rlgtherm.evaluate(run, run["bias_dph"], coefficients=coeffs))
    both("population_gyros", lambda i: rlgtherm.population_gyros(SMALL, 2 * i, 2, threads=2))

    def eq2py(calibration):  # your own compensator, called back from the library's threads
        return rlgtherm.Compensator(rlgtherm.fit(calibration, pair=("T1", "T2"))).compensate_run

    with warnings.catch_warnings():  # the +40 °C run lies beyond the fitted range
        warnings.simplefilter("ignore", UserWarning)
        both("population_gyros(compensator=)",
             lambda i: rlgtherm.population_gyros(SMALL, 2 * i, 2, threads=2, compensator=eq2py))
    return 0


if __name__ == "__main__":
    sys.exit(main())
