"""How FQI calls its regressors and plays its evaluations: no thread started per step, no
warning from scikit-learn's workers, the caller's scikit-learn configuration in every
thread, evaluations that end on envs whose episodes never do."""
import threading
import warnings

import gymnasium as gym
import numpy as np
import pytest
import sklearn
from sklearn.ensemble import ExtraTreesClassifier, ExtraTreesRegressor
from sklearn.linear_model import Ridge

from fqi import FQI, evaluate


class Endless(gym.Env):
    """Two actions, two random features, reward = the action; never terminates, no time
    limit."""

    observation_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
    action_space = gym.spaces.Discrete(2)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return np.zeros(2, dtype=np.float32), {}

    def step(self, action):
        obs = self.np_random.uniform(-1, 1, 2).astype(np.float32)
        return obs, float(action), False, False, {}


@pytest.fixture
def thread_starts(monkeypatch):
    """The number of threads started so far (a list of one int, updated)."""
    count = [0]
    start = threading.Thread.start

    def counted(thread, *args, **kwargs):
        count[0] += 1
        return start(thread, *args, **kwargs)

    monkeypatch.setattr(threading.Thread, "start", counted)
    return count


def forest_with_threads():
    return ExtraTreesRegressor(n_estimators=4, max_depth=6, n_jobs=2, random_state=0)


@pytest.mark.parametrize("n_jobs", [1, 2])
def test_learn_starts_threads_only_once_whatever_its_steps(thread_starts, n_jobs):
    # a forest with n_jobs=2 predicts the 8 envs' observations at every step, and the
    # 4 evaluation episodes' after each iteration: joblib would start a pool each time
    agent = FQI(forest_with_threads(), "CartPole-v1", samples_per_iteration=400,
                resample_every=2, n_envs=8, eval_episodes=4, n_jobs=n_jobs, seed=0)
    agent.learn(total_timesteps=800)
    first = thread_starts[0]
    agent.learn(total_timesteps=3_200)
    assert agent.num_timesteps >= 4_000
    assert first <= 12                     # the kept pools (their workers and handlers)
    assert thread_starts[0] - first <= 2   # four times the steps: nothing more


def test_a_forest_with_threads_inside_fqi_warns_nothing(monkeypatch):
    # scikit-learn's tasks swap the process's warning filters around each call; two
    # threads doing so at once can leave them emptied, and every later task then warns
    inside = {}
    overlaps = []
    enter, exit_ = warnings.catch_warnings.__enter__, warnings.catch_warnings.__exit__

    def entered(self):
        me = threading.get_ident()
        inside[me] = inside.get(me, 0) + 1
        if any(count for thread, count in inside.items() if thread != me):
            overlaps.append(me)
        return enter(self)

    def exited(self, *exc_info):
        inside[threading.get_ident()] -= 1
        return exit_(self, *exc_info)

    before = list(warnings.filters)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        monkeypatch.setattr(warnings.catch_warnings, "__enter__", entered)
        monkeypatch.setattr(warnings.catch_warnings, "__exit__", exited)
        FQI(forest_with_threads(), "CartPole-v1", samples_per_iteration=500, n_envs=8,
            eval_episodes=2, n_jobs=2, seed=0).learn(total_timesteps=1_500)
        monkeypatch.undo()
    assert [str(w.message) for w in caught] == []
    assert overlaps == []
    assert warnings.filters == before


class _ConfigRecorder(Ridge):
    """A Ridge that records scikit-learn's ``assume_finite`` at each fit and prediction."""

    seen = []

    def fit(self, X, y):
        self.seen.append(sklearn.get_config()["assume_finite"])
        return super().fit(X, y)

    def predict(self, X):
        self.seen.append(sklearn.get_config()["assume_finite"])
        return super().predict(X)


def test_the_callers_sklearn_configuration_reaches_fqis_threads():
    _ConfigRecorder.seen = []
    with sklearn.config_context(assume_finite=True):
        FQI(_ConfigRecorder(), "CartPole-v1", samples_per_iteration=300, resample_every=2,
            n_envs=150, n_jobs=2, seed=0).learn(total_timesteps=600)
    assert len(_ConfigRecorder.seen) > 10 and all(_ConfigRecorder.seen)


def test_an_env_without_time_limit_is_evaluated_in_bounded_time():
    agent = FQI(Ridge(), Endless(), samples_per_iteration=50, resample_every=1, n_envs=2,
                eval_episodes=3, seed=0)
    with pytest.warns(RuntimeWarning, match="reached 1,000 steps without ending .*TimeLimit"):
        agent.learn(total_timesteps=50)
    assert agent.history[-1]["mean_return"] <= 1_000
    with pytest.warns(RuntimeWarning, match="3 of 3 evaluation episodes reached 1,000 steps"):
        result = evaluate(agent, Endless(), n_episodes=3)
    assert result.lengths.tolist() == [1_000] * 3
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # a cap that is asked for is no surprise
        result = evaluate(agent, Endless(), n_episodes=2, max_episode_steps=20)
    assert result.lengths.tolist() == [20, 20]
    assert evaluate(agent, gym.wrappers.TimeLimit(Endless(), 30), n_episodes=2
                    ).lengths.tolist() == [30, 30]
    with pytest.raises(ValueError, match="max_episode_steps must be >= 1"):
        evaluate(agent, Endless(), n_episodes=2, max_episode_steps=0)


def test_learn_evaluates_only_when_asked_and_follows_the_training_episodes():
    agent = FQI(Ridge(), "CartPole-v1", samples_per_iteration=500, n_envs=4, seed=0)
    agent.learn(total_timesteps=1_000)
    assert np.isnan([r["reward"] for r in agent.history]).all()
    assert all(r["t_evaluate"] < 0.01 for r in agent.history)
    returns = [r["train_return"] for r in agent.history]
    assert np.isfinite(returns).all() and min(returns) >= 8  # CartPole lasts 8+ steps
    evaluated = FQI(Ridge(), "CartPole-v1", samples_per_iteration=500, n_envs=4,
                    eval_env="CartPole-v1", seed=0)
    assert len(evaluated._eval_seeds) == 10


def test_a_classifier_is_refused_at_construction():
    with pytest.raises(TypeError, match="ExtraTreesClassifier is a classifier; use its "
                                        "regressor counterpart"):
        FQI(ExtraTreesClassifier(), "CartPole-v1")


@pytest.mark.parametrize("observation, match", [
    ([np.nan, 0.0, 0.0, 0.0], r"the observation is not finite"),
    ([[0.0, np.inf, 0.0, 0.0]], r"the observation is not finite"),
    ([0.0, 0.0, 0.0], r"the observation is of shape \(3,\); expected \(4,\)"),
])
def test_predict_names_what_is_wrong_with_an_observation(observation, match):
    # (scikit-learn's ExtraTreesRegressor takes NaN: it would return an action)
    agent = FQI(ExtraTreesRegressor(n_estimators=2), "CartPole-v1", samples_per_iteration=100, n_envs=2, seed=0)
    agent.learn(total_timesteps=100)
    with pytest.raises(ValueError, match=match):
        agent.predict(observation)
