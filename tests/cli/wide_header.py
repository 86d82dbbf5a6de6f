#!/usr/bin/env python3
"""wide_header.py RLGTHERM DIR: data files with very wide headers are refused or read in linear
time and memory bounded by the file (sim/limits.h, kMaxColumns = 65,536 columns).

- a tidy CSV and a delimited log with 1,000,000 columns: refused (exit 2) naming the file, the
  line and the count, before any row is read;
- the same at the limit, 65,536 columns: read (exit 0), the CSV by `allan`, the log by `import
  columns`.

Each command must finish within LIMIT_CPU_S seconds of CPU time (user + system: what other jobs
on the cores do not inflate, as they do wall time) and LIMIT_MB of resident memory. These are
the readers' acceptance limits, not their speed: docs/performance.md ("Wide headers") has the
measured numbers, 0.03-0.6 s and 12-22 MB per command on a loaded machine; the sanitizer build
takes 2.0 CPU-s at the limit's 65,536 columns (1.97 s wall on an idle machine, 7.4 s wall beside
a CI run's other jobs). The limits leave a margin of 2.5 times or more in time over the sanitizer
build and 45 in memory, while a reader quadratic in the columns (17 s at 65,536 columns, 60 s
and more at 1,000,000) or one that reads a whole absurd header fails them."""
import os
import re
import subprocess
import sys
import time

LIMIT_CPU_S = 5.0  # CPU time per command (measured: 0.03-0.6 s, 2.0 s sanitized; see the docstring)
KILL_AFTER_S = 60.0  # wall time after which a command is killed: it has failed already
LIMIT_MB = 1024.0  # peak resident memory per command (measured: 12-22 MB)
MAX_COLUMNS = 65536  # sim/limits.h, kMaxColumns

rlg, out_dir = sys.argv[1], sys.argv[2]
os.makedirs(out_dir, exist_ok=True)
problems = []


def write(name, header, rows):
    path = os.path.join(out_dir, name)
    with open(path, "w") as f:
        f.write(header + "\n")
        for row in rows:
            f.write(row + "\n")
    return path


def run(what, args, status, regex):
    """Runs rlgtherm ARGS in a child of its own and checks its status, stderr, time and memory."""
    # ru_maxrss of RUSAGE_CHILDREN is the largest of the children waited for so far: each run is
    # measured in a fresh helper process, so it is this command's alone.
    # Its CPU time likewise (ru_utime + ru_stime of the children).
    probe = ("import resource, subprocess, sys\n"
             "try:\n"
             "    p = subprocess.run(sys.argv[2:], capture_output=True, text=True, timeout=float(sys.argv[1]))\n"
             "except subprocess.TimeoutExpired:\n"
             "    sys.exit(3)\n"
             "use = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
             "sys.stdout.write(f'{p.returncode} {use.ru_utime + use.ru_stime} {use.ru_maxrss / 1024.0}\\n' + p.stderr)\n")
    p = subprocess.run([sys.executable, "-c", probe, str(KILL_AFTER_S), rlg] + args, capture_output=True, text=True)
    if p.returncode != 0:
        problems.append(f"{what}: " + (f"still running after {KILL_AFTER_S:g} s, killed" if p.returncode == 3 else
                                       f"the probe failed: {p.stderr.strip()}"))
        return
    first, _, stderr = p.stdout.partition("\n")
    code, seconds, mb = first.split()
    code, seconds, mb = int(code), float(seconds), float(mb)
    print(f"{what}: exit {code}, {seconds:.2f} CPU-s, {mb:.0f} MB; stderr: {stderr.strip()[:300]}")
    if code != status:
        problems.append(f"{what}: exit status {code}, expected {status}")
    if not re.search(regex, stderr):
        problems.append(f"{what}: stderr does not match /{regex}/")
    if seconds > LIMIT_CPU_S:
        problems.append(f"{what}: took {seconds:.2f} CPU-s, more than {LIMIT_CPU_S:g}")
    if mb > LIMIT_MB:
        problems.append(f"{what}: took {mb:.0f} MB, more than {LIMIT_MB:g} MB")


def names(n, width=7):
    return ",".join(f"x{i:0{width}d}" for i in range(n))


def zeros(n):
    return ",".join(["0"] * n)


# A tidy CSV of 1,000,000 columns: refused at its header.
n = 1_000_000
csv = write("wide_1m.csv", "run,t_s,T1,bias_dph," + names(n), [f"a,{t},20,0.1," + zeros(n) for t in range(2)])
run("tidy CSV, 1,000,000 columns", ["allan", csv], 2,
    r"wide_1m\.csv:1: the header has more than the 65536 columns a data file may have")
# A delimited log of 1,000,000 columns: refused at its header.
log = write("wide_1m_log.csv", "time,temp,rate," + names(n), [f"{t},20,0.1," + zeros(n) for t in range(3)])
run("import columns, 1,000,000 columns", ["import", "columns", log, "--time", "time:s", "--temp", "temp", "--rate",
                                           "rate:dph", "-o", os.path.join(out_dir, "wide_1m_imported.csv")], 2,
    r"wide_1m_log\.csv:1: the header has more than the 65536 columns a data file may have")

# At the limit: read. 200 samples at 1 s are enough for an Allan deviation.
n = MAX_COLUMNS - 4
csv = write("wide_limit.csv", "run,t_s,T1,bias_dph," + names(n), [f"a,{t},20,{t % 7 * 0.01}," + zeros(n) for t in range(200)])
run("tidy CSV, 65,536 columns", ["allan", csv, "--json"], 0, r"ignoring extra columns: x0000000, .* and 65512 more")
n = MAX_COLUMNS - 3
log = write("wide_limit_log.csv", "time,temp,rate," + names(n), [f"{t},20,0.1," + zeros(n) for t in range(3)])
run("import columns, 65,536 columns", ["import", "columns", log, "--time", "time:s", "--temp", "temp", "--rate",
                                        "rate:dph", "-o", os.path.join(out_dir, "wide_limit_imported.csv")], 0, r"^$")

for p in problems:
    print("FAIL:", p)
if not problems:  # ~60 MB; kept for a look when something failed
    for name in os.listdir(out_dir):
        os.remove(os.path.join(out_dir, name))
sys.exit(1 if problems else 0)
