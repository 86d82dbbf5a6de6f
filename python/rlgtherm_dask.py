"""A population suite or a calibration plan on Dask: gyro shards mapped over workers, reduced by
rlgtherm.

    import rlgtherm_dask
    summary = rlgtherm_dask.run_population("scenarios/paper-population.toml")          # this machine
    summary = rlgtherm_dask.run_population(suite, client=Client("tcp://scheduler:8786"))  # a cluster
    answer = rlgtherm_dask.run_plan("scenarios/plan-default.toml", client)              # `plan --json`

Each task is `rlgtherm.population_gyros(suite, first, count, threads)` on one shard of gyros
(with your compensator=, when given, which travels to the workers pickled); the last task is
`rlgtherm.population_summary(suite, shards)`, the dict of `rlgtherm validate SUITE --json`, identical to the one-machine run for any shard size, worker count or order (the C++
summary does not depend on the order gyros arrive in; gyro i's seed comes from the suite seed
and i). The same for a plan: tasks `rlgtherm.plan_gyros(plan, first, count,
threads)`, then `rlgtherm.plan_merge(plan, shards)`, the dict of `rlgtherm plan PLAN --json`.
No science here: this module only splits and schedules.

On a cluster, every worker imports rlgtherm and this module (install both with `cmake --install
build --component python`, or put build/python on the workers' PYTHONPATH) and reads the suite
file and the scenario and gyro files it names **at the same path as the client** (a shared file
system, or the repository checked out at the same place): only the path travels with a task.
"""
import dask
import rlgtherm

#: Gyros per task. Each task builds its suite, which runs gyro 0 once (0.5 % more work at 200);
#: a gyro of scenarios/paper-population.toml costs 13 CPU-ms (docs/python.md), so a task is ~3 s:
#: long beside Dask's per-task overhead (~1 ms), short enough to balance hundreds of workers.
DEFAULT_SHARD_SIZE = 200


def shards(count, shard_size=DEFAULT_SHARD_SIZE, first=0):
    """(first, count) of each shard of gyros first .. first + count - 1, shard_size at most."""
    if shard_size < 1:
        raise ValueError(f"shard_size {shard_size}: expected 1 or more gyros")
    return [(f, min(shard_size, first + count - f)) for f in range(first, first + count, shard_size)]


def _gyros(suite, first, count, threads, seed, compensator):
    # A module-level function: a worker unpickles it by name, importing rlgtherm there. A worker
    # exists to run gyros, so it keeps freed memory for the next one (rlgtherm.keep_freed_memory:
    # less than half the CPU per gyro; idempotent).
    rlgtherm.keep_freed_memory()
    return rlgtherm.population_gyros(suite, first, count, threads, seed=seed, compensator=compensator)


def _summary(suite, parts, seed, compensator):
    return rlgtherm.population_summary(suite, parts, seed=seed, compensator=compensator)


def _named(compensator):
    """compensator= as (name, fit), so that its name is fixed on the client: the summary task gets
    the name alone, and each shard task the fit (pickled by Dask: a function of an importable
    module by reference, one defined in a script or a notebook by value)."""
    if compensator is None or isinstance(compensator, tuple):
        return compensator
    name = getattr(compensator, "__name__", None)
    if not isinstance(name, str):
        raise ValueError("compensator: this callable has no __name__ to name its rows by: give (name, fit)")
    return (name, compensator)


def _computed(graph, client):
    """graph computed on `client` when given, else on Dask's current scheduler."""
    return client.compute(graph).result() if client is not None else graph.compute()


def population_delayed(suite, shard_size=DEFAULT_SHARD_SIZE, *, first=0, count=None, threads=1, seed=None,
                       compensator=None):
    """The summary of gyros first .. first + count - 1 (count None: to the end) as a
    dask.delayed object: one task per shard, then the summary task. `.compute()` runs it on
    the current scheduler (a distributed Client once one is made, else local threads);
    `client.compute(...)` on a given client. threads: C++ threads per task (the GIL is released,
    so Dask worker threads also run shards side by side). compensator: your own, as
    rlgtherm.population_gyros takes it (fit, or (name, fit)), run on the workers per gyro."""
    suite = str(suite)
    if count is None:
        count = rlgtherm.population_count(suite) - first
    named = _named(compensator)
    parts = [dask.delayed(_gyros)(suite, f, n, threads, seed, named) for f, n in shards(count, shard_size, first)]
    return dask.delayed(_summary)(suite, parts, seed, named[0] if named else None)


def run_population(suite, client=None, shard_size=DEFAULT_SHARD_SIZE, **options):
    """population_delayed(suite, shard_size, **options), computed: on `client`
    (distributed.Client) when given, else on Dask's current scheduler. Returns the dict of
    `rlgtherm validate SUITE --json`."""
    return _computed(population_delayed(suite, shard_size, **options), client)


#: Gyros per plan task. A gyro of scenarios/plan-default.toml goes through 16 simulated candidates
#: in about 50 CPU-ms (docs/performance.md), so a task is ~1 s; each task also screens the plan's
#: candidates (milliseconds).
DEFAULT_PLAN_SHARD_SIZE = 20


def _plan_gyros(plan, first, count, threads):
    rlgtherm.keep_freed_memory()
    return rlgtherm.plan_gyros(plan, first, count, threads)


def _plan_merge(plan, parts, verify):
    return rlgtherm.plan_merge(plan, parts, verify=verify)


def plan_delayed(plan, shard_size=DEFAULT_PLAN_SHARD_SIZE, *, threads=1, verify=0):
    """A plan's answer (the dict of `rlgtherm plan PLAN --json [--verify N]`) as a dask.delayed
    object: one task per shard of gyros, then the merge (with the verification, on the merging
    worker). threads: C++ threads per task."""
    plan = str(plan)
    parts = [dask.delayed(_plan_gyros)(plan, f, n, threads) for f, n in shards(rlgtherm.plan_count(plan), shard_size)]
    return dask.delayed(_plan_merge)(plan, parts, verify)


def run_plan(plan, client=None, shard_size=DEFAULT_PLAN_SHARD_SIZE, **options):
    """plan_delayed(plan, shard_size, **options), computed on `client` when given, else on Dask's
    current scheduler: the dict of `rlgtherm plan PLAN --json`, the same for any shard size."""
    return _computed(plan_delayed(plan, shard_size, **options), client)
