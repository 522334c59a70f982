"""The FQI agent on ObjectWorld: SB3-style API, data regimes, determinism, persistence, the
thesis's numbers, learning, baselines, bad input. Other envs: test_fqi_envs.py."""
import csv
import os
import pickle
import threading

import gymnasium as gym
import joblib
import numpy as np
import pytest
from conftest import run_in_fork
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.exceptions import NotFittedError
from sklearn.linear_model import Ridge

import envs
from boxtrees import BoxExtraTreesRegressor, ObjectSets
from fqi import FQI, GridObservation, RandomPolicy, evaluate, make_box_forest, make_grid_ridge
from fqi._collect import _Collector, _Transitions
from fqi._saving import _SAVE_FORMAT
from fqi._observations import _observation_format

ENV = "ObjectWorld-v0"
REFERENCE = envs.reference_worlds(400)  # the thesis's evaluation: 400 episodes of 50 steps


def small_forest(**params):
    return BoxExtraTreesRegressor(n_estimators=5, n_tests=50, view_bounds=10, n_jobs=1,
                                  **params)


# The thesis's protocol, at a small size: what these tests were written for.
THESIS = dict(gamma=0.5, resample_every=1, keep_data=False, exploration_initial_eps=0.2,
              exploration_final_eps=0.2, tie_break="first")


def small_agent(regressor=None, **params):
    settings = dict(samples_per_iteration=1000, n_envs=50, eval_seeds=REFERENCE[:10], seed=0,
                    **THESIS)
    settings.update(params)
    return FQI(small_forest() if regressor is None else regressor, ENV, **settings)


class ObjectCountQ(RegressorMixin, BaseEstimator):
    """Q(s) = weight * (number of objects in s); records what it was fitted on."""

    def __init__(self, weight=1.0):
        self.weight = weight

    def fit(self, X, y):
        self.X_, self.y_ = X, np.asarray(y)
        return self

    def predict(self, X):
        return self.weight * ObjectSets(X.data, X.offsets).sizes.astype(float)


@pytest.fixture(scope="module")
def trained():
    return small_agent().learn(n_iterations=2)


# ---------------------------------------------------------------- SB3 shape
def test_evaluate_policy_from_stable_baselines3(trained):
    from stable_baselines3.common.evaluation import evaluate_policy

    env = envs.PaddedObjects(gym.make(ENV), max_objects=128)
    with pytest.warns(UserWarning, match="Monitor"):
        mean, std = evaluate_policy(trained, env, n_eval_episodes=2)
    assert np.isfinite(mean) and np.isfinite(std)


def test_predict_accepts_every_observation_form(trained):
    worlds = envs.BatchedObjectWorld(6)
    obs, _ = worlds.reset(seed=3)
    batch, _ = trained.predict(obs)
    assert batch.shape == (6,) and batch.dtype.kind == "i"
    assert [trained.predict(o)[0] for o in obs] == batch.tolist()  # one (n, 3) each
    assert trained.predict(list(obs))[0].tolist() == batch.tolist()
    single = envs.PaddedObjects(gym.make(ENV), 128)
    padded = np.stack([single.observation(o) for o in obs])
    assert trained.predict(padded)[0].tolist() == batch.tolist()
    assert trained.predict(padded[2])[0] == batch[2]
    assert trained.q_values(obs).shape == (6, 4) and trained.q_values(obs[0]).shape == (4,)
    assert trained.predict(np.empty((0, 3)))[0] in range(4)
    # epsilon-greedy when not deterministic: epsilon=1 gives some non-greedy actions
    trained.exploration_rate = 1.0
    try:
        explored, _ = trained.predict(np.tile(padded, (20, 1, 1)), deterministic=False)
    finally:
        trained.exploration_rate = 0.2
    assert (explored != np.tile(batch, 20)).any()


def test_callback_sees_every_iteration_and_can_stop():
    seen = []

    def plain(locals_, globals_):
        seen.append(locals_["record"]["iteration"])
        assert locals_["self"].iteration == len(seen)
        return len(seen) < 2  # stop after the second iteration

    agent = small_agent(eval_episodes=0).learn(n_iterations=5, callback=plain)
    assert seen == [0, 1] and agent.iteration == 2
    rewards = []
    agent = small_agent().learn(n_iterations=3, callback=lambda l, g: rewards.append(l["record"]["reward"]))
    assert rewards == [r["reward"] for r in agent.history] and len(rewards) == 3


def test_progress_bar_and_verbose(capsys):
    small_agent(eval_episodes=0, verbose=1).learn(n_iterations=2, progress_bar=True)
    captured = capsys.readouterr()
    assert "FQI" in captured.err and "2/2" in captured.err  # tqdm writes to stderr
    assert captured.out.count("iteration") == 2


def test_csv_log_has_one_row_per_iteration(tmp_path):
    path = tmp_path / "log.csv"
    agent = small_agent(log_path=path).learn(n_iterations=2)
    agent.learn(n_iterations=1)  # appends, one header
    with path.open() as f:
        rows = list(csv.DictReader(f))
    assert [int(r["iteration"]) for r in rows] == [0, 1, 2]
    for key in ("reward", "mean_return", "t_collect", "t_targets", "t_fit", "t_evaluate",
                "n_samples", "nodes_per_tree"):
        assert float(rows[-1][key]) == pytest.approx(agent.history[-1][key])
    assert float(rows[1]["nodes_per_tree"]) > 1


# ---------------------------------------------------------------- persistence and seeds
def test_save_load_round_trip(trained, tmp_path):
    trained.save(tmp_path / "agent.joblib")
    loaded = FQI.load(tmp_path / "agent.joblib")
    worlds = envs.BatchedObjectWorld(50)
    obs, _ = worlds.reset(seed=envs.reference_worlds(50))
    np.testing.assert_array_equal(loaded.predict(obs)[0], trained.predict(obs)[0])
    np.testing.assert_array_equal(loaded.q_values(obs), trained.q_values(obs))
    np.testing.assert_equal(loaded.history, trained.history)  # (NaN equal to NaN)
    assert loaded.iteration == 2
    assert loaded.gamma == trained.gamma and loaded.eval_seeds == trained.eval_seeds
    assert loaded.tie_break == trained.tie_break == "first"
    assert loaded.observation_space == trained.observation_space
    assert isinstance(loaded.get_env(), envs.BatchedObjectWorld)  # from the saved id
    loaded.learn(n_iterations=1)  # training continues on fresh data
    assert loaded.iteration == 3 and loaded.num_timesteps == 3000


def _without_times(history):
    return [{k: v for k, v in record.items() if not k.startswith("t_")} for record in history]


@pytest.mark.parametrize("params", [{}, {"keep_data": True, "max_samples": 3000},
                                    {"resample_every": 2}],
                         ids=["re-sampling", "keeping data", "every 2"])
def test_a_pickled_agent_learns_on_exactly_as_the_original(params):
    agent = small_agent(**params).learn(n_iterations=1)
    copy = pickle.loads(pickle.dumps(agent))
    # the transitions travel only when the next iteration still uses them
    assert (copy._data is None) == (not params)
    agent.learn(n_iterations=2)
    copy.learn(n_iterations=2)
    np.testing.assert_equal(_without_times(copy.history), _without_times(agent.history))
    worlds = envs.BatchedObjectWorld(50)
    obs, _ = worlds.reset(seed=envs.reference_worlds(50))
    np.testing.assert_array_equal(copy.q_values(obs), agent.q_values(obs))


def test_same_seed_same_reward_curve():
    def curve(seed):
        return [r["reward"] for r in small_agent(seed=seed).learn(n_iterations=3).history]

    first = curve(7)
    assert curve(7) == first
    assert curve(8) != first


def _collector(worlds, seed=0):
    return _Collector(worlds, _observation_format(worlds.single_observation_space),
                      np.random.default_rng(seed))


def test_training_never_sees_reference_worlds():
    seeds = []
    worlds = envs.BatchedObjectWorld(20)
    reset = worlds.reset

    def spy(*, seed=None, options=None):
        seeds.append(seed)
        return reset(seed=seed, options=options)

    worlds.reset = spy
    data, steps = _collector(worlds).collect(
        2050, lambda obs, q, envs: np.zeros(len(obs), dtype=int))
    assert steps == 2060 and len(data) == 2050  # 100 steps: 2 episodes, 1 step of a third
    # one seeded reset; then the batched engine's autoreset continues each world's generator
    assert seeds[1:] == [None, None]
    assert len(seeds[0]) == 20 and max(seeds[0]) < envs.REFERENCE_SEED_START


# ---------------------------------------------------------------- algorithm
def test_collection_reuses_q_values_as_next_state_values():
    q = ObjectCountQ().predict
    collector = _collector(envs.BatchedObjectWorld(30, max_steps=7))

    def q_values(sets):
        base = q(sets)
        return np.column_stack([base, -base, 2 * base, np.zeros_like(base)])

    def policy(obs, values, envs):
        return values.argmax(axis=1) % 4

    data, _ = collector.collect(30 * 10 + 5, policy, q_values)  # crosses an episode end
    assert len(data) == 305
    np.testing.assert_array_equal(data.next_values, q_values(data.next_states).max(axis=1))
    np.testing.assert_array_equal(data.states[30:60].data, data.next_states[:30].data)


def test_targets_bootstrap_through_truncation_but_not_termination():
    agent = small_agent(ObjectCountQ(weight=2.0), gamma=0.5, resample_every=None)
    agent.learn(n_iterations=1)
    first = agent.q_functions_
    np.testing.assert_array_equal(
        np.concatenate([m.y_ for m in first]),
        np.concatenate([agent._data.rewards[agent._data.actions == a] for a in range(4)]))
    # every episode here ends by truncation: all targets bootstrap
    data = agent._data
    agent.learn(n_iterations=1)
    expected = data.rewards + 0.5 * 2.0 * data.next_states.sizes
    for a, model in enumerate(agent.q_functions_):
        np.testing.assert_allclose(model.y_, expected[data.actions == a])
    # a (synthetic) termination cuts the bootstrap
    data.terminated[::3] = True
    agent.learn(n_iterations=1)
    expected = data.rewards + np.where(data.terminated, 0.0, data.next_states.sizes)
    for a, model in enumerate(agent.q_functions_):
        np.testing.assert_allclose(model.y_, expected[data.actions == a])


def test_regimes_collect_when_they_should():
    def new_samples(**params):
        agent = small_agent(eval_episodes=0, **params).learn(n_iterations=7)
        return [r["new_samples"] for r in agent.history], [r["n_samples"] for r in agent.history]

    assert new_samples(resample_every=1) == ([1000] * 7, [1000] * 7)
    assert new_samples(resample_every=None) == ([1000] + [0] * 6, [1000] * 7)
    assert new_samples(resample_every=5) == ([1000, 0, 0, 0, 0, 1000, 0], [1000] * 7)
    kept = new_samples(keep_data=True, max_samples=2500)
    assert kept == ([1000] * 7, [1000, 2000, 2500, 2500, 2500, 2500, 2500])


def test_missing_action_keeps_its_previous_q_function():
    agent = small_agent(ObjectCountQ(), exploration_initial_eps=0.0,
                        exploration_final_eps=0.0, eval_episodes=0).learn(n_iterations=1)
    # every action has the same Q-values: greedy with ties to the first action, the agent
    # picks action 0 everywhere
    with pytest.warns(RuntimeWarning, match="no transition with action"):
        agent.learn(n_iterations=1)


def test_box_fqi_and_grid_ridge_beat_random():
    """Thesis 3.2 at small scale: 3 iterations of 5,000 samples on ObjectWorld-v0, scored
    on the 400 reference worlds (20,000 steps) against the random policy."""
    random_score = evaluate(RandomPolicy(ENV, seed=0), ENV, seeds=REFERENCE).total
    scores = {}
    for name, regressor in [("box", make_box_forest(ENV, n_estimators=10, random_state=0)),
                            ("grid", make_grid_ridge(ENV))]:
        agent = FQI(regressor, ENV, samples_per_iteration=5000, n_envs=400, eval_episodes=0,
                    seed=0)
        scores[name] = evaluate(agent.learn(n_iterations=3), ENV, seeds=REFERENCE).total
    assert random_score < -80_000
    # measured (seed 0): box about +40,000, grid about -34,000, random -95,650
    assert scores["box"] > random_score + 100_000, scores
    assert scores["grid"] > random_score + 40_000, scores


# ---------------------------------------------------------------- baselines
def test_grid_observation_reuses_grid_counts():
    from stable_baselines3.common.env_checker import check_env

    env = GridObservation(gym.make(ENV), n_bins=10)
    check_env(env, warn=True)
    raw = gym.make(ENV)
    obs, _ = env.reset(seed=4)
    objects, _ = raw.reset(seed=4)
    assert obs.shape == (400,) and obs.dtype == np.float32
    np.testing.assert_array_equal(obs, env.grid.transform([objects])[0])
    assert obs.sum() == np.sum(np.abs(objects[:, :2]).max(axis=1) <= 10)
    assert GridObservation(gym.make("ObjectWorldSword-v0")).action_space.n == 8


def test_scripted_policies_use_the_same_evaluation():
    greedy = evaluate(envs.GreedyPolicy(envs.BatchedObjectWorld(1)), ENV, seeds=REFERENCE)
    assert greedy.total > 100_000 and greedy.lengths.tolist() == [50] * 400
    assert evaluate(RandomPolicy(ENV, seed=1), ENV, seeds=REFERENCE[:20]).total < 0


# ---------------------------------------------------------------- bad input
class NoPredict(BaseEstimator):
    def fit(self, X, y):
        return self


@pytest.mark.parametrize("regressor, match", [
    (NoPredict(), "has no predict"), ("forest", "fit and predict"), (None, "fit and predict")])
def test_regressor_without_fit_predict(regressor, match):
    with pytest.raises(TypeError, match=match):
        FQI(regressor, ENV)


def test_env_needs_discrete_actions_and_grids_need_object_sets():
    with pytest.raises(TypeError, match="Discrete action space"):
        FQI(small_forest(), gym.make("Pendulum-v1"))
    with pytest.raises(TypeError, match=r"object-set observations have rows .* Sequence\(Box"):
        GridObservation(gym.make("CartPole-v1"))
    with pytest.raises(TypeError, match="env must be"):
        FQI(small_forest(), 42)


def test_an_object_world_env_keeps_the_batched_engine_and_its_rules():
    env = gym.make("ObjectWorldTreasure-v0", view="arrow")
    agent = FQI(make_box_forest(env, n_estimators=2, n_tests=10), env,
                samples_per_iteration=400, n_envs=40, eval_seeds=REFERENCE[:4])
    for vector, n in ((agent.get_env(), 40), (agent._eval_env, 4)):
        assert isinstance(vector, envs.BatchedObjectWorld) and vector.num_envs == n
        assert vector.rules == env.unwrapped.rules
    assert agent.regressor.view_bounds == (-10.0, 10.0, -10.0, 10.0)
    assert make_grid_ridge(env)[0].n_types == 7  # arrow view: 7 types


def test_thesis_run_is_unchanged():
    """A small box-FQI run on the reference worlds gives, reward for reward, what it gave
    when the agent played ObjectWorld's batched engine directly: the same training worlds,
    drawn from the same generator, and the same action draws."""
    forest = make_box_forest(ENV, n_estimators=5, n_tests=50, random_state=0)
    agent = FQI(forest, ENV, samples_per_iteration=2000, n_envs=100, eval_seeds=REFERENCE[:20],
                seed=0, **THESIS).learn(n_iterations=3)
    assert [r["reward"] for r in agent.history] == [-1300.0, -2400.0, -1100.0]
    assert agent.num_timesteps == 6000
    kept = FQI(make_box_forest(ENV, n_estimators=5, n_tests=50, random_state=0), ENV,
               samples_per_iteration=1000, n_envs=50, eval_seeds=REFERENCE[:10], seed=3,
               **{**THESIS, "keep_data": True}, max_samples=2500).learn(n_iterations=4)
    assert [r["reward"] for r in kept.history] == [100.0, -1200.0, 200.0, -4850.0]


@pytest.mark.parametrize("params, error, match", [
    ({"exploration_final_eps": -0.1}, ValueError,
     r"exploration_final_eps must lie in \[0.0, 1.0\]"),
    ({"exploration_initial_eps": 1.5}, ValueError, "exploration_initial_eps"),
    ({"exploration_fraction": float("nan")}, ValueError, "exploration_fraction"),
    ({"exploration_final_eps": "0.2"}, TypeError, "exploration_final_eps must be a number"),
    ({"samples_per_iteration": 0}, ValueError, "samples_per_iteration must be >= 1"),
    ({"samples_per_iteration": 2.5}, TypeError, "samples_per_iteration must be an int"),
    ({"gamma": 1.0}, ValueError, "gamma"),
    ({"resample_every": 0}, ValueError, "resample_every"),
    ({"keep_data": True, "max_samples": 10}, ValueError, "max_samples"),
    ({"eval_episodes": 1.5}, TypeError, "eval_episodes must be an int"),
    ({"n_envs": 0}, ValueError, "n_envs"),
    ({"n_jobs": 0}, ValueError, "n_jobs"),
    ({"n_jobs": 1.5}, TypeError, "n_jobs must be an int"),
    ({"verbose": "yes"}, TypeError, "verbose must be an int or a bool"),
    ({"verbose": -1}, ValueError, "verbose must be >= 0"),
    ({"tie_break": "last"}, ValueError, "tie_break must be one of 'random', 'first'"),
    ({"exploration_zeta": 1.0}, ValueError, "exploration_zeta must be greater than 1"),
    ({"exploration_zeta": 0.5}, ValueError, r"exploration_zeta must lie in \[1.0, inf\]"),
    ({"exploration_zeta": "2"}, TypeError, "exploration_zeta must be a number"),
    ({"double": 1}, TypeError, "double must be a bool"),
    ({"action_input": "yes"}, TypeError, "action_input must be a bool"),
])
def test_bad_parameters(params, error, match):
    with pytest.raises(error, match=match):
        small_agent(**params)


@pytest.mark.parametrize("observation, error, match", [
    (np.zeros((5, 2)), ValueError, r"\(n, 3\) array"),
    (np.zeros(3), ValueError, r"got shape \(3,\)"),
    (np.zeros((2, 5, 6)), ValueError, "padded"),
    (np.array([[0.0, 1.0, np.nan]]), ValueError, "NaN"),
    (np.array([[0.0, 1.0, -1.0]]), ValueError, "negative type"),
    ([np.zeros((2, 2))], ValueError, r"objects of 2 columns, .* fitted on objects of 3"),
    (np.array([["a", "b", "c"]]), TypeError, "numbers"),
])
def test_predict_rejects_bad_observations(trained, observation, error, match):
    with pytest.raises(error, match=match):
        trained.predict(observation)


def test_predict_before_learn_and_bad_learn_arguments(tmp_path):
    agent = small_agent()
    with pytest.raises(NotFittedError, match="learn"):
        agent.predict(np.zeros((1, 3)))
    with pytest.raises(ValueError, match="n_iterations"):
        agent.learn(n_iterations=0)
    with pytest.raises(TypeError, match="callback"):
        agent.learn(n_iterations=1, callback=3)
    with pytest.raises(TypeError, match="progress_bar must be a bool"):
        agent.learn(n_iterations=1, progress_bar="yes")


def test_log_path_is_checked_at_construction(tmp_path, monkeypatch):
    with pytest.raises(FileNotFoundError, match="directory .*missing.* does not exist"):
        small_agent(log_path=tmp_path / "missing" / "log.csv")
    with pytest.raises(IsADirectoryError, match="is a directory"):
        small_agent(log_path=tmp_path)
    with pytest.raises(TypeError, match="log path must be a str or path-like"):
        small_agent(log_path=3)
    monkeypatch.setattr(os, "access", lambda path, mode: False)  # tests may run as root
    with pytest.raises(PermissionError, match="not writable"):
        small_agent(log_path=tmp_path / "log.csv")


def _truncated_save(agent, path):
    agent.save(path)
    saved = path.read_bytes()
    path.write_bytes(saved[:len(saved) // 2])


@pytest.mark.parametrize("write, match", [
    (lambda agent, path: path.write_bytes(b""), "is empty"),
    (lambda agent, path: path.write_bytes(np.random.default_rng(0).bytes(300)),
     r"not an agent saved by FQI.save \(not a joblib pickle\)"),
    (lambda agent, path: path.write_text("iteration,reward\n0,1.0\n"), "not a joblib pickle"),
    (_truncated_save, "truncated or damaged"),
    (lambda agent, path: joblib.dump([1, 2], path), "pickle of a list, not an agent"),
    (lambda agent, path: joblib.dump({"rules": {}}, path), "pickle of a dict, not an agent"),
    (lambda agent, path: joblib.dump({"format": 1}, path),
     f"FQI save of format version 1; this version of fqi reads version {_SAVE_FORMAT}"),
    (lambda agent, path: joblib.dump({"format": _SAVE_FORMAT, "state": {}}, path),
     "not an agent saved by FQI.save: it lacks _q, action_input, action_space, double, env"),
    (lambda agent, path: joblib.dump({"format": _SAVE_FORMAT, "state": [1]}, path),
     "not an agent saved by FQI.save: it lacks state"),
])
def test_load_names_the_file_and_what_is_wrong(trained, tmp_path, write, match):
    path = tmp_path / "agent.joblib"
    write(trained, path)
    with pytest.raises(ValueError, match=match) as excinfo:
        FQI.load(path)
    assert str(path) in str(excinfo.value)


def test_load_of_a_missing_file_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        FQI.load(tmp_path / "missing.joblib")


class ConstantQ(RegressorMixin, BaseEstimator):
    """Q(s) = value everywhere, predicted `n_values` times per batch (default: one per set);
    with `after_rewards`, only once fitted on non-zero targets (0 before)."""

    def __init__(self, value=0.0, n_values=None, after_rewards=False):
        self.value = value
        self.n_values = n_values
        self.after_rewards = after_rewards

    def fit(self, X, y):
        self.fitted_on_rewards_ = bool(np.any(y))
        return self

    def predict(self, X):
        value = self.value if self.fitted_on_rewards_ or not self.after_rewards else 0.0
        return np.full(len(X) if self.n_values is None else self.n_values, value)


@pytest.mark.parametrize("regressor, match", [
    (ConstantQ(np.nan), r"predicted non-finite Q-values \(NaN or inf\) for 50 of 50"),
    (ConstantQ(np.inf), "non-finite"),
    (ConstantQ(n_values=1), "predicted an array of size 1 for 50 observations"),
])
def test_bad_predictions_are_caught_at_construction(regressor, match):
    with pytest.raises(ValueError, match=match) as excinfo:
        small_agent(regressor)
    assert str(excinfo.value).startswith("ConstantQ(") and "first observations" in str(
        excinfo.value)


@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_bad_predictions_stop_training_at_their_iteration(value):
    regressor = ConstantQ(value, after_rewards=True)
    agent = small_agent(regressor)  # evaluates 10 worlds at iteration 0
    with pytest.raises(ValueError, match=r"non-finite Q-values \(NaN or inf\) for 10 of 10") \
            as excinfo:
        agent.learn(n_iterations=3)
    assert str(excinfo.value).startswith("iteration 0's Q-function of action 0 (ConstantQ(")
    assert agent.history == []
    agent = small_agent(regressor, eval_episodes=0)  # first predicts collecting, iteration 1
    with pytest.raises(ValueError, match="iteration 0's Q-function of action 0"):
        agent.learn(n_iterations=3)
    assert len(agent.history) == 1


def test_regressor_without_object_sets_is_told_to_wrap_them():
    with pytest.raises((TypeError, ValueError), match=r"Ridge\(\) failed to fit and predict "
                       r"the env's observations, which FQI gives it as boxtrees.ObjectSets") \
            as excinfo:
        small_agent(Ridge())
    assert "a pipeline starting with boxtrees.GridCounts" in str(excinfo.value)
    assert excinfo.value.__cause__ is not None


@pytest.mark.parametrize("make, error, match", [
    (lambda: make_box_forest(n_estimators=0), ValueError, "n_estimators must be >= 1"),
    (lambda: make_box_forest(n_tests=True), TypeError, "n_tests must be an int"),
    (lambda: make_box_forest(n_jobs=0), ValueError, "n_jobs must be a non-zero int"),
    (lambda: make_box_forest(test_type="square"), ValueError, "'test_type' parameter"),
    (lambda: make_box_forest(test_width=float("nan")), ValueError, "'test_width' parameter"),
    (lambda: make_box_forest(random_state=-1), ValueError, "'random_state' parameter"),
    (lambda: make_grid_ridge(ENV, n_bins=0), ValueError, "n_bins must be >= 1"),
    (lambda: make_grid_ridge(ENV, alpha=-1.0), ValueError, r"alpha must lie in \[0.0, inf\)"),
    (lambda: make_grid_ridge(ENV, alpha=float("nan")), ValueError, "alpha"),
    (lambda: make_grid_ridge(), TypeError, "needs an env observing object sets"),
    (lambda: make_grid_ridge(view_bounds=(0, 0, 0, 1), n_types=2), ValueError,
     "xmin < xmax"),
    (lambda: make_grid_ridge(view_bounds=5, n_types=0), ValueError, "'n_types' parameter"),
    (lambda: make_box_forest("CartPole-v1").view_bounds is None or 1 / 0, None, None),
    (lambda: RandomPolicy(ENV, seed=-1), ValueError, "seed must be >= 0"),
    (lambda: RandomPolicy(ENV, seed=True), TypeError, "seed must be an int"),
])
def test_baselines_check_their_parameters(make, error, match):
    if error is None:
        make()
        return
    with pytest.raises(error, match=match):
        make()


class ScriptedPolicy:
    """``predict`` returns ``answer(n)`` for a batch of n observations."""

    def __init__(self, answer):
        self.answer = answer

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return self.answer(len(observation))


@pytest.mark.parametrize("policy, error, match", [
    (object(), TypeError, "policy must have a method predict.*object has no predict"),
    (ScriptedPolicy(lambda n: (np.zeros(3, int), None)), ValueError,
     r"returned 3 actions \(shape \(3,\)\) for a batch of 10 observations; expected 10, "
     r"one per env"),
    (ScriptedPolicy(lambda n: (np.full(n, 7), None)), ValueError,
     r"returned action 7; the action space is Discrete\(4\)"),
    (ScriptedPolicy(lambda n: (np.full(n, -1), None)), ValueError, "returned action -1"),
    (ScriptedPolicy(lambda n: (np.zeros(n), None)), ValueError, "int actions.*float64"),
    (ScriptedPolicy(lambda n: np.zeros(n, int)), TypeError, r"pair \(actions, state\)"),
])
def test_evaluate_checks_the_policy_and_its_actions(policy, error, match):
    with pytest.raises(error, match=match):
        evaluate(policy, ENV, seeds=REFERENCE[:10])


@pytest.mark.parametrize("kwargs, error, match", [
    ({"n_episodes": 0}, ValueError, "n_episodes must be >= 1"),
    ({"n_episodes": 5.0}, TypeError, "n_episodes must be an int"),
    ({"n_episodes": 2, "seeds": [1]}, ValueError, "n_episodes=2 but 1 seeds were given"),
    ({"seeds": "0123"}, TypeError, "seeds must be a sequence of ints"),
    ({"seeds": [0.5]}, TypeError, r"seeds\[0\] must be an int"),
])
def test_evaluate_rejects_bad_episode_counts_and_seeds(kwargs, error, match):
    with pytest.raises(error, match=match):
        evaluate(RandomPolicy(ENV), ENV, **kwargs)


def test_transitions_concatenate_drops_unknown_next_values():
    sets = ObjectSets.from_sequence([np.zeros((1, 3))] * 2)
    known = _Transitions(sets, np.zeros(2, int), np.zeros(2), sets, np.zeros(2, bool),
                         np.ones(2))
    unknown = _Transitions(sets, np.zeros(2, int), np.zeros(2), sets, np.zeros(2, bool))
    join = ObjectSets.concatenate
    assert _Transitions.concatenate([known, known], join).next_values.tolist() == [1, 1, 1, 1]
    assert _Transitions.concatenate([known, unknown], join).next_values is None


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")
def test_a_forked_child_predicts_with_threads_of_its_own():
    from sklearn.ensemble import ExtraTreesRegressor

    agent = FQI(ExtraTreesRegressor(n_estimators=2, random_state=0), "CartPole-v1",
                samples_per_iteration=200, eval_episodes=0, n_jobs=2, seed=0).learn(n_iterations=1)
    obs = np.zeros((3, 4), dtype=np.float32)
    expected = agent.q_values(obs)  # its thread pool exists before the fork
    assert run_in_fork(lambda: np.array_equal(agent.q_values(obs), expected))


_MEETING = threading.Barrier(2, timeout=30)


class MeetingRidge(Ridge):
    """A Ridge whose fit on a Q-function's targets (not the agent's check, on zeros) first
    waits for another to start: one after the other, those fits time out."""

    def fit(self, X, y, sample_weight=None):
        if np.any(y):
            _MEETING.wait()
        return super().fit(X, y, sample_weight)


@pytest.mark.parametrize("double", [False, True])
def test_n_jobs_fits_the_actions_side_by_side_to_the_same_models(double):
    agents = [FQI(regressor, "CartPole-v1", samples_per_iteration=200, eval_episodes=0,
                  double=double, n_jobs=n_jobs, seed=0).learn(n_iterations=2)
              for regressor, n_jobs in ((MeetingRidge(), 2), (Ridge(), 1))]
    obs = np.random.default_rng(0).normal(size=(20, 4))
    np.testing.assert_array_equal(agents[0].q_values(obs), agents[1].q_values(obs))
    assert not _MEETING.broken
