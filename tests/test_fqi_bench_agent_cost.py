"""benchmarks/bench_agent_cost.py at a tiny size: its rows are the runs it times, and no
run starts a thread per step."""
import json

import pytest

from benchmarks import bench_agent_cost


def test_the_quick_run_writes_its_rows(tmp_path, monkeypatch):
    names = ["ExtraTrees n_jobs=2", "Ridge pipeline"]
    monkeypatch.setattr(bench_agent_cost, "REGRESSORS",
                        {name: bench_agent_cost.REGRESSORS[name] for name in names})
    monkeypatch.setattr(bench_agent_cost, "QUICK_STEPS", 600)
    monkeypatch.setattr(bench_agent_cost, "EVAL_EPISODES", 2)
    bench_agent_cost.main(["--quick", "--out", str(tmp_path)])
    report = json.loads((tmp_path / "bench_agent_cost.json").read_text())
    assert [(r["regressor"], r["evaluation"]) for r in report["rows"]] == [
        (name, evaluation) for name in names for evaluation in (False, True)]
    for row in report["rows"]:
        assert row["steps"] >= 600 and row["seconds"] > 0
        assert row["seconds_per_10k_steps"] == pytest.approx(
            row["seconds"] * 10_000 / row["steps"])
        assert (row["t_evaluate"] > 1e-3) == row["evaluation"]  # (no episode: microseconds)
    # 600 steps of 16 envs: about 40 predictions of the forest, more with the evaluation
    assert report["summary"]["max_threads_started"] <= 12
    assert report["solves"] == [] and (tmp_path / "bench_agent_cost.png").stat().st_size
