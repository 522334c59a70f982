"""`FQI.learn` in stable-baselines3's shape: exact step counts, collection rounds with several
backups each, the backups on fixed trees, the exploration schedule, and the defaults learning
on a small Box env and a small object-set env."""
import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces
from sklearn.ensemble import ExtraTreesRegressor, RandomForestRegressor
from sklearn.linear_model import Ridge
from sklearn.tree import DecisionTreeRegressor

from boxtrees import BoxExtraTreesRegressor
from fqi import FQI, RandomPolicy, evaluate
from fqi._collect import _Transitions
from fqi._q_function import _QFunction


def cartpole_agent(**params):
    settings = dict(n_envs=1, samples_per_iteration=300, resample_every=2, eval_episodes=0,
                    seed=0)
    return FQI(ExtraTreesRegressor(n_estimators=5, random_state=0), "CartPole-v1",
               **{**settings, **params})


def test_total_timesteps_counts_every_transition_in_rounds_with_their_backups():
    agent = cartpole_agent().learn(total_timesteps=1000)
    assert agent.num_timesteps == 1000
    # rounds of 300 steps (the last one 100), each followed by 2 backups on all data kept
    assert [r["new_samples"] for r in agent.history] == [300, 0, 300, 0, 300, 0, 100, 0]
    assert [r["n_samples"] for r in agent.history] == [300, 300, 600, 600, 900, 900, 1000,
                                                       1000]
    assert agent.learn(total_timesteps=500).num_timesteps == 1500  # continues
    several = cartpole_agent(n_envs=4).learn(total_timesteps=1000)
    # the envs step together: a round's last step may go past its count (counted, not kept)
    assert 1000 <= several.num_timesteps < 1004
    assert several.num_timesteps - 4 * 4 < several.history[-1]["n_samples"] <= 1000


def test_the_buffer_keeps_the_latest_transitions():
    agent = cartpole_agent(max_samples=700).learn(total_timesteps=1200)
    assert [r["n_samples"] for r in agent.history][-2:] == [700, 700]
    replaced = cartpole_agent(keep_data=False).learn(total_timesteps=900)
    assert {r["n_samples"] for r in replaced.history} == {300}


def _brute_force_backup(q, data, targets, discounts):
    """One backup on `q`'s trees, leaf by leaf and tree by tree."""
    future = np.empty((len(data), len(q.models)))
    for action, model in enumerate(q.models):
        mine = data.actions == action
        next_leaves = np.asarray(model.apply(data.next_states)).reshape(len(data), -1)
        leaves = (np.asarray(model.apply(data.states[mine])).reshape(mine.sum(), -1)
                  if mine.any() else np.empty((0, next_leaves.shape[1])))
        for i in range(len(data)):
            values = [targets[mine][leaves[:, t] == next_leaves[i, t]].mean()
                      for t in range(leaves.shape[1]) if (leaves[:, t] == next_leaves[i, t]).any()]
            future[i, action] = (np.mean(values) if values
                                 else model.predict(data.next_states[i:i + 1])[0])
    return data.rewards + discounts * future.max(axis=1)


@pytest.mark.parametrize("regressor", [
    ExtraTreesRegressor(n_estimators=4, min_samples_split=10, random_state=0),
    DecisionTreeRegressor(min_samples_leaf=5, random_state=0),
    BoxExtraTreesRegressor(n_estimators=4, test_type="classic", min_samples_split=10,
                           bootstrap=False, random_state=0, n_jobs=1)],
    ids=["extra-trees", "tree", "box"])
def test_backups_on_fixed_trees_recompute_the_leaf_means(regressor):
    rng = np.random.default_rng(0)
    n = 120
    states, next_states = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    actions, rewards = rng.integers(2, size=n), rng.normal(size=n)
    data = _Transitions(states, actions, rewards, next_states, rng.random(n) < 0.2)
    fitted_on = rng.normal(size=n)
    q = _QFunction.fit(regressor, data, fitted_on, 2, rng, None, 0)
    discounts = np.where(data.terminated, 0.0, 0.9)
    # on the targets the trees were fitted on, a backup is the fitted Q-function's own
    np.testing.assert_allclose(q.backups(data, fitted_on, discounts, 1),
                               rewards + discounts * q.values(next_states).max(axis=1))
    # on others, the brute-force leaf means; leaves without data leave each tree's mean
    data = data[:80]  # the last 40 transitions' leaves may now hold none
    targets = rng.normal(size=80)
    once = _brute_force_backup(q, data, targets, discounts[:80])
    np.testing.assert_allclose(q.backups(data, targets, discounts[:80], 1), once)
    np.testing.assert_allclose(q.backups(data, targets, discounts[:80], 2),
                               _brute_force_backup(q, data, once, discounts[:80]))
    only_zero = data[data.actions == 0]  # action 1's trees keep their own predictions
    np.testing.assert_allclose(q.backups(only_zero, only_zero.rewards, 0.9, 1),
                               _brute_force_backup(q, only_zero, only_zero.rewards, 0.9))


def test_leaf_backups_carry_value_further_per_fit():
    """A chain where only the last step pays: on trees that tell its states apart, each
    leaf backup carries the value one more step back."""
    n = 600
    chain = np.tile(np.arange(6.0), n // 6)
    states = np.column_stack([chain, np.zeros((n, 3))])
    data = _Transitions(states, np.zeros(n, dtype=int), (chain == 5).astype(float),
                        states + [1, 0, 0, 0], chain == 5, next_values=np.zeros(n))
    tree = DecisionTreeRegressor()
    agent = cartpole_agent(leaf_backups=3, gamma=0.5)
    agent.n_actions = 1
    agent._q = _QFunction.fit(tree, data, chain, 1, np.random.default_rng(0), None, 0)
    targets = agent._targets(data, None)  # r (Q_{n-1} = 0 on the next states), then 3 backups
    assert targets[:6].tolist() == [0.0, 0.0, 0.125, 0.25, 0.5, 1.0]
    agent.leaf_backups, data.next_values = 0, np.zeros(n)
    assert agent._targets(data, None)[:6].tolist() == [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]


@pytest.mark.parametrize("regressor, error, match", [
    (Ridge(), TypeError, "apply"),
    (RandomForestRegressor(n_estimators=3), ValueError, "mean over its trees"),
    (ExtraTreesRegressor(n_estimators=3, bootstrap=True), ValueError, "without bootstrap")])
def test_leaf_backups_need_a_forest_of_leaf_means(regressor, error, match):
    with pytest.raises(error, match=match):
        FQI(regressor, "CartPole-v1", leaf_backups=2, n_envs=20)
    with pytest.raises(ValueError, match="leaf_backups must be >= 0"):
        cartpole_agent(leaf_backups=-1)


def test_leaf_backups_learn_end_to_end():
    obs = np.random.default_rng(0).normal(size=(50, 4))
    for regressor in (ExtraTreesRegressor(n_estimators=5, random_state=0),
                      BoxExtraTreesRegressor(n_estimators=5, bootstrap=False, n_jobs=1)):
        with_backups, without = (
            FQI(regressor, "CartPole-v1", n_envs=2, samples_per_iteration=300,
                leaf_backups=backups, eval_episodes=0, seed=0).learn(total_timesteps=900)
            for backups in (5, 0))
        assert with_backups.iteration == 15  # 3 rounds of 5 backups
        # the same data (the first round is random play), other targets from the second fit
        first = with_backups.history[0]["collect_reward_per_step"]
        assert first == without.history[0]["collect_reward_per_step"]
        assert not np.allclose(with_backups.q_values(obs), without.q_values(obs))


def test_exploration_falls_as_in_stable_baselines3s_dqn():
    rates = []
    agent = cartpole_agent(samples_per_iteration=250, resample_every=1,
                           exploration_fraction=0.5, exploration_initial_eps=1.0,
                           exploration_final_eps=0.1)
    agent.learn(total_timesteps=1000,
                callback=lambda locals_, globals_: rates.append(locals_["self"].exploration_rate))
    # set before each round from the share of the steps done: 0, 1/4, 1/2, 3/4
    assert rates == pytest.approx([1.0, 0.55, 0.1, 0.1])
    thesis = cartpole_agent(exploration_initial_eps=0.2, exploration_final_eps=0.2)
    thesis.learn(n_iterations=4, callback=lambda l, g: rates.append(l["self"].exploration_rate))
    assert rates[4:] == [0.2] * 4


def _held_actions(agent, q, envs, n_steps):
    """The actions `agent` collects with (`exploration_zeta`) over `n_steps` steps of the
    envs `envs`, as an (n_steps, len(envs)) array."""
    return np.array([agent._behaviour(None, q, envs) for _ in range(n_steps)])


def test_exploration_zeta_holds_random_actions_for_zeta_distributed_durations():
    agent = cartpole_agent(n_envs=3, exploration_zeta=2.0).learn(total_timesteps=300)
    agent._held[:] = 0
    everyone = np.arange(3)
    random = _held_actions(agent, None, everyone, 20_000)  # before any fit: random play
    assert set(np.unique(random)) == {0, 1}
    # an action changes only where a hold ends: holds of mean ~6 steps (zeta(2), capped at
    # 10,000) change it on ~1/12 of the steps, one-step random play on 1/2
    changes = (random[1:] != random[:-1]).mean()
    assert 0.02 < changes < 0.2, changes
    one_step = _held_actions(cartpole_agent(n_envs=3).learn(total_timesteps=300), None,
                             everyone, 2_000)
    assert 0.45 < (one_step[1:] != one_step[:-1]).mean() < 0.55
    # greedy once the holds have ended, with no new hold at epsilon 0
    agent._held[1] = 0
    agent.exploration_rate = 0.0
    q = np.tile([[0.0, 1.0]], (3, 1))
    assert (_held_actions(agent, q, everyone, 50) == 1).all()
    # each env holds its own action, and only the envs that act count their steps down:
    # env 2 holds action 0 for 3 steps, then plays the greedy action 1
    agent._held[:] = [[1, 1, 0], [7, 4, 3]]
    played = _held_actions(agent, q[:1], np.array([2]), 5)
    assert played[:, 0].tolist() == [0, 0, 0, 1, 1]
    np.testing.assert_array_equal(agent._held, [[1, 1, 0], [7, 4, 0]])
    # same seed, same collection
    twice = [cartpole_agent(n_envs=3, exploration_zeta=2.0, exploration_final_eps=0.5)
             .learn(total_timesteps=900) for _ in range(2)]
    assert [r["collect_reward_per_step"] for r in twice[0].history] == [
        r["collect_reward_per_step"] for r in twice[1].history]


def test_the_defaults_learn_cartpole_from_its_feature_vector():
    agent = FQI(ExtraTreesRegressor(n_estimators=10, min_samples_split=10, random_state=0),
                "CartPole-v1", eval_episodes=0, seed=0).learn(total_timesteps=7_500)
    random = evaluate(RandomPolicy("CartPole-v1", seed=0), "CartPole-v1", n_episodes=10).mean
    learned = evaluate(agent, "CartPole-v1", n_episodes=10).mean
    assert random < 30 and learned > 150, (random, learned)  # measured: 22.0, 249.9


class NearestType(gym.Env):
    """Up to 5 objects ``[x, y, type]`` (types 0-2) in ``[-5, 5]^2``; the reward is 1 when
    the action names the type of the object nearest the origin. Episodes of 10 steps."""

    observation_space = spaces.Sequence(spaces.Box(np.array([-5, -5, 0], dtype=np.float32),
                                                   np.array([5, 5, 2], dtype=np.float32)),
                                        stack=True)
    action_space = spaces.Discrete(3)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return self._draw(), {}

    def _draw(self):
        n = int(self.np_random.integers(1, 6))
        self.objects = np.column_stack([self.np_random.uniform(-5, 5, (n, 2)),
                                        self.np_random.integers(0, 3, n)]).astype(np.float32)
        return self.objects

    def step(self, action):
        nearest = self.objects[np.argmin(np.abs(self.objects[:, :2]).max(axis=1)), 2]
        reward = float(action == nearest)
        self.t += 1
        return self._draw(), reward, False, self.t == 10, {}


def test_the_defaults_learn_an_object_set_env():
    agent = FQI(BoxExtraTreesRegressor(n_estimators=10, random_state=0), NearestType,
                eval_episodes=0, seed=0).learn(total_timesteps=5_000)
    seeds = range(50)
    random = evaluate(RandomPolicy(NearestType(), seed=0), NearestType, seeds=seeds).mean
    learned = evaluate(agent, NearestType, seeds=seeds).mean
    assert random < 4.5 and learned > 8, (random, learned)  # of 10; measured: 3.36, 9.3


@pytest.mark.parametrize("call, error, match", [
    (lambda agent: agent.learn(), TypeError, "total_timesteps or n_iterations"),
    (lambda agent: agent.learn(100, n_iterations=2), TypeError, "one of them"),
    (lambda agent: agent.learn(total_timesteps=0), ValueError, "total_timesteps must be >= 1"),
])
def test_learn_takes_steps_or_iterations(call, error, match):
    with pytest.raises(error, match=match):
        call(cartpole_agent())


def test_offline_data_is_learned_by_iterations():
    agent = cartpole_agent(resample_every=None)
    with pytest.raises(ValueError, match="learn\\(n_iterations=...\\)"):
        agent.learn(total_timesteps=100)
    agent.learn(n_iterations=3)
    assert [r["new_samples"] for r in agent.history] == [300, 0, 0]


@pytest.mark.parametrize("tie_break", ["random", "first"])
def test_greedy_ties_are_broken_as_tie_break_says(tie_break):
    agent = cartpole_agent(tie_break=tie_break, exploration_initial_eps=0.0,
                           exploration_final_eps=0.0)
    q = np.array([[1.0, 1.0, 0.5]] * 3000 + [[2.0, 2.0 - 1e-7, 2.0 + 1e-3]] * 3000)
    actions = agent._greedy(q)
    tied, clear = np.bincount(actions[:3000], minlength=3), actions[3000:]
    assert (clear == 2).all()  # a gap above the tolerance is no tie
    if tie_break == "first":
        assert tied.tolist() == [3000, 0, 0]
        return
    assert tied[2] == 0 and abs(tied[0] - 1500) < 150  # uniform over the tied actions
    near = agent._greedy(np.array([[-18.2093042, -18.2093046, -18.2093037]] * 3000))
    assert np.bincount(near, minlength=3).min() > 800  # rounding-close values tie
    # predict stays deterministic: the first of tied actions
    agent.learn(total_timesteps=300)
    agent._q.values = lambda batch, n_jobs: np.ones((len(batch), 2))
    assert (agent.predict(np.zeros((50, 4), dtype=np.float32))[0] == 0).all()
