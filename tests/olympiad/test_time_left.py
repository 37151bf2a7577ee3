"""The time a plan's unfinished cells take (roto.olympiad.time_left)."""

import pytest

from roto.olympiad.time_left import (
    busiest_worker_load,
    cell_seconds,
    rate_sources,
    recent_rate,
    task_throughputs,
    throughput,
)


def test_the_busiest_worker_takes_whole_cells_largest_first():
    assert busiest_worker_load([5, 5, 5], 2) == 10  # cells are never split
    assert busiest_worker_load([7, 4, 3, 3], 2) == 10  # largest first: 7+3 and 4+3
    assert busiest_worker_load([4], 3) == 4
    assert busiest_worker_load([], 2) == 0


def test_a_running_cells_rate_is_taken_between_its_last_two_evaluations():
    records = [{"env_steps": 1000, "train_wall_s": 10.0}, {"env_steps": 4000, "train_wall_s": 12.0}]
    assert recent_rate(records) == 1500.0
    assert recent_rate(records[:1]) is None and recent_rate([{"env_steps": 1}, {"env_steps": 2}]) is None


def test_each_task_runs_at_its_own_finished_cells_throughput():
    summaries = [
        {"task": "bounce", "env_steps": 5_000_000, "train_wall_s": 1000.0},
        {"task": "bounce", "env_steps": 5_000_000, "train_wall_s": 3000.0},  # all steps over all seconds: 2500
        {"task": "baoding", "env_steps": 10_000_000, "train_wall_s": 5000.0},
    ]
    rates = task_throughputs(summaries)
    assert rates == {"bounce": 2500.0, "baoding": 2000.0}
    assert throughput(summaries) == pytest.approx(20_000_000 / 9000.0)  # every task's steps over every second
    assert throughput([]) == 0.0 and task_throughputs([]) == {}
    task_of = {"a": "bounce", "b": "baoding", "c": "juggle"}
    seconds = cell_seconds({"a": 5_000_000, "b": 1_000_000, "c": 300}, task_of, rates, fallback=100.0)
    assert seconds == pytest.approx({"a": 2000.0, "b": 500.0, "c": 3.0})  # juggle has no cell: the fallback
    line = rate_sources(rates, ["bounce", "juggle", "bounce"], 100.0, "all the finished cells' throughput")
    assert line == (
        "bounce 2500, juggle 100 env steps/s (the finished cells' throughput per task; "
        "juggle at all the finished cells' throughput)"
    )
    assert rate_sources({}, ["bounce"], 42.0, "the started cells' last evaluation rounds") == (
        "bounce 42 env steps/s (the started cells' last evaluation rounds)"
    )
