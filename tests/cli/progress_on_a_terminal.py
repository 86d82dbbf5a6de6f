#!/usr/bin/env python3
"""progress_on_a_terminal.py RLGTHERM PLAN.toml DATA.csv: `plan` and `compare`, which can run for
minutes, show their progress on stderr when it is a terminal, as simulate, validate and diagnose
do (docs/cli.md), one line rewritten in place and cleared at the end; on a pipe
stderr stays empty, and stdout is the same either way."""
import os
import pty
import subprocess
import sys

rlg, plan, data = sys.argv[1:4]


def run(args, tty):
    """(stdout, stderr) of rlgtherm ARGS with stderr on a pseudo-terminal or a pipe."""
    if not tty:
        p = subprocess.run([rlg, *args], capture_output=True, text=True, check=True)
        return p.stdout, p.stderr
    master, slave = pty.openpty()
    p = subprocess.Popen([rlg, *args], stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    err = b""
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # EIO: the child closed the terminal
            break
        if not chunk:
            break
        err += chunk
    out = p.stdout.read().decode()
    assert p.wait() == 0, f"rlgtherm {args}: exit {p.returncode}"
    os.close(master)
    return out, err.decode()


problems = []
for args, expect in ((["plan", plan, "--threads", "2"], "plan: gyro 64 of 64"),
                     (["compare", data], "compare: fitting ")):
    out_tty, err_tty = run(args, True)
    out_pipe, err_pipe = run(args, False)
    print(f"{args[0]}: terminal stderr {err_tty[-80:]!r}")
    if expect not in err_tty:
        problems.append(f"{args[0]}: no '{expect}' on a terminal: {err_tty[-300:]!r}")
    if not err_tty.endswith("\r\x1b[K"):
        problems.append(f"{args[0]}: the progress line is not cleared at the end: {err_tty[-80:]!r}")
    if err_pipe:
        problems.append(f"{args[0]}: progress on a pipe: {err_pipe[:200]!r}")
    if out_tty != out_pipe:
        problems.append(f"{args[0]}: stdout differs with stderr on a terminal")
if problems:
    sys.exit("progress_on_a_terminal: " + "\n".join(problems))
print("progress_on_a_terminal: plan and compare show progress on a terminal only")
