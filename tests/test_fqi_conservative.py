"""FQI's offline constraint (``support_threshold``): backups and greedy actions over the
actions the data support; and the data sets offline users have (0/1 flags, D4RL's and
d3rlpy's names, d3rlpy's rows and episodes)."""
import gymnasium as gym
import numpy as np
import pytest
from sklearn.ensemble import ExtraTreesClassifier, ExtraTreesRegressor
from sklearn.linear_model import LinearRegression, Ridge
from sklearn.tree import DecisionTreeClassifier

from fqi import FQI

A, C, B = 0.0, 0.5, 1.0  # the states' one feature


class Chain(gym.Env):
    """State A: action 0 goes to B (reward 0), action 1 ends the episode (reward 1). B:
    every action ends it, reward 0. (C, between them, only appears in the data.)"""

    observation_space = gym.spaces.Box(-1.0, 2.0, shape=(1,))
    action_space = gym.spaces.Discrete(2)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.state = A
        return np.float32([A]), {}

    def step(self, action):
        if self.state == A and action == 0:
            self.state = B
            return np.float32([B]), 0.0, False, False, {}
        return np.float32([self.state]), float(self.state == A), True, False, {}


def chain_data(copies=20):
    """In A both actions; in B only action 0; in C only action 1 (reward 3), which makes a
    linear Q-function of action 1 rise from A (1) through C (3) to B (5): a value the data
    never show, as a regressor extrapolates to an action unseen at a state."""
    rows = [(A, 0, 0.0, B, False), (A, 1, 1.0, A, True), (C, 1, 3.0, C, True),
            (B, 0, 0.0, B, True)] * copies
    states, actions, rewards, next_states, ends = map(np.array, zip(*rows))
    return {"observations": states[:, None].astype(np.float32), "actions": actions,
            "rewards": rewards, "next_observations": next_states[:, None].astype(np.float32),
            "terminations": ends}


def chain_agent(**params):
    return FQI(LinearRegression(), Chain, gamma=0.99, n_envs=1, eval_episodes=0, seed=0,
               **params).learn_offline(chain_data(), n_iterations=3)


@pytest.mark.parametrize("classifier, double", [(None, False),
                                               (DecisionTreeClassifier(), False),
                                               (DecisionTreeClassifier(), True)])
def test_the_constrained_backup_never_bootstraps_on_an_action_unseen_in_a_state(classifier,
                                                                                double):
    free = chain_agent(support_threshold=None, double=double)
    # unconstrained: (A, 0) bootstraps on action 1's extrapolated 5 at B, so A picks 0
    assert free.q_values(np.float32([B]))[1] == pytest.approx(5.0)
    assert free.q_values(np.float32([A]))[0] == pytest.approx(0.99 * 5.0)
    assert free.predict(np.float32([A]))[0] == 0 and free.predict(np.float32([B]))[0] == 1
    assert free.support_model_ is None
    agent = chain_agent(support_classifier=classifier, double=double)  # the default, 0.3
    shares = agent._support.shares(np.float32([[A], [C], [B]]))
    np.testing.assert_allclose(shares, [[0.5, 0.5], [0, 1], [1, 0]], atol=0.15)
    # at B only action 0 is supported: (A, 0) is worth its true 0, and A ends with 1
    assert agent.q_values(np.float32([A]))[0] == pytest.approx(0.0, abs=1e-9)
    assert agent.predict(np.float32([A]))[0] == 1 and agent.predict(np.float32([B]))[0] == 0
    np.testing.assert_array_equal(agent.predict(np.float32([[A], [B], [C]]))[0], [1, 0, 1])
    # the raw Q-values stay the regressor's
    assert agent.q_values(np.float32([B]))[1] == pytest.approx(5.0)
    from fqi import evaluate
    assert evaluate(agent, Chain, n_episodes=2).mean == 1.0
    assert evaluate(free, Chain, n_episodes=2).mean == 0.0


def test_a_threshold_of_zero_supports_every_action():
    agent = chain_agent(support_threshold=0.0)
    assert agent.predict(np.float32([A]))[0] == 0  # as unconstrained


def test_the_support_model_is_saved_and_a_load_can_lift_the_constraint(tmp_path):
    agent = chain_agent(support_classifier=DecisionTreeClassifier())
    agent.save(tmp_path / "agent.joblib")
    loaded = FQI.load(tmp_path / "agent.joblib", env=Chain)
    assert isinstance(loaded.support_model_, DecisionTreeClassifier)
    assert loaded.predict(np.float32([A]))[0] == 1
    free = FQI.load(tmp_path / "agent.joblib", env=Chain, support_threshold=None)
    assert free.predict(np.float32([B]))[0] == 1  # the saved model, unused


def test_online_learning_after_offline_refits_the_support_on_the_grown_data():
    agent = chain_agent(support_classifier=DecisionTreeClassifier())
    first = agent.support_model_
    agent.learn(total_timesteps=50)
    assert agent.support_model_ is not first
    assert agent.support_model_.n_features_in_ == 1 and len(agent._data) > 80
    assert agent._next_supported.shape == (len(agent._data), 2)


def test_cartpole_random_data_support_every_action_almost_everywhere():
    from test_fqi_offline import random_transitions

    data = random_transitions("CartPole-v1", 3000)
    agent = FQI(ExtraTreesRegressor(n_estimators=5, random_state=0), "CartPole-v1",
                eval_episodes=0, seed=0).learn_offline(data, n_iterations=2)
    assert isinstance(agent.support_model_, ExtraTreesClassifier)
    assert agent._next_supported.all(axis=1).mean() > 0.9


def test_where_every_action_is_supported_the_agent_is_the_unconstrained_one():
    """The behaviour model draws its seed from a stream of its own: the Q-functions are the
    very ones fitted without the constraint."""
    from test_fqi_offline import random_transitions

    data = random_transitions("CartPole-v1", 1000)
    states = np.array(data["observations"])
    q = [FQI(ExtraTreesRegressor(n_estimators=5), "CartPole-v1", eval_episodes=0, seed=3,
             support_threshold=threshold).learn_offline(data, n_iterations=3).q_values(states)
         for threshold in (None, 0.0)]
    np.testing.assert_array_equal(*q)


@pytest.mark.parametrize("params, error, match", [
    ({"support_threshold": 1.5}, ValueError, r"support_threshold must lie in \[0.0, 1.0\]"),
    ({"support_threshold": "high"}, TypeError, "support_threshold must be a number"),
    ({"support_classifier": Ridge()}, TypeError,
     "support_classifier must be a classifier with fit and predict_proba methods; Ridge "
     "has no predict_proba"),
])
def test_bad_constraint_parameters_are_named(params, error, match):
    with pytest.raises(error, match=match):
        FQI(LinearRegression(), Chain, eval_episodes=0, **params)


# ---------------------------------------------------------------------------- data sets
def episodes(rng):
    """Three episodes of CartPole-shaped rows: terminated (5 steps), cut by a time limit
    (4), terminated (3); their observations one longer than their steps."""
    return [(rng.normal(size=(length + 1, 4)).astype(np.float32),
             rng.integers(2, size=length), rng.normal(size=length), terminated)
            for length, terminated in ((5, True), (4, False), (3, True))]


def expected_transitions(parts):
    """The 12 transitions of `episodes`, as the mapping `learn_offline` takes."""
    columns = {key: [] for key in ("observations", "next_observations", "actions", "rewards",
                                   "terminations")}
    for observations, actions, rewards, terminated in parts:
        ends = np.zeros(len(actions), dtype=bool)
        ends[-1] = terminated
        for key, value in zip(columns, (observations[:-1], observations[1:], actions, rewards,
                                        ends)):
            columns[key].append(value)
    return {key: np.concatenate(value) for key, value in columns.items()}


class D3rlpyRows:
    """d3rlpy's MDPDataset arrays: one step per row, a terminated episode's last row its
    last step (flagged terminal), a timed-out one's last row only its last next
    observation (flagged timeout); float flags, as d3rlpy keeps them."""

    def __init__(self, parts, drop=()):
        rows = {key: [] for key in ("observations", "actions", "rewards", "terminals",
                                    "timeouts")}
        for observations, actions, rewards, terminated in parts:
            if terminated:  # d3rlpy's next observation after a terminal: unused
                observations = observations[:-1]
            else:
                actions, rewards = np.append(actions, 0), np.append(rewards, 0.0)
            flags = np.zeros(len(actions), dtype=np.float32)
            flags[-1] = 1.0
            for key, value in zip(rows, (observations, actions, rewards,
                                         flags * terminated, flags * (not terminated))):
                rows[key].append(value)
        for key, values in rows.items():
            if key not in drop:
                setattr(self, key, np.concatenate(values))


class D3rlpyEpisode:
    def __init__(self, observations, actions, rewards, terminated):
        self.observations, self.terminated = observations, terminated
        self.actions, self.rewards = actions[:, None], rewards[:, None]  # d3rlpy's (T, 1)


class D3rlpyEpisodes:
    """d3rlpy 2's ReplayBuffer: its episodes, each one row per step, as `D3rlpyRows`."""

    def __init__(self, parts):
        rows = D3rlpyRows(parts)
        ends = np.flatnonzero(rows.terminals + rows.timeouts) + 1
        self.episodes = [D3rlpyEpisode(*(getattr(rows, key)[start:end] for key in (
            "observations", "actions", "rewards")), bool(rows.terminals[end - 1]))
            for start, end in zip([0, *ends[:-1]], ends)]


def learned_data(dataset):
    agent = FQI(ExtraTreesRegressor(n_estimators=2), "CartPole-v1", eval_episodes=0, seed=0)
    return agent.learn_offline(dataset, n_iterations=1)._data


def assert_same_transitions(data, expected):
    np.testing.assert_array_equal(data.states, expected["observations"])
    np.testing.assert_array_equal(data.actions, expected["actions"])
    np.testing.assert_array_equal(data.rewards, expected["rewards"])
    np.testing.assert_array_equal(data.terminated, expected["terminations"])
    live = ~expected["terminations"]  # (nothing bootstraps from a terminal's next state)
    np.testing.assert_array_equal(data.next_states[live], expected["next_observations"][live])


@pytest.mark.parametrize("form", [D3rlpyRows, D3rlpyEpisodes])
def test_d3rlpy_rows_and_episodes_are_read_as_their_transitions(form):
    parts = episodes(np.random.default_rng(0))
    data = learned_data(form(parts))
    assert len(data) == 12
    assert_same_transitions(data, expected_transitions(parts))


def test_d3rlpy_rows_ending_unflagged_end_by_a_timeout():
    parts = episodes(np.random.default_rng(1))
    rows = D3rlpyRows(parts)
    rows.timeouts[-1] = 0.0  # d3rlpy's last, open, episode
    assert_same_transitions(learned_data(rows), expected_transitions(parts))
    rows.terminals, rows.timeouts = rows.terminals.astype(int), rows.timeouts.astype(int)
    assert_same_transitions(learned_data(rows), expected_transitions(parts))
    del rows.timeouts  # optional: the time-limited episode then runs on into the next
    assert len(learned_data(rows)) == 13


@pytest.mark.parametrize("drop, match", [
    ("terminals", "the dataset lacks terminals; d3rlpy's rows need observations, actions, "
                  "rewards, terminals"),
    ("rewards", "dataset must be a mapping of arrays"),
])
def test_d3rlpy_rows_lacking_a_field_are_named(drop, match):
    rows = D3rlpyRows(episodes(np.random.default_rng(0)), drop=(drop,))
    with pytest.raises((ValueError, TypeError), match=match):
        learned_data(rows)


def test_d3rlpy_rows_misaligned_are_named():
    rows = D3rlpyRows(episodes(np.random.default_rng(0)))
    rows.rewards = rows.rewards[:-1]
    with pytest.raises(ValueError, match=r"rewards have shape \(12,\); expected \(13,\)"):
        learned_data(rows)
    rows = D3rlpyRows(episodes(np.random.default_rng(0)))
    rows.terminals, rows.timeouts = np.zeros_like(rows.terminals), np.ones_like(rows.timeouts)
    with pytest.raises(ValueError, match="hold no transition"):
        learned_data(rows)


def test_flags_as_0_1_numbers_and_the_other_names():
    parts = episodes(np.random.default_rng(2))
    expected = expected_transitions(parts)
    for flags in (np.int8, np.float64):
        data = {**expected, "terminations": expected["terminations"].astype(flags),
                "truncations": np.zeros(12, dtype=flags)}
        assert_same_transitions(learned_data(data), expected)
    d4rl = {key: value for key, value in expected.items() if key != "terminations"}
    d4rl.update(terminals=expected["terminations"], timeouts=np.zeros(12, dtype=int))
    assert_same_transitions(learned_data(d4rl), expected)


@pytest.mark.parametrize("change, error, match", [
    (lambda d: d.update(terminations=np.full(12, 2)), ValueError,
     "the dataset's terminations must be bools or 0/1 numbers; found 2"),
    (lambda d: d.update(timeouts=np.full(12, 0.5)), ValueError,
     "the dataset's timeouts must be bools or 0/1 numbers; found 0.5"),
    (lambda d: d.update(truncations=np.zeros(12), timeouts=np.zeros(12)), ValueError,
     "both truncations and timeouts"),
    (lambda d: d.update(terminations=np.array(["no"] * 12)), TypeError,
     "the dataset's terminations must be numbers"),
    (lambda d: d.update(truncations=np.zeros(11)), ValueError,
     r"truncations have shape \(11,\); expected \(12,\)"),
])
def test_bad_flags_are_named(change, error, match):
    data = expected_transitions(episodes(np.random.default_rng(0)))
    change(data)
    with pytest.raises(error, match=match):
        learned_data(data)
