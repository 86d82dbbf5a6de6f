#!/usr/bin/python3
"""The measured plan for a large population on Dask (docs/python.md, "Populations"): what one
gyro of a population suite costs, what a local Dask cluster delivers, and what 1,000,000 gyros
would take on N workers.

Run from the repository (after the build; ~1 minute on the default suite):
    PYTHONPATH=build/python /usr/bin/python3 python/examples/population_plan.py
    PYTHONPATH=build/python /usr/bin/python3 python/examples/population_plan.py SUITE --gyros 200 --workers 2

1. CPU per gyro: population_gyros(suite, 0, GYROS, threads=1) timed with time.process_time
   (one thread, so CPU time is the work; it includes the suite's gyro-0 run, as every Dask
   shard pays it).
2. Dask: the same gyros on a LocalCluster of WORKERS single-threaded worker processes
   (rlgtherm_dask.run_population, 2 shards per worker): wall time without the cluster's start,
   the workers' CPU time, and the summary compared with the one-process summary (they must be
   identical).
3. The plan: CPU per gyro x TARGET / (workers x efficiency), the efficiency being the share of
   the workers' CPU time that went into gyros (one-process CPU / workers' CPU: each shard's
   gyro 0, scheduling, transfers and the summary are the rest). It assumes one dedicated core
   per worker; on a busy machine wall times stretch, CPU times do not.
"""
import argparse
import math
import os
import time
from pathlib import Path

import rlgtherm
import rlgtherm_dask
from distributed import Client, LocalCluster

REPO = Path(__file__).resolve().parents[2]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("suite", nargs="?", default=str(REPO / "scenarios/paper-population.toml"))
    parser.add_argument("--gyros", type=int, default=200, help="gyros measured (default 200)")
    parser.add_argument("--workers", type=int, default=2, help="local Dask worker processes (default 2)")
    parser.add_argument("--target", type=int, default=1_000_000, help="population planned (default 1,000,000)")
    a = parser.parse_args()

    # 1. One process, one thread, keeping freed memory as the CLI and the Dask shards do.
    rlgtherm.keep_freed_memory()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    shard = rlgtherm.population_gyros(a.suite, 0, a.gyros, threads=1)
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    per_gyro = cpu / a.gyros
    t0 = time.perf_counter()
    reference = rlgtherm.population_summary(a.suite, [shard])
    summary_s = time.perf_counter() - t0
    shard_bytes = sum(v.nbytes for v in shard.values() if hasattr(v, "nbytes")) / a.gyros
    print(f"suite {a.suite}: {rlgtherm.population_count(a.suite)} gyros, {shard['metrics'].shape[1]} metrics, "
          f"{shard['check_passed'].shape[1]} checks, {shard['parameters'].shape[1]} spread parameters")
    print(f"one process, 1 thread: {a.gyros} gyros in {cpu:.2f} CPU-s ({wall:.2f} s wall): "
          f"{1e3 * per_gyro:.1f} CPU-ms per gyro; summary {summary_s:.2f} s; {shard_bytes:.0f} bytes per gyro in a shard")

    # 2. A local Dask cluster. Its worker processes are spawned afresh and find rlgtherm and
    # rlgtherm_dask on the PYTHONPATH they inherit.

    where = [str(Path(rlgtherm.__file__).parents[1]), str(Path(rlgtherm_dask.__file__).parent)]  # the package's parent
    os.environ["PYTHONPATH"] = os.pathsep.join([*where, os.environ.get("PYTHONPATH", "")])
    shard_size = math.ceil(a.gyros / (2 * a.workers))
    t0 = time.perf_counter()
    with LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=40) as cluster, Client(cluster) as client:
        start_s = time.perf_counter() - t0
        workers_cpu = client.run(time.process_time)
        t0 = time.perf_counter()
        summary = rlgtherm_dask.run_population(a.suite, client, shard_size, count=a.gyros)
        dask_s = time.perf_counter() - t0
        dask_cpu = sum(client.run(time.process_time).values()) - sum(workers_cpu.values())
    identical = summary == reference
    # Of the workers' CPU time, the share that simulated the gyros (the rest: each shard's gyro 0,
    # Dask's scheduling and transfers, the summary): what a cluster of dedicated cores achieves.
    # Above 100 % is the noise of CPU time on a shared machine (a few %): the plan takes 100 %.
    efficiency = cpu / dask_cpu
    print(f"Dask LocalCluster, {a.workers} worker processes x 1 thread (started in {start_s:.1f} s): {a.gyros} gyros "
          f"in shards of {shard_size} in {dask_s:.2f} s wall ({a.gyros / dask_s:.1f} gyros/s), {dask_cpu:.2f} "
          f"worker CPU-s: efficiency {100 * efficiency:.0f} %; summary identical to one process: {identical}")
    print(f"load average while measuring: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores (wall times count "
          "other work on the machine; CPU times do not)")

    # 3. The plan.
    efficiency = min(efficiency, 1.0)
    print(f"\nplan for {a.target:,} gyros: {per_gyro:.4f} CPU-s per gyro x {a.target:,} = "
          f"{per_gyro * a.target / 3600:,.1f} CPU-hours; wall = that / (workers x {100 * efficiency:.0f} %)")
    for workers in (a.workers, 64, 256, 1024):
        print(f"  {workers:5d} workers: {per_gyro * a.target / (workers * efficiency) / 3600:8.2f} h")
    print(f"  in {math.ceil(a.target / rlgtherm_dask.DEFAULT_SHARD_SIZE):,} tasks of "
          f"{rlgtherm_dask.DEFAULT_SHARD_SIZE} gyros ({per_gyro * rlgtherm_dask.DEFAULT_SHARD_SIZE:.0f} CPU-s each)")
    print(f"  shards reaching the summary task: {shard_bytes * a.target / 1e9:.2f} GB; the summary keeps "
          f"{8 * (shard['metrics'].shape[1] + 1) * a.target / 1e9:.2f} GB (a value per metric and gyro, and each gyro's id)")
    if not identical:
        raise SystemExit("the Dask summary differs from the one-process summary")


if __name__ == "__main__":  # Dask's worker processes are spawned: they import this file, and must not rerun it
    main()
