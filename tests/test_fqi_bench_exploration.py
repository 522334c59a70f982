"""benchmarks/bench_exploration.py: the episodes of FQI's first round, one-step and held."""
import json

from benchmarks import bench_exploration


def test_counts_the_first_rounds_episodes_and_holds_shorten_cartpoles():
    one_step = bench_exploration.random_play("CartPole-v1", None, 40, 4, seed=0)
    held = bench_exploration.random_play("CartPole-v1", 1.5, 40, 4, seed=0)
    for row in (one_step, held):
        # every CartPole episode of random play falls (terminates) well before 500 steps,
        # and its return is its length (a reward of 1 per step)
        assert row["episodes"] == row["terminated"] == 40
        assert row["mean_return"] == row["mean_length"] < 100
    # a held push topples the pole sooner than alternating random pushes
    assert held["mean_length"] < one_step["mean_length"]
    assert bench_exploration.random_play("CartPole-v1", None, 40, 4, seed=0) == one_step


def test_main_prints_and_writes_json(tmp_path, capsys):
    bench_exploration.main(["--env", "CartPole-v1", "--zeta", "2", "--episodes", "5",
                            "--n-envs", "2", "--out", str(tmp_path)])
    rows = json.loads((tmp_path / "bench_exploration.json").read_text())["rows"]
    assert [row["zeta"] for row in rows] == [None, 2.0]
    out = capsys.readouterr().out
    assert "one-step" in out and "held, zeta 2" in out and "5 of 5" in out
