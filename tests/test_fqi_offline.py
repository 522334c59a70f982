"""`FQI.learn_offline`: fitted Q-iteration on a fixed data set, from a plain mapping of arrays
(feature vectors or object sets) or a Minari dataset built here (nothing is downloaded)."""
import gymnasium as gym
import numpy as np
import pytest
from sklearn.ensemble import ExtraTreesRegressor

from boxtrees import BoxExtraTreesClassifier, BoxExtraTreesRegressor, ObjectSets
from fqi import FQI, RandomPolicy, evaluate


def random_transitions(env_id, n, seed=0):
    """`n` transitions of the uniform random policy, as the mapping `learn_offline` takes."""
    env = gym.make(env_id)
    rng = np.random.default_rng(seed)
    columns = {key: [] for key in ("observations", "actions", "rewards", "next_observations",
                                   "terminations", "truncations")}
    obs, _ = env.reset(seed=seed)
    for _ in range(n):
        action = int(rng.integers(env.action_space.n))
        next_obs, reward, terminated, truncated, _ = env.step(action)
        for key, value in zip(columns, (obs, action, reward, next_obs, terminated, truncated)):
            columns[key].append(value)
        obs = env.reset()[0] if terminated or truncated else next_obs
    return {key: (values if key.endswith("observations") else np.array(values))
            for key, values in columns.items()}


def cartpole(**params):
    return FQI(ExtraTreesRegressor(n_estimators=10, min_samples_split=10, random_state=0),
               "CartPole-v1", eval_episodes=0, seed=0, **params)


def test_a_mapping_of_random_play_is_learned_without_playing():
    data = random_transitions("CartPole-v1", 5000)
    data["observations"] = np.array(data["observations"])  # a matrix or a list of rows alike
    agent = cartpole().learn_offline(data, n_iterations=20)
    assert agent.num_timesteps == 0 and len(agent.history) == 20
    assert {r["n_samples"] for r in agent.history} == {5000}
    random = evaluate(RandomPolicy("CartPole-v1", seed=0), "CartPole-v1", n_episodes=10).mean
    learned = evaluate(agent, "CartPole-v1", n_episodes=10).mean
    assert random < 30 and learned > 100, (random, learned)
    # then online: the collected transitions join the data set
    agent.learn(total_timesteps=500)
    assert agent.history[-1]["n_samples"] == 5500 and agent.num_timesteps >= 500


def test_object_sets_are_learned_from_a_mapping():
    from test_fqi_learn import NearestType

    env = NearestType()
    rng = np.random.default_rng(1)
    observations, next_observations, actions, rewards = [], [], [], []
    obs, _ = env.reset(seed=1)
    for _ in range(3000):
        action = int(rng.integers(3))
        next_obs, reward, _, truncated, _ = env.step(action)
        observations.append(obs)
        next_observations.append(next_obs)
        actions.append(action)
        rewards.append(reward)
        obs = env.reset()[0] if truncated else next_obs
    data = {"observations": observations, "next_observations": ObjectSets.from_sequence(
        next_observations), "actions": actions, "rewards": rewards,
        "terminations": np.zeros(3000, dtype=bool)}
    agent = FQI(BoxExtraTreesRegressor(n_estimators=10, random_state=0), NearestType,
                gamma=0.5, eval_episodes=0, seed=0).learn_offline(data, n_iterations=3)
    learned = evaluate(agent, NearestType, seeds=range(50)).mean
    assert learned > 8, learned  # of 10 steps; random play scores about 3.4
    # the offline constraint's behaviour model takes the object sets too
    assert isinstance(agent.support_model_, BoxExtraTreesClassifier)
    supported = agent._next_supported
    assert supported.shape == (3000, 3) and supported.all(axis=1).mean() > 0.8


@pytest.mark.filterwarnings("ignore:.*is set to None:UserWarning")  # its metadata
def test_a_minari_dataset_made_here_is_learned(tmp_path, monkeypatch):
    minari = pytest.importorskip("minari")
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path))
    env = minari.DataCollector(gym.make("CartPole-v1"))
    env.reset(seed=0)
    for _ in range(2000):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
    dataset = env.create_dataset(dataset_id="cartpole/random-v0", algorithm_name="random")
    agent = cartpole().learn_offline(dataset, n_iterations=10)
    assert {r["n_samples"] for r in agent.history} == {dataset.total_steps}
    assert evaluate(agent, "CartPole-v1", n_episodes=10).mean > 50
    # the dataset's transitions: each episode's observations, less its last, and the next
    data = agent._data
    episode = next(dataset.iterate_episodes())
    np.testing.assert_array_equal(data.states[:len(episode.actions)], episode.observations[:-1])
    np.testing.assert_array_equal(data.next_states[:len(episode.actions)],
                                  episode.observations[1:])
    with pytest.raises(ValueError, match="the dataset's observation space"):
        FQI(ExtraTreesRegressor(), "Acrobot-v1", eval_episodes=0).learn_offline(dataset, 1)


@pytest.mark.parametrize("change, error, match", [
    (lambda d: d.pop("rewards"), ValueError, "the dataset lacks rewards"),
    (lambda d: d.update(actions=np.full(10, 2)), ValueError, r"actions must lie in \[0, 2\)"),
    (lambda d: d.update(actions=np.zeros(10)), TypeError, "actions must be ints"),
    (lambda d: d.update(rewards=np.full(10, np.nan)), ValueError, "rewards must be finite"),
    (lambda d: d.update(terminations=np.zeros(9, dtype=bool)), ValueError,
     r"terminations have shape \(9,\); expected \(10,\)"),
    (lambda d: d.update(next_observations=d["next_observations"][:5]), ValueError,
     "10 observations and 5 next observations"),
    (lambda d: d.update(observations=np.zeros((10, 3))), ValueError,
     "the dataset's observations are a batch of shape"),
])
def test_a_bad_dataset_is_named(change, error, match):
    data = {key: np.asarray(value) for key, value in random_transitions("CartPole-v1", 10).items()}
    change(data)
    with pytest.raises(error, match=match):
        cartpole().learn_offline(data, n_iterations=1)


def test_something_else_is_no_dataset():
    with pytest.raises(TypeError, match="dataset must be a mapping"):
        cartpole().learn_offline([1, 2, 3], n_iterations=1)


def test_an_agent_loaded_without_an_env_needs_one_to_evaluate(tmp_path):
    data = random_transitions("CartPole-v1", 200)
    agent = FQI(ExtraTreesRegressor(n_estimators=3), lambda: gym.make("CartPole-v1"),
                eval_episodes=2, seed=0).learn_offline(data, n_iterations=1)
    agent.save(tmp_path / "agent.joblib")
    loaded = FQI.load(tmp_path / "agent.joblib")  # made from a factory: saved without it
    with pytest.raises(ValueError, match="no env to evaluate on"):
        loaded.learn_offline(data, n_iterations=1)
    assert len(loaded.history) == 1  # unchanged
    FQI.load(tmp_path / "agent.joblib", eval_episodes=0).learn_offline(data, n_iterations=1)


@pytest.mark.filterwarnings("ignore:Training and eval env are not of the same type")
def test_stable_baselines3_evaluation_scores_the_iterates_and_keeps_the_best(tmp_path):
    """Offline, an SB3 EvalCallback on an env scores the iterates as online: it saves the
    best one and its threshold stops the backups."""
    from stable_baselines3.common.callbacks import EvalCallback, StopTrainingOnRewardThreshold

    evaluation = EvalCallback(gym.make("CartPole-v1"), eval_freq=2, n_eval_episodes=2,
                              best_model_save_path=tmp_path, warn=False, verbose=0,
                              callback_on_new_best=StopTrainingOnRewardThreshold(
                                  reward_threshold=1, verbose=0))
    agent = cartpole().learn_offline(random_transitions("CartPole-v1", 500), n_iterations=6,
                                     callback=evaluation)
    assert agent.iteration == 2 and agent.num_timesteps == 0
    assert FQI.load(tmp_path / "best_model", env="CartPole-v1").iteration == 2
