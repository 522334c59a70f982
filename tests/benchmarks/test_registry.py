"""The experiment registry: every thesis figure once, settings that resolve, rules on real
settings, budgets, and the registry settings the other benchmarks build on."""

import dataclasses

import numpy as np
import pytest

from benchmarks.reproduce import BUDGETS, EXPERIMENTS, REGISTRY
from benchmarks.reproduce.kinds import KINDS
from benchmarks.reproduce.registry import Experiment, resolve
from benchmarks.reproduce.runner import plan
from boxtrees import ObjectSets
from envs import ENEMY, GRASS, MONEY, WALL

from harness import TINY


# ------------------------------------------------------------------------------ registry
def test_registry_covers_every_thesis_figure_once():
    figures = [e.figure for e in EXPERIMENTS if e.figure != "extra"]
    assert sorted(figures) == sorted(["A.1", "A.2", "A.3", "A.4", "A.5", "3.1", "3.2", "3.3",
                                      "3.4", "3.5", "3.6", "3.8", "3.9", "3.10"])
    assert {e.name for e in EXPERIMENTS if e.figure == "extra" and not e.explains} == {
        "keep_data", "keep_data_horizon", "keep_data_size", "keep_data_trees",
        "keep_data_nmin", "fqi_region", "rmse_region", "fqi_frame", "keep_data_frame",
        "keep_data_boxes", "keep_data_tests", "dqn",
        "attention", "ceiling",
        "ceiling_sword",
        "baselines", "baselines_sword", "search_dqn_grid", "search_dqn_objects",
        "search_ppo_objects", "control_cartpole",
        "control_acrobot", "control_mountaincar", "control_lunarlander", "fqi_defaults",
        "games_pong", "games_freeway", "games_boxing", "games_highway", "search_games_boxing"}
    ablations = [e for e in EXPERIMENTS if e.explains]
    assert {name for e in ablations for name in e.explains} == {
        "rmse_K", "rmse_nmin", "rmse_TW", "rmse_grid", "fqi_grid", "representations",
        "fqi_TW", "sampling", "sword"}
    for ablation in ablations:
        assert ablation.figure == "extra" and ablation.hypothesis and ablation.findings
        assert all(REGISTRY[name].figure != "extra" for name in ablation.explains)
    assert {e.name for e in EXPERIMENTS if e.on_demand} == {
        "keep_data_horizon", "keep_data_size", "keep_data_trees", "keep_data_nmin",
        "fqi_region", "rmse_region", "fqi_frame", "keep_data_frame", "keep_data_boxes",
        "keep_data_tests", "baselines_sword",
        "search_dqn_grid",
        "search_dqn_objects",
        "search_ppo_objects", "control_cartpole",
        "control_acrobot", "control_mountaincar", "control_lunarlander", "fqi_defaults",
        "games_pong", "games_freeway", "games_boxing", "games_highway", "search_games_boxing"}
    assert len(REGISTRY) == len(EXPERIMENTS)


def _rule_labels(rule):
    labels = []
    for name in ("groups", "labels", "others"):
        value = getattr(rule, name, ())
        labels += [x for group in value for x in group] if name == "groups" else list(value)
    labels += [getattr(rule, name) for name in ("label", "stable", "reference")
               if hasattr(rule, name)]
    return labels


@pytest.mark.parametrize("experiment", EXPERIMENTS, ids=lambda e: e.name)
def test_every_setting_resolves_and_every_rule_names_real_settings(experiment):
    assert experiment.kind in KINDS  # and each setting is its kind's Settings (on import)
    for label in experiment.settings:
        owner, owner_label = resolve(experiment, label)
        params = owner.params(owner_label)
        # the thesis's game, but for gymnasium's own tasks and the real games
        assert params["env_id"].startswith("ObjectWorld") == (params["kind"] not in (
            "control", "games"))
        if params["kind"] == "sb3":
            assert "gamma" in params["hyperparams"]      # searched, never SB3's default
    for rule in experiment.findings:
        assert set(_rule_labels(rule)) <= set(experiment.settings), rule
    assert experiment.ceiling is None or experiment.ceiling in experiment.settings


def test_thesis_axes_and_budgets():
    assert list(REGISTRY["fqi_nmin"].settings) == ["n_min=10", "n_min=20", "n_min=30"]
    assert list(REGISTRY["rmse_grid"].settings) == ["N=5", "N=10", "N=16", "N=21"]
    assert REGISTRY["fqi_K"].params("K=50")["n_estimators"] == 15  # standard M
    assert REGISTRY["representations"].params("classic")["n_tests"] == 500  # tuned K
    assert REGISTRY["treasure"].params("global")["view"] == "global"
    full = BUDGETS["full"]
    assert (full.seeds, full.iterations, full.samples, full.eval_steps) == (5, 20, 20_000,
                                                                             20_000)
    sword = [u for u in plan([REGISTRY["sword"]], full, "out") if u.seed == 0]
    assert {u.samples for u in sword} == {40_000}


def test_same_as_settings_share_their_owners_units(tmp_path):
    units = plan([REGISTRY["representations"], REGISTRY["dqn"]], BUDGETS["full"], tmp_path)
    assert len(units) == 5 * 5 + 5  # DQN's FQI settings are the representations' runs
    assert len({u.path for u in units}) == len(units)
    owners = {(u.experiment, u.label) for u in plan([REGISTRY["dqn"]], TINY, tmp_path)}
    assert ("representations", "fixed TW=1") in owners


def test_circular_same_as_is_rejected():
    loop = Experiment("loop", "extra", "t", "fqi", settings={"a": {"same_as": "loop/a"}})
    REGISTRY["loop"] = loop
    try:
        with pytest.raises(ValueError, match="circular"):
            resolve(loop, "a")
    finally:
        del REGISTRY["loop"]


def test_bench_fqi_and_sweep_fqi_runs_are_registry_settings():
    """The thesis-scale benchmark and the sweeps build their agents from the registry."""
    from benchmarks import bench_fqi, sweep_fqi
    from benchmarks.reproduce.registry import REGISTRY

    for experiment, label, changes in [*bench_fqi.FQI_RUNS.values(), *sweep_fqi.REGIMES.values()]:
        params = REGISTRY[experiment].params(label)
        assert params["kind"] == "fqi" and set(changes) <= {"resample_every", "gamma"}
    assert sweep_fqi._params(sweep_fqi.REGIMES["offline"], 10)["resample_every"] is None
    assert sweep_fqi._params(sweep_fqi.REGIMES["keep"], 10)["n_estimators"] == 10


@pytest.mark.parametrize("name", ["full", "quick"])
def test_the_tuned_baselines_are_scored_once_per_fqi_iteration(name):
    baselines, budget = REGISTRY["baselines"], BUDGETS[name]
    own = [label for label, setting in baselines.settings.items() if "same_as" not in setting]
    assert len(own) == 3
    assert [baselines.params(label, budget)["checkpoints"] for label in own] == [
        budget.iterations] * 3


def test_an_ablations_game_constants_ridge_penalty_and_test_regions_reach_its_units():
    from benchmarks.reproduce.kinds._game import make_env, regressor

    def settings(experiment, label):
        return KINDS[experiment.kind].settings(experiment.params(label))

    rules = make_env(settings(REGISTRY["rmse_TW_reach"], "TW=2.5, reach 2")).unwrapped.rules
    assert (rules.contact_radius, rules.start_clearance) == (2.0, 2.0)
    assert make_env(settings(REGISTRY["rmse_TW"], "TW=2.5")).unwrapped.rules.contact_radius \
        == 0.6
    grid = settings(REGISTRY["fqi_grid_alpha"], "N=15, alpha=1000")
    ridge = regressor(grid, make_env(grid), TINY, 0)
    assert ridge[0].n_bins == 15 and ridge[-1].alpha == 1000.0
    other = regressor(settings(REGISTRY["fqi_grid"], "N=15"), make_env(grid), TINY, 0)
    assert other[-1].alpha == 1.0
    near = settings(REGISTRY["fqi_region"], "near (6)")
    assert regressor(near, make_env(near), TINY, 0).view_bounds == (-6.0, 6.0, -6.0, 6.0)
    whole = settings(*resolve(REGISTRY["fqi_region"], "whole view (10)"))
    assert regressor(whole, make_env(whole), TINY, 0).view_bounds == (-10.0, 10.0, -10.0, 10.0)
    with pytest.raises(ValueError, match="test_region"):
        dataclasses.replace(near, test_region=-1.0)
    # walls' tests near the agent, the other types' over the whole view
    walls = settings(REGISTRY["keep_data_frame"], "move frame, walls near (2)")
    view = (-10.0, 10.0, -10.0, 10.0)
    assert regressor(walls, make_env(walls), TINY, 0).view_bounds == {
        MONEY: view, WALL: 2.0, GRASS: view, ENEMY: view}
    for wrong in ({"type_regions": ((WALL, 0.0),)}, {"test_region": 4.0}):
        with pytest.raises(ValueError, match="type_regions"):
            dataclasses.replace(walls, **wrong)


def test_a_move_frame_agent_fits_one_forest_on_every_move_turned_up():
    from benchmarks.reproduce.kinds._game import make_agent
    from envs import in_move_frame

    experiment = REGISTRY["fqi_frame"]
    settings = KINDS["fqi"].settings(experiment.params("move frame"))
    agent = make_agent(settings, TINY, 0, 200)
    assert agent.action_input is in_move_frame
    agent.learn(n_iterations=1)
    # Q(s, a) is the one forest's value of s turned into a's frame
    sets = ObjectSets(np.float32([[1, 2, 0], [3, -4, 3], [-1, 0, 1]]), [0, 2, 3])
    q = agent.q_values(sets)
    (forest,) = agent.q_functions_
    for action in range(4):
        np.testing.assert_array_equal(
            q[:, action], forest.predict(in_move_frame(sets, np.full(2, action))))
    sword = dataclasses.replace(settings, env_id="ObjectWorldSword-v0")
    with pytest.raises(ValueError, match="move_frame needs the game of four moves"):
        make_agent(sword, TINY, 0, 200)


@pytest.mark.parametrize("label, final", [("move frame, walls near (2), gamma 0.9", 0.2),
                                          ("move frame, walls near (2), gamma 0.9, "
                                           "epsilon to 0.05", 0.05)])
def test_game_agents_explore_with_the_thesis_epsilon_or_fall_linearly_to_the_final(label, final):
    from benchmarks.reproduce.kinds._game import THESIS_EPSILON, make_agent

    settings = KINDS["fqi"].settings(REGISTRY["keep_data_frame"].params(label))
    agent = make_agent(settings, TINY, 0, 100)
    rates = []
    agent.learn(n_iterations=4, callback=lambda *_: rates.append(agent.exploration_rate))
    # the first round is random play (no Q-function yet) whatever the rate
    assert rates == pytest.approx([THESIS_EPSILON + (final - THESIS_EPSILON) * i / 4
                                   for i in range(4)])


def test_the_reference_worlds_are_seeds_fqi_never_trains_on():
    """The two packages cannot import each other; the harness joins them on one boundary."""
    import envs
    from fqi._envs import _TRAINING_SEED_END

    assert envs.REFERENCE_SEED_START == _TRAINING_SEED_END
    assert min(envs.reference_worlds(3)) == _TRAINING_SEED_END


def test_the_control_runs_measured_fqis_current_defaults():
    """Their cache keys hold ``"fqi": {}``: a change of FQI's defaults would reuse runs of
    the old ones. This fails first (then delete those runs and update the record)."""
    import inspect

    from benchmarks.reproduce.registry import FQI_DEFAULTS_MEASURED
    from fqi import FQI

    defaults = {name: parameter.default
                for name, parameter in inspect.signature(FQI).parameters.items()}
    assert {name: defaults[name] for name in FQI_DEFAULTS_MEASURED} == FQI_DEFAULTS_MEASURED


@pytest.mark.parametrize("name, first_ties, held, action_input", [
    ("control_cartpole", True, False, False), ("control_acrobot", True, False, True),
    ("control_mountaincar", False, True, False), ("control_lunarlander", False, False, False)])
def test_the_control_settings_per_env(name, first_ties, held, action_input):
    """The envs run before `tie_break` existed keep those runs beside the new default's; the
    others run each FQI setting once, with ties broken at random; MountainCar alone adds a
    setting with held random actions, Acrobot one forest over observation and action that
    stops at half DQN's budget."""
    labels = list(REGISTRY[name].settings)
    tied = [label for label in labels if label.endswith(", first-action ties")]
    assert len(tied) == (3 if first_ties else 0)
    held_labels = [label for label in labels if label.endswith(", held exploration")]
    assert len(held_labels) == held
    for label in held_labels:
        assert REGISTRY[name].settings[label]["fqi"]["exploration_zeta"] == 1.5
    stopped = [label for label in labels if "stop" in REGISTRY[name].params(label)]
    assert len(stopped) == action_input
    for label in stopped:
        params = REGISTRY[name].params(label)
        assert params["fqi"]["action_input"] and params["stop"] * 2 == params["steps"]
        assert params["fqi"]["exploration_zeta"] == 3
        assert params["regressor"] == "extra-trees, 150 grown out"
    assert sum(label.startswith("FQI") for label in labels) == (4 + 3 * first_ties + held
                                                                + action_input)
    assert {"DQN (rl-zoo3)", "PPO (rl-zoo3)"} <= set(labels)
