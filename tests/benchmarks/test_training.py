"""The one way the benchmarks train and score stable-baselines3 agents, and FQI alike."""
import gymnasium as gym
import numpy as np
import pytest
from sklearn.ensemble import ExtraTreesRegressor

import envs
from benchmarks.training import EvalCallback, WrappedPolicy, timed_learn, train_sb3
from fqi import FQI, GridObservation, evaluate

_SMALL_DQN = {"learning_starts": 50, "buffer_size": 1000, "policy_kwargs": {"net_arch": [16]}}


def test_an_sb3_model_is_scored_during_training_and_after_its_last_update(tmp_path,
                                                                          monkeypatch):
    monkeypatch.chdir(tmp_path)
    curve = EvalCallback(gym.make("CartPole-v1"), 100, n_episodes=3)
    model, seconds, cpu_seconds = train_sb3("DQN", lambda: gym.make("CartPole-v1"), 300,
                                            _SMALL_DQN, seed=0, callback=curve)
    assert [steps for steps, _ in curve.evaluations] == [100, 200, 300]
    # the last point scores the trained model, as evaluate does after training
    assert curve.evaluations[-1][1] == evaluate(model, "CartPole-v1", n_episodes=3).mean
    assert seconds > 0 and cpu_seconds > 0 and curve.eval_seconds > 0
    assert list(tmp_path.iterdir()) == []  # no SB3 log folder


def test_fqi_is_scored_by_the_same_callback_after_its_iterations():
    agent = FQI(ExtraTreesRegressor(n_estimators=5, random_state=0), "CartPole-v1",
                samples_per_iteration=100, resample_every=1, eval_episodes=0, seed=0)
    curve = EvalCallback("CartPole-v1", 150, n_episodes=2, score="total", scale=0.5)
    seconds, _ = timed_learn(agent, curve, n_iterations=4)
    steps = [steps for steps, _ in curve.evaluations]  # collections overshoot a little
    assert len(steps) == 3 and steps[-1] == agent.num_timesteps
    assert 150 <= steps[0] < 300 <= steps[1] < steps[2]
    assert curve.evaluations[-1][1] == 0.5 * evaluate(agent, "CartPole-v1", n_episodes=2).total
    assert seconds > 0


def test_a_model_trained_on_wrapped_observations_plays_from_the_envs_own():
    env = gym.make("ObjectWorld-v0")
    grid = GridObservation(env, n_bins=4)
    model, _, _ = train_sb3("DQN", lambda: GridObservation(gym.make("ObjectWorld-v0"), n_bins=4),
                            100, _SMALL_DQN, seed=0)
    seeds = envs.reference_worlds(2)
    played = evaluate(WrappedPolicy(model, grid), env, seeds=seeds)
    wrapped = evaluate(model, GridObservation(gym.make("ObjectWorld-v0"), n_bins=4), seeds=seeds)
    np.testing.assert_array_equal(played.returns, wrapped.returns)


def test_a_wrapped_policy_plays_sampled_actions_when_asked_to_whatever_it_is_asked():
    class Recorder:
        asked = []

        def predict(self, batch, deterministic=True):
            self.asked.append(deterministic)
            return np.zeros(len(batch), dtype=int), None

    env = gym.make("ObjectWorld-v0")
    grid, model = GridObservation(env, n_bins=4), Recorder()
    batch = [env.reset(seed=0)[0]] * 2
    WrappedPolicy(model, grid).predict(batch, deterministic=True)
    WrappedPolicy(model, grid).predict(batch, deterministic=False)
    WrappedPolicy(model, grid, sampled=True).predict(batch, deterministic=True)
    assert model.asked == [True, False, False]


@pytest.mark.parametrize("kwargs, match", [({"eval_freq": 0}, "eval_freq must be > 0"),
                                            ({"score": "median"}, "score must be")])
def test_bad_evaluation_settings(kwargs, match):
    with pytest.raises(ValueError, match=match):
        EvalCallback("CartPole-v1", **{"eval_freq": 10, **kwargs})


def test_a_continued_fqi_agent_is_scored_during_its_second_call_too():
    agent = FQI(ExtraTreesRegressor(n_estimators=3, random_state=0), "CartPole-v1",
                samples_per_iteration=200, resample_every=1, n_envs=1, eval_episodes=0,
                seed=0).learn(total_timesteps=600)
    curve = EvalCallback("CartPole-v1", 200, n_episodes=1)
    timed_learn(agent, curve, total_timesteps=600)
    # the first multiple of 200 comes at once, then one per round; the end once
    assert [steps for steps, _ in curve.evaluations] == [800, 1000, 1200]
    before = curve.eval_seconds
    seconds, _ = timed_learn(agent, curve, total_timesteps=200)  # the same callback again
    assert curve.eval_seconds > before and seconds > 0  # only this call's evaluations out
