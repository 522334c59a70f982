"""The unit kinds: typed settings, a kind in one class, the attention figure's tests, the
baselines' searches, the PPO run on the objects and the reference policies."""
import json
from dataclasses import replace

import numpy as np
import pytest

import envs
from benchmarks.reproduce import BUDGETS, EXPERIMENTS, REGISTRY, Experiment, plots, runner
from benchmarks.reproduce.cache import load_unit, save_unit, unit_path
from benchmarks.reproduce.cli import main
from benchmarks.reproduce.kinds import KINDS, UnitKind
from benchmarks.reproduce.registry import resolve
from benchmarks.reproduce.runner import setting_units
from benchmarks.reproduce.units import Unit, run_unit

from harness import TINY


def test_a_test_effect_is_the_right_child_minus_the_left():
    from benchmarks.reproduce.kinds.attention import tree_tests
    from boxtrees import BoxExtraTreesRegressor

    rng = np.random.default_rng(0)
    X = [np.column_stack([rng.uniform(-3, 3, (4, 2)), rng.integers(0, 2, 4)]) for _ in range(300)]
    # more objects of type 0 near the origin: a higher target (they attract)
    y = [float(((np.abs(s[:, :2]).max(1) < 1) & (s[:, 2] == 0)).sum()) for s in X]
    tree = BoxExtraTreesRegressor(1, n_tests=50, min_samples_split=10,
                                  random_state=0).fit(X, y)[0].tree_
    rows = tree_tests(tree)
    root = rows[0]
    assert root[8] == tree.value[tree.children_right[0]] - tree.value[tree.children_left[0]]
    assert root[4] == 0 and root[8] > 0


def test_baseline_searches_run_when_named_with_their_own_seeds_and_curves(tmp_path):
    report = main(["--budget", "tiny", "--only", "search_dqn_grid,search_dqn_objects",
                   "--out", str(tmp_path), "--no-progress"])
    search = REGISTRY["search_dqn_objects"]
    assert len(search.settings) == 8 and search.seeds == 2
    # its own 2 seeds at the full and quick budgets, at most the budget's (1 at tiny)
    assert runner.seeds_for(search, BUDGETS["full"]) == runner.seeds_for(
        search, BUDGETS["quick"]) == [0, 1]
    assert runner.seeds_for(search, TINY) == [0]
    assert runner.seeds_for(REGISTRY["rmse_K_datasets"], BUDGETS["full"]) == list(range(5))
    for name in ("search_dqn_grid", "search_dqn_objects"):
        for label in REGISTRY[name].settings:
            for seed in runner.seeds_for(REGISTRY[name], TINY):
                result = json.loads(unit_path(tmp_path, TINY, name, label, seed).read_text())["result"]
                steps = [s for s, _ in result["curve"]]
                assert len(steps) == 4 and steps == sorted(steps)
                assert result["curve"][-1] == [result["total_timesteps"], result["reward"]]
        assert f'<a id="{name}"></a>' in report.read_text()
    assert '<a id="search_ppo_objects"></a>' not in report.read_text()


@pytest.mark.parametrize("normalize, gamma", [(False, 0.9), (True, 0.9), (True, None)])
def test_a_ppo_run_on_the_objects_with_attention(normalize, gamma, monkeypatch):
    import stable_baselines3
    from benchmarks import training
    from benchmarks.reproduce.units import run_unit
    from stable_baselines3.common import vec_env

    wrapped = []

    class OtherDefault(stable_baselines3.PPO):  # a discount default of its own
        def __init__(self, *args, gamma=0.95, **kwargs):
            super().__init__(*args, gamma=gamma, **kwargs)

    class Recorded(vec_env.VecNormalize):
        def __init__(self, venv, **kwargs):
            super().__init__(venv, **kwargs)
            wrapped.append((kwargs, self))

    monkeypatch.setattr(training, "VecNormalize", Recorded)
    monkeypatch.setitem(training.ALGORITHMS, "PPO", OtherDefault)
    params = {**REGISTRY["search_ppo_objects"].params("CartPole, gamma 0.9, attention"),
              "hyperparams": {"n_envs": 2, "n_steps": 32, "batch_size": 32, "n_epochs": 1,
                              "normalize": normalize, **({} if gamma is None else
                                                         {"gamma": gamma})},
              "step_scale": 1.0, "max_objects": 32}
    result = run_unit(Unit("search_ppo_objects", "CartPole, gamma 0.9, attention", 0, params,
                           TINY.samples, TINY, None))
    assert params["attention"] and result["total_timesteps"] >= TINY.dqn_steps
    assert len(result["curve"]) == 4 and np.isfinite(result["reward"])
    # rewards only, at the run's discount (the algorithm's default if not set); never the
    # padded observations
    assert [kwargs for kwargs, _ in wrapped] == (
        [{"norm_obs": False, "norm_reward": True, "gamma": gamma or 0.95}] if normalize
        else [])
    # and the model trained through it: its return statistics saw every step
    assert all(env.ret_rms.count >= TINY.dqn_steps for _, env in wrapped)


def test_the_set_encoders_arguments_pass_through_the_hyperparameters():
    pytest.importorskip("torch")
    from benchmarks.reproduce.kinds.sb3 import with_set_encoder
    from fqi import SetEncoder

    given = {"gamma": 0.9, "policy_kwargs": {"net_arch": [8],
                                             "features_extractor_kwargs": {"scale": [2, 3]}}}
    assert with_set_encoder(given, attention=True) == {
        "gamma": 0.9, "policy_kwargs": {
            "net_arch": [8], "features_extractor_class": SetEncoder,
            "features_extractor_kwargs": {"scale": [2, 3], "attention": True}}}
    assert with_set_encoder({})["policy_kwargs"]["features_extractor_kwargs"] == {
        "attention": False}


def test_reference_policies_score_on_the_reference_worlds_as_learners_do():
    from benchmarks.reproduce.units import run_unit
    from fqi import evaluate

    budget = replace(TINY, eval_steps=150)  # 3 reference worlds
    seeds = envs.reference_worlds(3)
    worlds = envs.BatchedObjectWorld(3)
    def unit(params):
        return Unit("ceiling", "reference", 0, {"kind": "policy", "env_id": "ObjectWorld-v0",
                                                **params}, TINY.samples, budget, None)

    greedy = run_unit(unit({"policy": "greedy"}))
    direct = evaluate(envs.GreedyPolicy(worlds), worlds, seeds=seeds)
    assert greedy["episode_returns"] == direct.returns.tolist()
    assert greedy["reward"] == direct.total * budget.reward_scale
    planner = run_unit(unit({"policy": "planner", "depth": 2, "width": 2}))
    rewards = [envs.LookaheadPlanner(depth=2, width=2).play(envs.ObjectWorldEnv(), seed=s)[1]
               for s in seeds]
    assert planner["episode_returns"] == [float(r.sum()) for r in rewards]
    assert planner["player"] == "LookaheadPlanner(depth=2, width=2, route_width=50, discount=0.95)"


@pytest.mark.parametrize("kind, params, match", [
    ("fqi", {"env_id": "ObjectWorld-v0", "model": "box", "test_type": "fixed",
             "n_estimators": 3, "n_tests": 5, "min_samples_split": 2, "n_test": 5},
     "fqi units take no parameter n_test"),
    ("fqi", {"env_id": "ObjectWorld-v0", "model": "box", "test_type": "fixed"},
     "a box model needs n_estimators, n_tests, min_samples_split"),
    ("rmse", {"env_id": "ObjectWorld-v0", "model": "tree"}, "model must be one of"),
    ("sb3", {"env_id": "ObjectWorld-v0", "algo": "A2C", "observation": "grid", "n_bins": 4},
     "algo must be 'DQN' or 'PPO'"),
    ("sb3", {"env_id": "ObjectWorld-v0", "algo": "DQN", "observation": "objects"},
     "observation 'objects' needs max_objects"),
    ("policy", {"env_id": "ObjectWorld-v0", "policy": "human"}, "policy must be one of"),
    ("dqn", {"n_bins": 4}, "missing 1 required positional argument: 'env_id'"),
    ("control", {"env_id": "CartPole-v1", "learner": "fqi", "steps": 10,
                 "fqi": {"epsilon": 0.1}}, "fqi takes no argument epsilon"),
    ("control", {"env_id": "CartPole-v1", "learner": "fqi", "steps": 10,
                 "fqi": {"seed": 1}}, "fqi takes no argument seed"),
    ("control", {"env_id": "CartPole-v1", "learner": "fqi", "steps": 10, "stop": 11},
     r"stop must be None or a whole number from 1 to steps \(10\), got 11"),
    ("control", {"env_id": "CartPole-v1", "learner": "DQN", "steps": 10, "stop": 0.5},
     "stop must be None or a whole number"),
    ("control", {"env_id": "CartPole-v1", "learner": "DQN", "steps": 10, "stop": 0},
     "stop must be None or a whole number from 1"),
    ("control", {"env_id": "CartPole-v1", "learner": "fqi", "steps": 10, "stop": True},
     "stop must be None or a whole number"),
])
def test_a_settings_mistake_is_named(kind, params, match):
    with pytest.raises(ValueError, match=match):
        KINDS[kind].settings({"kind": kind, **params})


def test_every_registry_setting_is_its_kinds_settings_at_every_budget():
    for experiment in EXPERIMENTS:
        for label in experiment.settings:
            owner, owner_label = resolve(experiment, label)
            for budget in BUDGETS.values():
                params = owner.params(owner_label, budget)
                settings = KINDS[params["kind"]].settings(params)
                assert settings.env_id == params["env_id"]


def test_a_kind_is_one_class_that_registers_itself(tmp_path):
    class Constant(UnitKind):
        name = "constant"
        budget_fields = ("eval_steps",)

        def run(self, unit, checkpoint=None):
            return {"reward": 7.0}

        def cost(self, unit):
            return 1.0

        def plot(self, experiment, stats, runs, budget):
            return plots.reward_bars(experiment, stats, budget)

    try:
        experiment = Experiment("constant", "extra", "A constant", "constant",
                                settings={"seven": {}})
        unit, = setting_units(experiment, "seven", TINY, tmp_path)
        assert unit.kind is KINDS["constant"] and runner.seeds_for(experiment, TINY) == [0]
        save_unit(unit, run_unit(unit))
        stats = KINDS["constant"].summarise("seven", [load_unit(unit)["result"]])
        assert stats.score == 7.0 and stats.n_runs == 1
    finally:
        del KINDS["constant"]


def test_a_stopped_control_run_ends_at_its_stop_on_the_schedule_of_its_steps(tmp_path):
    """``stop`` cuts the run short after the iteration whose collection reaches it (an SB3
    model: after the step); epsilon still decays over ``steps``, so a stopped FQI run is the
    start of the full one."""
    fqi = {"samples_per_iteration": 100, "n_envs": 1, "resample_every": 1,
           "exploration_fraction": 1.0, "exploration_final_eps": 0.0}
    common = {"env_id": "CartPole-v1", "learner": "fqi", "steps": 1000,
              "regressor": "extra-trees", "fqi": fqi, "eval_every": 100, "eval_episodes": 2}
    experiment = Experiment("stopped", "extra", "Stopped", "control", on_demand=True,
                            settings={"full": common, "stopped": {**common, "stop": 300},
                                      "DQN stopped": {**common, "learner": "DQN", "stop": 300,
                                                      "hyperparams": {"learning_starts": 100}}})
    full_budget = replace(TINY, control_scale=1.0)
    results = {}
    for label in experiment.settings:
        unit, = setting_units(experiment, label, full_budget, tmp_path)
        results[label] = run_unit(unit)
    stopped, full = results["stopped"], results["full"]
    assert stopped["total_timesteps"] == 300 and full["total_timesteps"] == 1000
    assert [steps for steps, _ in stopped["curve"]] == [100, 200, 300]
    assert stopped["curve"] == full["curve"][:3]
    dqn = results["DQN stopped"]
    assert dqn["total_timesteps"] == 300 and [s for s, _ in dqn["curve"]] == [100, 200, 300]


def test_the_control_table_counts_a_run_that_never_reached_the_threshold_as_the_last():
    """The median of 5 runs, 2 never past: the third of the others; of 3, 2 never: never;
    without a threshold, no count and no median."""
    control = KINDS["control"]
    settings = {label: {"env_id": "CartPole-v1", "learner": "fqi", "steps": 10,
                        "threshold": threshold}
                for label, threshold in (("five", 475.0), ("three", 475.0), ("none", None))}
    experiment = Experiment("table", "extra", "Table", "control", on_demand=True,
                            settings=settings)
    crossings = {"five": [10, None, 30, None, 20], "three": [10, None, None],
                 "none": [None, None]}
    runs = {label: [{"result": {"steps_to_threshold": c, "reward": 1.0, "seconds": 60.0,
                                "train_seconds": 60.0,
                                "train_cpu_seconds": 60.0}} for c in values]
            for label, values in crossings.items()}
    stats = {label: control.summarise(label, [r["result"] for r in runs[label]])
             for label in runs}
    rows = {line.split(" | ")[0].lstrip("| "): line.split(" | ")[3:5]
            for line in control.table(experiment, stats, runs)[2:]}
    assert rows == {"five": ["3/5", "30"], "three": ["1/3", "never"], "none": ["-", "-"]}


def test_gymnasium_tasks_run_each_learner_and_report_its_steps_to_the_threshold(tmp_path):
    report = main(["--budget", "tiny", "--only", "control_cartpole", "--out", str(tmp_path),
                   "--no-progress"]).read_text()
    experiment = REGISTRY["control_cartpole"]
    for label in experiment.settings:
        result = json.loads(unit_path(tmp_path, TINY, "control_cartpole", label,
                                      0).read_text())["result"]
        steps = [s for s, _ in result["curve"]]
        assert steps == sorted(steps) and steps[-1] == result["total_timesteps"]
        assert result["curve"][-1][1] == result["reward"] and result["train_seconds"] > 0
        assert steps[-1] >= round(experiment.params(label)["steps"] * TINY.control_scale)
    assert "| FQI, Extra-Trees | 1 |" in report and "runs solved" in report
    assert (tmp_path / "extra_control_cartpole.png").stat().st_size > 5000
