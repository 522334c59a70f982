"""benchmarks/bench_offline.py at a tiny size: the data sets, the FQI runs and the report;
the d3rlpy part where d3rlpy imports (it needs a venv of its own: gymnasium 1.0)."""
import json

import numpy as np
import pytest

from benchmarks import bench_offline


def episode_ends(data):
    return data["terminations"] | data["truncations"]


def test_collect_keeps_each_episode_in_order_and_ends_every_one():
    from fqi import RandomPolicy

    data, returns = bench_offline.collect(RandomPolicy("CartPole-v1", seed=0), 2_500, seed=0,
                                          n_envs=2)
    assert {key: len(value) for key, value in data.items()} == dict.fromkeys(
        bench_offline.KEYS, 2_500)
    ends = episode_ends(data)
    assert ends[-1] and ends[1_249]  # each of the 2 envs' rows closes its last episode
    # within an episode each row starts where the previous one went
    inside = ~ends[:-1]
    assert np.array_equal(data["next_observations"][:-1][inside], data["observations"][1:][inside])
    # after an end comes a reset: CartPole starts within 0.05 of upright and still
    assert np.abs(data["observations"][1:][ends[:-1]]).max() <= 0.05
    assert data["rewards"].sum() == 2_500 and 10 < returns.mean() < 40  # the random policy
    again, _ = bench_offline.collect(RandomPolicy("CartPole-v1", seed=0), 2_500, seed=0,
                                     n_envs=2)
    assert again["observations"].tobytes() == data["observations"].tobytes()  # seeded


def test_data_and_fqi_parts_then_the_report(tmp_path, monkeypatch, capsys):
    argv = ["--quick", "--out", str(tmp_path / "out"), "--data", str(tmp_path / "data")]
    bench_offline.main([*argv, "--parts", "data", "fqi"])
    info = json.loads((tmp_path / "data" / "info.json").read_text())
    random, medium = (info["datasets"][name] for name in bench_offline.DATASETS)
    assert random["transitions"] == medium["transitions"] == bench_offline.QUICK["transitions"]
    assert random["behaviour_mean_return"] < 30 < medium["behaviour_mean_return"]
    for name in bench_offline.DATASETS:
        data = bench_offline.load_dataset(tmp_path / "data", name)
        assert bench_offline.data_digest(data) == info["datasets"][name]["sha256"]
    runs = {(r["dataset"], r["method"]): r for r in (
        json.loads(path.read_text()) for path in (tmp_path / "out" / "runs").glob("*.json"))}
    assert set(runs) == {(name, method) for name in bench_offline.DATASETS
                         for method in bench_offline.FQI_METHODS}
    for run in runs.values():
        assert run["budget"] == {"iterations": bench_offline.QUICK["iterations"]}
        assert run["train_seconds"] > 0 and 8 <= run["mean_return"] <= 500
    # three backups on a thousand random transitions already beat the random policy
    for method in bench_offline.FQI_METHODS:
        assert runs["random", method]["mean_return"] > 1.5 * random["behaviour_mean_return"]
    # a rerun reuses the finished runs and the data
    monkeypatch.setattr(bench_offline, "run_fqi", lambda *a: pytest.fail("retrained"))
    monkeypatch.setattr(bench_offline, "collect", lambda *a, **k: pytest.fail("recollected"))
    bench_offline.main([*argv, "--parts", "data", "fqi", "report"])
    report = json.loads((tmp_path / "out" / "bench_offline.json").read_text())
    assert len(report["summary"]) == 4 and (tmp_path / "out" / "bench_offline.png").stat().st_size
    assert "| fqi-grown | 3 iterations |" in report["markdown"] in capsys.readouterr().out


@pytest.mark.filterwarnings("ignore:`torch.jit.script` is deprecated:DeprecationWarning")
def test_the_report_plays_a_saved_torchscript_policy(tmp_path):
    """The d3rlpy part leaves TorchScript policies to be played here: a hand-made one, the
    pole's angle plus its angular velocity, is scored as d3rlpy's would be."""
    torch = pytest.importorskip("torch")
    args = bench_offline.parse_args(["--quick", "--out", str(tmp_path / "out"),
                                     "--data", str(tmp_path / "data")])
    (args.data / "policies").mkdir(parents=True)
    (args.data / "info.json").write_text(json.dumps({
        "settings": {"transitions": args.transitions},
        "datasets": {name: {"behaviour_mean_return": 20.0, "sha256": name}
                     for name in bench_offline.DATASETS}}))

    class Lean(torch.nn.Module):
        def forward(self, x):
            return (x[:, 2] + x[:, 3] > 0).long()

    torch.jit.script(Lean()).save(str(args.data / "policies" / "lean.pt"))
    key = bench_offline.run_key("medium", "d3rlpy-dqn", 0, args.gradient_steps, args.transitions)
    (args.out / "runs").mkdir(parents=True)
    (args.out / "runs" / f"{key}.json").write_text(json.dumps({
        "dataset": "medium", "method": "d3rlpy-dqn", "seed": 0, "data_sha256": "medium",
        "budget": {"gradient_steps": args.gradient_steps}, "train_seconds": 1.0,
        "train_cpu_seconds": 1.0, "mean_return": None, "policy": "lean.pt"}))
    bench_offline.report_part(args)
    run = json.loads((args.out / "runs" / f"{key}.json").read_text())
    assert run["mean_return"] > 100  # played and written back
    assert "| d3rlpy-dqn | 200 gradient steps | - | - |" in json.loads(
        (args.out / "bench_offline.json").read_text())["markdown"]


def test_the_d3rlpy_part_says_how_to_get_d3rlpy(tmp_path):
    try:
        import d3rlpy  # noqa: F401
    except ImportError:
        pass
    else:
        pytest.skip("d3rlpy is installed here")
    with pytest.raises(SystemExit, match="d3rlpy-python"):
        bench_offline.main(["--quick", "--parts", "d3rlpy", "--out", str(tmp_path)])


def synthetic_episodes(rng):
    """Episode-ordered transitions: a terminated episode, a truncated one, a terminated one."""
    parts = []
    for length, terminated in ((5, True), (4, False), (3, True)):
        observations = rng.normal(size=(length + 1, 4)).astype(np.float32)
        ends = np.zeros(length, dtype=bool)
        ends[-1] = True
        parts.append({"observations": observations[:-1], "next_observations": observations[1:],
                      "actions": rng.integers(2, size=length), "rewards": np.ones(length),
                      "terminations": ends & terminated, "truncations": ends & ~terminated})
    return {key: np.concatenate([p[key] for p in parts]) for key in bench_offline.KEYS}


def test_d3rlpy_learns_from_the_same_transitions(tmp_path):
    pytest.importorskip("d3rlpy")
    data = synthetic_episodes(np.random.default_rng(0))
    dataset = bench_offline.mdp_dataset(data)
    assert dataset.transition_count == len(data["actions"]) == 12
    picked = [dataset.transition_picker(episode, i) for episode in dataset.episodes
              for i in range(episode.transition_count)]
    assert np.array_equal([t.observation for t in picked], data["observations"])
    assert np.array_equal([t.action[0] for t in picked], data["actions"])
    terminal = np.array([t.terminal for t in picked], dtype=bool)
    assert np.array_equal(terminal, data["terminations"])
    assert np.array_equal(np.array([t.next_observation for t in picked])[~terminal],
                          data["next_observations"][~terminal])
    record = bench_offline.run_d3rlpy(data, "d3rlpy-cql", 0, 20, tmp_path / "cql.pt")
    assert record["transitions_seen"] == 12 and record["train_seconds"] > 0
    assert (tmp_path / "cql.pt").stat().st_size > 0
