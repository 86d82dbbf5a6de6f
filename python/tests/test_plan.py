"""Calibration plans from Python (docs/plan.md, docs/python.md): plan is `rlgtherm plan --json`;
plan_gyros shards merged by plan_merge, in any order and on Dask, give the same dict."""
import json

import pytest

import rlgtherm
from conftest import SOURCE, cli

PLAN = str(SOURCE / "tests/data/plan/population.toml")  # 16 gyros, two candidates, 5 s samples


def plan_json():
    # Exit 4: no candidate meets this plan's target (docs/cli.md); the JSON is printed all the same.
    out, _ = cli("plan", PLAN, "--json", status=4)
    return json.loads(out)


@pytest.fixture(scope="module")
def whole():
    return rlgtherm.plan(PLAN)


def test_plan_is_the_cli_json(whole):
    assert whole == plan_json()
    assert rlgtherm.plan_count(PLAN) == 16


def test_shards_in_any_order_merge_to_the_whole_plan(whole):
    shards = [rlgtherm.plan_gyros(PLAN, f, n) for f, n in [(0, 5), (5, 5), (10, 6)]]
    assert rlgtherm.plan_merge(PLAN, shards[::-1]) == whole
    assert shards[1] == plan_json_shard("5:10")


def plan_json_shard(gyros):
    out, _ = cli("plan", PLAN, "--gyros", gyros)
    return json.loads(out)


def test_a_gyro_in_two_shards_or_none_is_a_value_error():
    a = rlgtherm.plan_gyros(PLAN, 0, 10)
    with pytest.raises(ValueError, match="shard"):
        rlgtherm.plan_merge(PLAN, [a, a])
    with pytest.raises(ValueError):
        rlgtherm.plan_merge(PLAN, [a])
    with pytest.raises(ValueError, match="expected a range within 0 .. 15"):
        rlgtherm.plan_gyros(PLAN, 10, 7)


def test_a_dask_cluster_of_two_worker_processes_gives_the_same_answer(whole, dask_client):
    import rlgtherm_dask
    assert rlgtherm_dask.run_plan(PLAN, dask_client, shard_size=6) == whole  # shards of 6, 6, 4
