"""benchmarks/bench_acrobot.py at a tiny size: its curves, first crossings and the registry's
DQN figures it reads beside them."""
import json

from benchmarks import bench_acrobot
from benchmarks.reproduce.stats import median_steps, steps_to_threshold


def test_first_crossing_and_median_count_a_run_that_never_crosses_as_last():
    curve = [[5000, -300.0], [10000, -100.0], [15000, -90.0]]
    assert steps_to_threshold(curve, -100.0) == 10000
    assert steps_to_threshold(curve[:1], -100.0) is None
    assert steps_to_threshold(curve, None) is None
    assert median_steps([15004, None, 25015, None, 20010]) == 25015
    assert median_steps([None, None, 5000]) is None and median_steps([]) is None
    # an even count: the mean of the middle two, never reached if either is
    assert median_steps([10000, 20000, 30000, None]) == 25000
    assert median_steps([10000, 20000, None, None]) is None


def test_a_tiny_run_writes_its_curve_beside_the_cached_dqn_runs(tmp_path):
    dqn = tmp_path / "results" / bench_acrobot.DQN_RUNS
    dqn.mkdir(parents=True)
    for seed, curve in enumerate([[[25000, -120.0], [30000, -95.0]], [[5000, -500.0]],
                                  [[20000, -90.0]]]):
        result = {"curve": curve, "steps_to_threshold": steps_to_threshold(curve, -100.0)}
        (dqn / f"seed{seed}.json").write_text(json.dumps({"result": result}))
    summary = bench_acrobot.main(["--seeds", "0", "--trees", "3", "--stop", "1000",
                                  "--jobs", "1", "--results", str(tmp_path / "results"),
                                  "--out", str(tmp_path / "out")])
    assert summary["dqn_first_crossing"] == {0: 30000, 1: None, 2: 20000}
    assert summary["dqn_median"] == 30000  # the run that never crossed counts as the last
    (run,) = summary["runs"]
    assert summary["fqi_median"] == run["first_crossing"]
    # one round of 2,500 steps, then the evaluation that ends training
    assert [steps for steps, _ in run["curve"]] == [2500]
    assert -500 <= run["curve"][0][1] <= 0 and run["train_seconds"] > 0
    assert run["first_crossing"] == steps_to_threshold(run["curve"], -100.0)
    written = json.loads((tmp_path / "out" / "bench_acrobot.json").read_text())
    assert written["runs"][0]["curve"] == run["curve"] and written["action_input"] is True
    assert (tmp_path / "out" / "bench_acrobot.png").stat().st_size > 0
