"""benchmarks/bench_control.py end to end at a tiny budget: every agent's run, the JSON and
the PNG, and the MushroomRL peer when it is installed."""
import json

import pytest

from benchmarks import bench_control


def test_tiny_run_writes_json_and_png_and_resumes(tmp_path, capsys, monkeypatch):
    argv = ["--envs", "CartPole-v1", "--seeds", "0", "--steps", "400", "--eval-every", "200",
            "--no-peer", "--out", str(tmp_path)]
    bench_control.main(argv)
    report = json.loads((tmp_path / "bench_control.json").read_text())
    assert (tmp_path / "bench_control.png").stat().st_size > 0
    assert {r["agent"] for r in report["runs"]} == set(bench_control.AGENTS)
    for run in report["runs"]:
        assert run["env_steps"] >= 400 and [s for s, _ in run["curve"]][0] >= 200
        assert run["curve"][-1][0] == run["env_steps"] and run["steps_to_threshold"] is None
        assert run["train_seconds"] > 0 and run["eval_seconds"] > 0
        assert run["train_cpu_seconds"] > 0
    assert "| CartPole-v1 | fqi-box |" in report["markdown"] in capsys.readouterr().out
    # a rerun with the same arguments reuses the finished runs instead of training again
    monkeypatch.setattr(bench_control, "run", lambda *args: pytest.fail("retrained"))
    bench_control.main(argv)
    assert json.loads((tmp_path / "bench_control.json").read_text())["runs"] == report["runs"]


def test_bad_arguments(capsys):
    with pytest.raises(SystemExit):
        bench_control.main(["--steps", "0"])
    assert "--steps must be >= 1" in capsys.readouterr().err


def test_mushroom_peer_when_installed(monkeypatch):
    pytest.importorskip("mushroom_rl")
    monkeypatch.setattr(bench_control, "PEER_ITERATIONS", 3)
    peer = bench_control.run_peer(seed=0, samples=300)
    assert peer["iterations"] == 3
    assert peer["mushroom_mean"] > 0 and peer["ours_mean"] > 0
    assert peer["mushroom_seconds_per_iteration"] > 0 and peer["ours_seconds_per_iteration"] > 0
