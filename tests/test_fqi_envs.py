"""FQI on gymnasium envs other than ObjectWorld: Box and object-set observations, every env
form, vector envs with episodes of different lengths under each autoreset mode, SB3
callbacks, persistence, evaluation, bad envs, and the package's import rules."""
import ast
import pathlib
import pickle
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, SyncVectorEnv
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.ensemble import ExtraTreesRegressor
from sklearn.linear_model import Ridge

import fqi
from boxtrees import BoxExtraTreesRegressor, ObjectSets
from fqi import FQI, GridObservation, RandomPolicy, evaluate, make_box_forest, make_grid_ridge
from fqi._collect import _Collector
from fqi._observations import _observation_format

ROOT = pathlib.Path(__file__).resolve().parents[1]


def classic_forest(**params):
    """A fast forest for feature vectors: boxtrees' classic axis-aligned splits."""
    return BoxExtraTreesRegressor(n_estimators=10, n_tests=4, test_type="classic",
                                  min_samples_split=5, n_jobs=1, **params)


# ---------------------------------------------------------------- envs written for the tests
class Countdown(gym.Env):
    """Episodes of 1 to 5 steps (drawn at reset), ended by a termination or a truncation
    (drawn too). Observation ``[tag, episode, t, length]``; reward ``10 t + action``."""

    def __init__(self, tag=0):
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(4,), dtype=np.float32)
        self.action_space = spaces.Discrete(2)
        self.tag, self.episode = tag, -1

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.episode += 1
        self.t, self.length = 0, int(self.np_random.integers(1, 6))
        self.terminates = bool(self.np_random.integers(2))
        return self._obs(), {}

    def step(self, action):
        self.t += 1
        end = self.t == self.length
        return (self._obs(), 10.0 * self.t + int(action), end and self.terminates,
                end and not self.terminates, {})

    def _obs(self):
        return np.array([self.tag, self.episode, self.t, self.length], dtype=np.float32)


class Coins(gym.Env):
    """An object-set game: coins (type 0) and pits (type 1) on a line through the agent, seen
    as agent-relative rows ``[x, y, type]`` within 5 cells. Actions move left (0) or right
    (1); reaching a coin gives +1, a pit -1; 20 steps per episode."""

    def __init__(self):
        row = spaces.Box(np.array([-5, -5, 0]), np.array([5, 5, 1]), dtype=np.float32)
        self.observation_space = spaces.Sequence(row, stack=True)
        self.action_space = spaces.Discrete(2)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        n = int(self.np_random.integers(2, 7))
        x = self.np_random.choice([-4, -3, -2, -1, 1, 2, 3, 4], size=n, replace=False)
        self.objects = np.column_stack([x, np.zeros(n), self.np_random.integers(0, 2, size=n)])
        self.t = 0
        return self._obs(), {}

    def step(self, action):
        self.objects[:, 0] -= 1 if action == 1 else -1  # the world moves against the agent
        here = self.objects[:, 0] == 0
        reward = float(np.sum(np.where(self.objects[here, 2] == 0, 1.0, -1.0)))
        self.objects = self.objects[~here & (np.abs(self.objects[:, 0]) <= 5)]
        self.t += 1
        return self._obs(), reward, False, self.t == 20, {}

    def _obs(self):
        return self.objects.astype(np.float32)


class Broken(gym.Env):
    """Raises in `step`."""

    observation_space = spaces.Box(-1, 1, shape=(2,), dtype=np.float32)
    action_space = spaces.Discrete(2)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return np.zeros(2, dtype=np.float32), {}

    def step(self, action):
        raise RuntimeError("the simulator lost its connection")


def countdowns(n_envs, mode=AutoresetMode.NEXT_STEP):
    return SyncVectorEnv([lambda tag=tag: Countdown(tag) for tag in range(n_envs)],
                         autoreset_mode=mode)


# ---------------------------------------------------------------- learning
def test_cartpole_learns_at_a_tiny_budget():
    """8,000 env steps of FQI with classic trees on CartPole-v1's feature vector: the greedy
    policy balances far longer than the random one (about 21 steps)."""
    random_mean = evaluate(RandomPolicy("CartPole-v1", seed=0), "CartPole-v1",
                           seeds=range(10)).mean
    agent = FQI(classic_forest(), "CartPole-v1", gamma=0.95, samples_per_iteration=1000,
                resample_every=1, max_samples=20_000, n_envs=8, eval_episodes=0, seed=0)
    agent.learn(total_timesteps=8000)
    assert 8000 <= agent.num_timesteps < 8008 and len(agent._data) <= 8000
    score = evaluate(agent, "CartPole-v1", seeds=range(10)).mean
    assert random_mean < 30 and score > 100, (random_mean, score)  # measured: 21.3, 184


def test_sklearn_regressor_gets_a_feature_matrix():
    seen = []

    class Recording(ExtraTreesRegressor):
        def fit(self, X, y, sample_weight=None):
            seen.append(X)
            return super().fit(X, y, sample_weight)

    agent = FQI(Recording(n_estimators=5, random_state=0), "CartPole-v1",
                samples_per_iteration=200, eval_episodes=2, seed=0).learn(n_iterations=2)
    fitted = seen[1:]  # seen[0]: the check of the regressor when the env is set
    assert all(isinstance(X, np.ndarray) and X.ndim == 2 and X.shape[1] == 4 for X in fitted)
    assert sum(len(X) for X in fitted[:2]) == 200
    assert np.isfinite(agent.history[-1]["mean_return"])


def test_object_set_env_with_box_trees():
    """A Sequence-observation game written here: object sets reach the box forest as one
    ObjectSets per batch, and FQI learns to walk toward coins."""
    fitted = []

    class Recording(BoxExtraTreesRegressor):
        def fit(self, X, y, sample_weight=None):
            fitted.append(X)
            return super().fit(X, y, sample_weight)

    forest = Recording(n_estimators=10, n_tests=50, min_samples_split=5, n_jobs=1,
                       view_bounds=(-5, 5, -5, 5))
    agent = FQI(forest, Coins, gamma=0.8, samples_per_iteration=2000, n_envs=20,
                eval_episodes=20, seed=0).learn(n_iterations=4)
    assert all(isinstance(X, ObjectSets) for X in fitted)
    random_score = evaluate(RandomPolicy(Coins, seed=0), Coins, n_episodes=20).mean
    assert agent.history[-1]["mean_return"] > random_score + 0.5, (
        random_score, [r["mean_return"] for r in agent.history])
    obs, _ = Coins().reset(seed=3)
    assert agent.predict(obs)[0] in (0, 1)
    assert make_box_forest(Coins()).view_bounds == (-5.0, 5.0, -5.0, 5.0)
    assert make_grid_ridge(Coins)[0].n_types == 2


class AnyTypes(Coins):
    """Coins whose rows leave the type id unbounded: the view square is still known."""

    def __init__(self):
        super().__init__()
        row = spaces.Box(np.array([-5, -5, 0], dtype=np.float32),
                         np.array([5, 5, np.inf], dtype=np.float32))
        self.observation_space = spaces.Sequence(row, stack=True)


def test_a_forest_needs_only_the_view_square_a_grid_also_the_types():
    assert make_box_forest(AnyTypes).view_bounds == (-5.0, 5.0, -5.0, 5.0)
    with pytest.raises(ValueError, match="unbounded type; give n_types"):
        make_grid_ridge(AnyTypes)
    assert make_grid_ridge(AnyTypes, n_types=3)[0].n_types == 3


def test_a_forest_takes_regions_for_some_types_and_the_view_for_the_others():
    view = (-5.0, 5.0, -5.0, 5.0)
    assert make_box_forest(Coins(), view_bounds={1: 2.0}).view_bounds == {0: view, 1: 2.0}
    # unknown types: only the named ones (the others are drawn where their objects are)
    assert make_box_forest(AnyTypes, view_bounds={1: 2.0}).view_bounds == {1: 2.0}
    assert make_box_forest(view_bounds={1: 2.0}).view_bounds == {1: 2.0}


class MovingCoins(Coins):
    """Coins seen as rows ``[x, y, vx, type]``: every object also has a velocity, here a
    distractor the forest has to do without."""

    def __init__(self):
        super().__init__()
        row = spaces.Box(np.array([-5, -5, -1, 0]), np.array([5, 5, 1, 1]), dtype=np.float32)
        self.observation_space = spaces.Sequence(row, stack=True)

    def _obs(self):
        velocity = self.np_random.uniform(-1, 1, len(self.objects))
        rows = np.column_stack([self.objects[:, :2], velocity, self.objects[:, 2]])
        return rows.astype(np.float32)


def test_objects_of_more_attributes_learn_end_to_end():
    forest = make_box_forest(MovingCoins(), n_estimators=10, n_tests=50, min_samples_split=5,
                             n_jobs=1, random_state=0)
    assert forest.view_bounds == (-5.0, 5.0, -5.0, 5.0, -1.0, 1.0)
    agent = FQI(forest, MovingCoins, gamma=0.8, samples_per_iteration=2000, n_envs=20,
                eval_episodes=20, seed=0).learn(n_iterations=4)
    random_score = evaluate(RandomPolicy(MovingCoins, seed=0), MovingCoins, n_episodes=20).mean
    assert agent.history[-1]["mean_return"] > random_score + 0.5, (
        random_score, [r["mean_return"] for r in agent.history])
    obs, _ = MovingCoins().reset(seed=3)
    padded = np.zeros((8, 5), dtype=np.float32)
    padded[:len(obs), :4], padded[:len(obs), 4] = obs, 1
    assert agent.predict(padded)[0] == agent.predict(obs)[0]
    # the grid lies over the first two attributes
    grid_env = GridObservation(MovingCoins(), n_bins=5)
    assert grid_env.reset(seed=0)[0].shape == (5 * 5 * 2,)
    assert make_grid_ridge(MovingCoins)[0].view_bounds == (-5.0, 5.0, -5.0, 5.0)


def test_an_unbounded_attribute_needs_view_bounds_for_the_forest_not_for_the_grid():
    env = MovingCoins()
    row = spaces.Box(np.array([-5, -5, -np.inf, 0], dtype=np.float32),
                     np.array([5, 5, np.inf, 1], dtype=np.float32))
    env.observation_space = spaces.Sequence(row, stack=True)
    with pytest.raises(ValueError, match="unbounded attributes among the first 3; give view_bounds"):
        make_box_forest(env)
    assert make_grid_ridge(env)[0].view_bounds == (-5.0, 5.0, -5.0, 5.0)


# ---------------------------------------------------------------- vector envs and autoreset
def _plain_rollouts(seeds, policy, n_steps):
    """Per env: the transitions of a plain step-by-step rollout (reset with its seed, then
    reset without one at each episode end, as autoreset does)."""
    rollouts = []
    for tag, seed in enumerate(seeds):
        env, transitions = Countdown(tag), []
        obs, _ = env.reset(seed=seed)
        while len(transitions) < n_steps:
            action = int(policy(obs[None], None, np.array([tag]))[0])
            next_obs, reward, terminated, truncated, _ = env.step(action)
            transitions.append((*obs, action, reward, *next_obs, terminated))
            obs = env.reset()[0] if terminated or truncated else next_obs
        rollouts.append(transitions)
    return rollouts


@pytest.mark.parametrize("mode", list(AutoresetMode), ids=lambda m: m.value)
def test_no_transition_spans_an_episode_boundary(mode):
    """Episodes of 1-5 steps, different in each of 4 envs: the collected transitions of each
    env are exactly a prefix of its plain rollout (no reset step recorded, no transition
    from an episode's end into the next one's start), under every autoreset mode."""
    def policy(obs, q, envs):
        return (obs[:, 1] + obs[:, 2]).astype(int) % 2

    vector = countdowns(4, mode)
    formats = _observation_format(vector.single_observation_space)
    collector = _Collector(vector, formats, np.random.default_rng(0))
    first = collector.collect(37, policy)[0]
    second, steps = collector.collect(50, policy)  # episodes run on across collections
    assert len(first) == 37 and len(second) == 50 and steps >= 50
    seeds = np.random.default_rng(0).integers(2**40, size=4).tolist()
    plain = _plain_rollouts(seeds, policy, 100)
    for data in (first, second):
        assert (data.states[:, 1] == data.next_states[:, 1]).all()  # within one episode
        assert (data.next_states[:, 2] == data.states[:, 2] + 1).all()
    rows = [np.column_stack([d.states, d.actions, d.rewards, d.next_states, d.terminated])
            for d in (first, second)]
    assert rows[0][:, -1].any() and not rows[0][:, -1].all()  # both kinds of episode end
    for tag in range(4):
        expected = np.array(plain[tag], dtype=float)
        mine_first, mine_second = (r[r[:, 0] == tag] for r in rows)
        np.testing.assert_array_equal(mine_first, expected[:len(mine_first)])
        # the second collection goes on where the first stopped, past at most one
        # transition of the first's last step that was beyond its 37 samples
        starts = [start for start in (len(mine_first), len(mine_first) + 1)
                  if np.array_equal(mine_second, expected[start:start + len(mine_second)])]
        assert starts, tag


def test_terminal_targets_do_not_bootstrap_truncated_ones_do():
    """Q(s) = t of the observation: targets are r at a termination and r + gamma * t' at
    every other step, the last step of a truncated episode included."""

    class StepQ(RegressorMixin, BaseEstimator):
        def fit(self, X, y):
            self.X_, self.y_ = X, np.asarray(y)
            return self

        def predict(self, X):
            return np.asarray(X)[:, 2].astype(float)

    agent = FQI(StepQ(), countdowns(6), gamma=0.5, samples_per_iteration=300,
                resample_every=None, eval_episodes=0, seed=1).learn(n_iterations=2)
    data = agent._data
    ends = data.next_states[:, 2] == data.next_states[:, 3]
    assert (ends & data.terminated).any() and (ends & ~data.terminated).any()
    expected = data.rewards + np.where(data.terminated, 0.0, 0.5 * data.next_states[:, 2])
    for action, model in enumerate(agent.q_functions_):
        np.testing.assert_array_equal(model.y_, expected[data.actions == action])


def test_every_env_form():
    made = gym.make("CartPole-v1")
    forms = {
        "id": ("CartPole-v1", "CartPoleVectorEnv"),  # the registered vector entry point
        "env made by gymnasium": (made, "CartPoleVectorEnv"),
        "wrapped env": (gym.wrappers.TransformReward(made, lambda r: 2 * r), "SyncVectorEnv"),
        "env made by hand": (Countdown(), "SyncVectorEnv"),
        "factory": (Countdown, "SyncVectorEnv"),
        "vector env": (gym.make_vec("CartPole-v1", 3, vectorization_mode="sync"),
                       "SyncVectorEnv"),
    }
    for name, (env, kind) in forms.items():
        agent = FQI(classic_forest(), env, samples_per_iteration=60, eval_episodes=2, seed=0)
        assert type(agent.get_env()).__name__ == kind, name
        assert agent.get_env().num_envs == (3 if name == "vector env" else 16), name
        agent.learn(n_iterations=1)
        assert len(agent.history) == 1 and agent.num_timesteps >= 60, name
    doubled = FQI(classic_forest(), forms["wrapped env"][0], samples_per_iteration=64,
                  eval_episodes=0, seed=0).learn(n_iterations=1)
    assert set(np.unique(doubled._data.rewards)) == {2.0}  # the wrapper is kept


@pytest.mark.parametrize("env", [Countdown(), Countdown], ids=["env made by hand", "factory"])
def test_an_agent_on_copies_or_a_factory_pickles_and_learns_on_the_same(env):
    agent = FQI(classic_forest(random_state=0), env, samples_per_iteration=60,
                eval_episodes=2, seed=0).learn(n_iterations=1)
    copy = pickle.loads(pickle.dumps(agent))
    agent.learn(n_iterations=2)
    copy.learn(n_iterations=2)
    assert [r["reward"] for r in copy.history] == [r["reward"] for r in agent.history]
    assert copy.num_timesteps == agent.num_timesteps


def test_a_given_vector_env_is_used_as_it_is():
    vector = gym.make_vec("CartPole-v1", 5, vectorization_mode="sync")
    agent = FQI(classic_forest(), vector, samples_per_iteration=50, eval_episodes=3)
    assert agent.get_env() is vector and agent._eval_env.num_envs == 3  # rebuilt from its spec
    with pytest.raises(ValueError, match="n_envs=4 but the vector env has 5 envs"):
        FQI(classic_forest(), vector, n_envs=4)
    unspecced = countdowns(2)
    with pytest.raises(ValueError, match="give eval_env, or eval_episodes=0"):
        FQI(classic_forest(), unspecced, eval_episodes=2)
    FQI(classic_forest(), unspecced)  # (no evaluation by default)
    FQI(classic_forest(), unspecced, samples_per_iteration=20, eval_env=Countdown).learn(n_iterations=1)
    FQI(classic_forest(), unspecced, samples_per_iteration=20, eval_episodes=0).learn(n_iterations=1)


# ---------------------------------------------------------------- evaluation
def test_evaluate_fixed_seeds_in_any_batch_size():
    """One episode per seed, the same whatever the batch: in one round, in rounds of 2 (the
    last padded), or one env at a time."""
    greedy = FQI(classic_forest(), "CartPole-v1", samples_per_iteration=500, eval_episodes=0,
                 seed=0).learn(n_iterations=2)
    seeds = [7, 8, 9, 10, 11]
    results = [evaluate(greedy, gym.make_vec("CartPole-v1", n, vectorization_mode="sync"),
                        seeds=seeds) for n in (5, 2)]
    singles = [evaluate(greedy, "CartPole-v1", seeds=[seed]).total for seed in seeds[:2]]
    for result in results:
        np.testing.assert_array_equal(result.returns, results[0].returns)
        assert result.seeds == tuple(seeds) and len(result.lengths) == 5
    assert singles == results[0].returns[:2].tolist()
    first = results[0]
    assert first.total == first.returns.sum() and first.mean == first.returns.mean()
    np.testing.assert_array_equal(first.returns, first.lengths)  # CartPole: +1 per step
    default = evaluate(greedy, "CartPole-v1")
    assert len(default.returns) == 10 and default.seeds[0] == 2**40
    with pytest.raises(ValueError, match="n_episodes must be >= 1"):
        evaluate(greedy, "CartPole-v1", n_episodes=0)


def test_evaluate_policy_of_stable_baselines3_on_a_box_env():
    from stable_baselines3.common.evaluation import evaluate_policy

    agent = FQI(classic_forest(), "CartPole-v1", samples_per_iteration=300, eval_episodes=0,
                seed=0).learn(n_iterations=1)
    with pytest.warns(UserWarning, match="Monitor"):
        mean, std = evaluate_policy(agent, gym.make("CartPole-v1"), n_eval_episodes=2)
    assert mean >= 8 and np.isfinite(std)
    obs = np.zeros((3, 4), dtype=np.float32)
    assert agent.predict(obs)[0].shape == (3,) and agent.predict(obs[0])[0] in (0, 1)
    assert agent.q_values(obs).shape == (3, 2)
    with pytest.raises(ValueError, match=r"shape \(3, 5\); expected \(4,\)"):
        agent.predict(np.zeros((3, 5)))


# ---------------------------------------------------------------- SB3 conventions
def test_stable_baselines3_callbacks_are_called_and_can_stop():
    from stable_baselines3.common.callbacks import BaseCallback, CallbackList

    class Recorder(BaseCallback):
        def __init__(self, stop_after=None):
            super().__init__()
            self.stop_after, self.events, self.rewards = stop_after, [], []

        def _on_training_start(self):
            self.events.append("start")

        def _on_step(self):
            self.events.append("step")
            self.rewards.append(self.locals["record"]["reward"])
            assert self.model.num_timesteps == self.num_timesteps
            return self.stop_after is None or self.n_calls < self.stop_after

        def _on_training_end(self):
            self.events.append("end")

    agent = FQI(classic_forest(), "CartPole-v1", samples_per_iteration=100, eval_episodes=1,
                seed=0)
    recorder = Recorder()
    agent.learn(n_iterations=2, callback=recorder)
    assert recorder.events == ["start", "step", "step", "end"] and recorder.model is agent
    assert recorder.rewards == [r["reward"] for r in agent.history]
    assert recorder.training_env is agent.get_env()
    stopper, watcher = Recorder(stop_after=2), Recorder()
    plain = []
    agent.learn(n_iterations=5, callback=CallbackList([stopper, watcher]))
    assert agent.iteration == 4 and watcher.events == ["start", "step", "step", "end"]
    agent.learn(n_iterations=5, callback=[watcher, lambda locals_, globals_: plain.append(1) or False])
    assert agent.iteration == 5 and plain == [1]


@pytest.mark.filterwarnings("ignore:Training and eval env are not of the same type")
def test_stable_baselines3_eval_callback_and_logger():
    """SB3's EvalCallback runs on the agent and logs through `FQI.logger`; an SB3 logger
    given by `set_logger` receives each iteration's record under ``fqi/``."""
    from stable_baselines3.common.callbacks import EvalCallback
    from stable_baselines3.common.logger import KVWriter, Logger

    class Written(KVWriter):
        def __init__(self):
            self.dumps = []

        def write(self, key_values, key_excluded, step=0):
            self.dumps.append((step, dict(key_values)))

    agent = FQI(classic_forest(), "CartPole-v1", samples_per_iteration=100, eval_episodes=1,
                seed=0)
    evaluation = EvalCallback(gym.make("CartPole-v1"), eval_freq=1, n_eval_episodes=2,
                              warn=False, verbose=0)
    agent.learn(n_iterations=2, callback=evaluation)  # it warns that our vector env is not SB3's
    assert evaluation.n_calls == 2 and evaluation.last_mean_reward >= 8
    assert agent.logger.name_to_value == {}  # dumped after each iteration, and by the callback
    written = Written()
    agent.set_logger(Logger(None, [written]))
    agent.learn(n_iterations=1, callback=EvalCallback(gym.make("CartPole-v1"), eval_freq=1,
                                         n_eval_episodes=2, warn=False, verbose=0))
    (step, values), (eval_step, eval_values) = written.dumps
    assert step == eval_step == agent.num_timesteps
    assert values["fqi/iteration"] == 2 and values["fqi/reward"] == agent.history[-1]["reward"]
    assert set(values) == {f"fqi/{key}" for key in agent.history[-1]}
    assert "eval/mean_reward" in eval_values
    assert pickle.loads(pickle.dumps(agent)).logger is not agent.logger  # not pickled
    with pytest.raises(TypeError, match="logger must have record and dump"):
        agent.set_logger(print)


@pytest.mark.filterwarnings("ignore:Training and eval env are not of the same type")
def test_stable_baselines3_stopping_callbacks_end_learn(tmp_path):
    """SB3's way to stop early works as it does with DQN: an EvalCallback every 2 iterations
    whose new best passes a reward threshold stops training at that evaluation, and the
    best agent it saved loads."""
    from stable_baselines3.common.callbacks import EvalCallback, StopTrainingOnRewardThreshold

    agent = FQI(classic_forest(), "CartPole-v1", samples_per_iteration=100, eval_episodes=0,
                seed=0)
    threshold = StopTrainingOnRewardThreshold(reward_threshold=1, verbose=0)
    evaluation = EvalCallback(gym.make("CartPole-v1"), eval_freq=2, n_eval_episodes=2,
                              callback_on_new_best=threshold, best_model_save_path=tmp_path,
                              warn=False, verbose=0)
    agent.learn(n_iterations=6, callback=evaluation)
    assert agent.iteration == 2 and evaluation.best_mean_reward >= 8
    best = FQI.load(tmp_path / "best_model", env="CartPole-v1")
    assert best.iteration == 2 and best.num_timesteps == agent.num_timesteps
    unreachable = StopTrainingOnRewardThreshold(reward_threshold=501, verbose=0)
    agent.learn(n_iterations=3, callback=EvalCallback(
        gym.make("CartPole-v1"), eval_freq=1, n_eval_episodes=2,
        callback_on_new_best=unreachable, warn=False, verbose=0))
    assert agent.iteration == 5


class Closing(Countdown):
    """Counts the `close` calls of its instances."""

    closed = 0

    def close(self):
        Closing.closed += 1


class ClosingBroken(Closing):
    """A `Closing` that raises in `step`."""

    def step(self, action):
        raise RuntimeError("the simulator lost its connection")


def test_evaluate_and_a_failed_set_env_close_the_envs_they_build_and_no_other():
    Closing.closed = 0
    policy = RandomPolicy(Closing(), seed=0)
    evaluate(policy, Closing, seeds=[0, 1, 2])
    assert Closing.closed == 3
    given = SyncVectorEnv([Closing, Closing])
    evaluate(policy, given, seeds=[0, 1, 2])
    assert Closing.closed == 3 and not given.closed
    agent = FQI(classic_forest(), Closing, n_envs=2, samples_per_iteration=20,
                eval_episodes=2)
    assert Closing.closed == 3  # the agent's training and evaluation envs stay open
    old = agent.get_env()
    agent.set_env(given, eval_env=Closing)
    agent.set_env(agent.get_env(), eval_env=Closing)  # its own env again
    assert Closing.closed == 3 and not given.closed and not old.closed  # left as they are
    with pytest.raises(ValueError, match="the agent was made for"):
        agent.set_env(Coins)
    assert agent.get_env() is given and not given.closed
    with pytest.raises(RuntimeError, match="step"):
        agent.set_env(ClosingBroken)  # builds 2 training + 2 evaluation envs, then fails
    assert Closing.closed == 7 and agent.get_env() is given and not given.closed
    agent.learn(n_iterations=1)


def test_save_load_round_trip_on_a_box_env(tmp_path):
    agent = FQI(classic_forest(bootstrap=False), "CartPole-v1", gamma=0.9,
                samples_per_iteration=200, resample_every=1, max_samples=1000,
                leaf_backups=2, exploration_zeta=2.0, n_envs=4, eval_episodes=2,
                seed=3).learn(n_iterations=2)
    agent.save(tmp_path / "agent.joblib")
    loaded = FQI.load(tmp_path / "agent.joblib")
    for name in FQI._param_names():  # every constructor parameter, with no list kept by hand
        assert repr(getattr(loaded, name)) == repr(getattr(agent, name)), name
    obs = np.random.default_rng(0).normal(size=(20, 4)).astype(np.float32)
    np.testing.assert_array_equal(loaded.q_values(obs), agent.q_values(obs))
    np.testing.assert_equal(loaded.history, agent.history)  # (NaN equal to NaN)
    assert loaded.get_env() is not None  # the id
    agent.set_env("CartPole-v1")  # new episodes, as the loaded agent starts
    agent.learn(n_iterations=1)
    loaded.learn(n_iterations=1)  # the same random streams: the same next iteration
    assert loaded.history[-1]["reward"] == agent.history[-1]["reward"]
    np.testing.assert_array_equal(loaded.q_values(obs), agent.q_values(obs))

    countdown = FQI(classic_forest(), Countdown, samples_per_iteration=50,
                    eval_episodes=0).learn(n_iterations=1)
    countdown.save(tmp_path / "countdown.joblib")
    offline = FQI.load(tmp_path / "countdown.joblib", n_jobs=1)
    assert offline.get_env() is None and offline.n_jobs == 1
    assert offline.predict(np.zeros(4, dtype=np.float32))[0] in (0, 1)
    with pytest.raises(ValueError, match="no env"):
        offline.learn(n_iterations=1)
    offline.set_env(Countdown)
    offline.learn(n_iterations=1)
    with pytest.raises(ValueError, match="spaces"):
        FQI.load(tmp_path / "countdown.joblib", env="CartPole-v1")
    with pytest.raises(TypeError, match=r"unknown parameters \['gama'\]"):
        FQI.load(tmp_path / "countdown.joblib", gama=0.9)
    with pytest.raises(ValueError, match="gamma must lie"):
        FQI.load(tmp_path / "countdown.joblib", gamma=2.0)


# ---------------------------------------------------------------- bad envs
class DictObservation(Countdown):
    def __init__(self):
        super().__init__()
        self.observation_space = spaces.Dict({"a": spaces.Box(0, 1, shape=(2,))})


class WideRows(Coins):
    def __init__(self):
        super().__init__()
        self.observation_space = spaces.Sequence(spaces.Box(-1, 1, shape=(5,)))


class NaNRewards(Countdown):
    def step(self, action):
        obs, _, terminated, truncated, info = super().step(action)
        return obs, float("nan"), terminated, truncated, info


class NumberedFromOne(Countdown):
    def __init__(self):
        super().__init__()
        self.action_space = spaces.Discrete(2, start=1)


@pytest.mark.parametrize("env, error, match", [
    ("Pendulum-v1", TypeError, r"needs a Discrete action space .*got Box\(-2.0, 2.0"),
    (DictObservation, TypeError, r"got Dict\('a'.*FlattenObservation"),
    (WideRows, ValueError, r"observation of shape \(\d+, 3\), but the rows of the observation "
                           r"space Sequence\(Box\(-1.0, 1.0, \(5,\).* have 5 numbers"),
    ("FrozenLake-v1", TypeError, r"got Discrete\(16\): wrap the env in .*FlattenObservation"),
    (Broken, RuntimeError, r"\.step raised RuntimeError: the simulator lost its connection "
                           r"\(FQI tries the env once"),
    (NaNRewards, ValueError, r"non-finite rewards \(NaN or inf\)"),
    (NumberedFromOne, ValueError, r"numbered from 0; got Discrete\(2, start=1\)"),
    (42, TypeError, "env must be a registered env id, a gymnasium.Env"),
    (lambda: 42, TypeError, "must return a gymnasium.Env; it returned int"),
])
def test_bad_envs_fail_at_construction(env, error, match):
    with pytest.raises(error, match=match):
        FQI(classic_forest(), env)


def test_an_env_that_fails_later_is_named_with_the_iteration():
    class LateFailure(Countdown):
        def step(self, action):
            if self.episode >= 2:
                raise RuntimeError("the simulator crashed")
            return super().step(action)

    agent = FQI(classic_forest(), LateFailure, samples_per_iteration=500, n_envs=2,
                eval_episodes=0)
    with pytest.raises(RuntimeError, match="the simulator crashed") as excinfo:
        agent.learn(n_iterations=3)
    assert "while FQI collected the transitions of iteration 0" in excinfo.value.__notes__[0]


def test_regressor_is_tried_on_the_env_at_construction():
    with pytest.raises((TypeError, ValueError), match=r"Ridge\(\) failed to fit and predict the env's "
                       r"observations, which FQI gives it as boxtrees.ObjectSets.*"
                       r"pipeline starting with boxtrees.GridCounts"):
        FQI(Ridge(), Coins)
    FQI(Ridge(), "CartPole-v1", eval_episodes=0)  # a feature matrix is fine


@pytest.mark.parametrize("params, error, match", [
    ({"eval_episodes": 3, "eval_seeds": [1, 2]}, ValueError, "eval_episodes=3 but 2 eval_seeds"),
    ({"eval_seeds": [1, -2]}, ValueError, r"eval_seeds\[1\] must be >= 0"),
    ({"eval_seeds": 5}, TypeError, "eval_seeds must be a sequence of ints"),
    ({"eval_episodes": -1}, ValueError, "eval_episodes must be >= 0"),
    ({"n_envs": 0}, ValueError, "n_envs must be >= 1"),
    ({"eval_env": 3}, TypeError, "eval_env must be a registered env id"),
    ({"eval_env": "Acrobot-v1"}, ValueError, "eval_env has the spaces"),
])
def test_bad_evaluation_parameters(params, error, match):
    with pytest.raises(error, match=match):
        FQI(classic_forest(), "CartPole-v1", **params)


# ---------------------------------------------------------------- the package
def test_import_fqi_does_not_import_envs():
    code = "import sys, fqi; print(sorted(m for m in sys.modules if m.split('.')[0] in " \
           "('envs', 'benchmarks')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout
    assert out.strip() == "[]"


def test_fqi_imports_only_boxtrees_of_the_project():
    """architecture.json: the agent may import the trees, never the game or the harness."""
    project = {"boxtrees", "envs", "fqi", "benchmarks"}
    for path in sorted((ROOT / "fqi").glob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names = [node.module]
            else:
                continue
            imported = {name.split(".")[0] for name in names} & project
            assert imported <= {"boxtrees"}, (path.name, imported)


def test_public_names():
    assert sorted(fqi.__all__) == sorted(["FQI", "evaluate", "Evaluation", "RandomPolicy",
                                          "GridObservation", "make_box_forest",
                                          "make_grid_ridge", "CSVLogger", "SetEncoder"])
