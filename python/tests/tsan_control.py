"""The control of python.tsan_threads (ctest python.tsan_control, label tsan): a deliberate data
race in a library instrumented as the module is (tsan_racy.cpp), called from two Python threads
through ctypes with the GIL released, must be reported by the preloaded ThreadSanitizer. If it
were not (a runtime that did not start, a preload that did not take), python.tsan_threads would
pass without watching anything. `python3 tsan_control.py LIBRARY`."""
import ctypes
import sys
import threading

lib = ctypes.CDLL(sys.argv[1])
threads = [threading.Thread(target=lib.rlg_tsan_racy_bump) for _ in range(2)]
for t in threads:
    t.start()
for t in threads:
    t.join()
print("both threads done: no race reported")
