"""FQI with one regressor over observations and actions (``FQI(action_input=...)``): with
True the observation followed by the action's one-hot columns is the regressor's input; a
callable encodes them its own way."""
import pickle

import gymnasium as gym
import numpy as np
import pytest
from sklearn.ensemble import ExtraTreesRegressor
from sklearn.linear_model import LinearRegression

from boxtrees import BoxExtraTreesRegressor, ObjectSets
from fqi import FQI
from fqi._q_function import _ActionInputQFunction, _with_actions


def test_the_input_is_the_observation_then_the_actions_one_hot_columns():
    states = np.array([[0.5, -1.0], [2.0, 3.0]], dtype=np.float32)
    joint = _with_actions(states, np.array([2, 0]), 3)
    np.testing.assert_array_equal(joint, [[0.5, -1.0, 0, 0, 1], [2.0, 3.0, 1, 0, 0]])
    assert joint.dtype == np.float32


def _linear_q(states):
    """A Q-function linear in the state, with an offset per action (3 actions)."""
    return (2 * states[:, :1] - states[:, 1:2]) + np.array([0.0, 1.5, -4.0])


def test_one_regressor_fitted_on_every_transition_values_every_action(random_transitions):
    data = random_transitions(300, 2, 3)
    targets = _linear_q(data.states)[np.arange(300), data.actions]
    q = _ActionInputQFunction.fit(LinearRegression(), data, targets, 3,
                                  np.random.default_rng(0), None, 7, None)
    assert len(q.models) == 1 and q.iteration == 7
    assert q.models[0].n_features_in_ == 2 + 3
    probe = np.random.default_rng(1).normal(size=(20, 2))
    np.testing.assert_allclose(q.values(probe), _linear_q(probe), atol=1e-9)
    np.testing.assert_allclose(q.future(data), _linear_q(data.next_states).max(axis=1),
                               atol=1e-9)


def test_a_q_function_pickled_before_encodings_existed_reads_the_one_hot_columns(
        random_transitions):
    data = random_transitions(100, 2, 3)
    targets = _linear_q(data.states)[np.arange(100), data.actions]
    q = _ActionInputQFunction.fit(LinearRegression(), data, targets, 3,
                                  np.random.default_rng(0), None, 0, None)
    del q.encode      # the attributes an older version pickled
    old = pickle.loads(pickle.dumps(q))
    probe = np.random.default_rng(1).normal(size=(20, 2))
    np.testing.assert_allclose(old.values(probe), _linear_q(probe), atol=1e-9)


def test_leaf_backups_average_every_transitions_targets_in_the_one_forest(random_transitions):
    data = random_transitions(150, 2, 3)
    rng = np.random.default_rng(1)
    fitted_on = rng.normal(size=150)
    forest = ExtraTreesRegressor(n_estimators=3, min_samples_split=10, random_state=0)
    q = _ActionInputQFunction.fit(forest, data, fitted_on, 3, rng, None, 0, None)
    discounts = np.where(data.terminated, 0.0, 0.9)
    # on the targets it was fitted on, a backup is the fitted values' bootstrap
    np.testing.assert_allclose(q.backups(data, fitted_on, discounts, 1),
                               data.rewards + discounts * q.future(data))
    # on others, the leaves' means of the targets of every transition, whatever its action
    targets = rng.normal(size=150)
    model = q.models[0]
    leaves = model.apply(_with_actions(data.states, data.actions, 3))
    future = np.empty((150, 3))
    for action in range(3):
        next_leaves = model.apply(_with_actions(data.next_states, np.full(150, action), 3))
        for i in range(150):
            future[i, action] = np.mean([targets[leaves[:, t] == next_leaves[i, t]].mean()
                                         for t in range(3)])
    np.testing.assert_allclose(q.backups(data, targets, discounts, 1),
                               data.rewards + discounts * future.max(axis=1))


def test_action_input_repeats_with_its_seed_and_differs_from_a_regressor_per_action(
        cartpole_fqi):
    obs = np.random.default_rng(0).normal(size=(50, 4))
    agents = [cartpole_fqi(action_input=joint).learn(total_timesteps=1000)
              for joint in (True, True, False)]
    assert [agent.q_functions_[0].n_features_in_ for agent in agents] == [4 + 2, 4 + 2, 4]
    first, again, per_action = (agent.q_values(obs) for agent in agents)
    assert first.shape == (50, 2)
    np.testing.assert_array_equal(again, first)
    assert not np.allclose(per_action, first)


def test_action_input_needs_feature_vectors_and_no_double(cartpole_fqi, tmp_path):
    with pytest.raises(ValueError, match="double and action_input cannot be combined"):
        cartpole_fqi(action_input=True, double=True)
    objects = gym.spaces.Sequence(gym.spaces.Box(-5.0, 5.0, shape=(3,)))

    class ObjectEnv(gym.Env):
        observation_space, action_space = objects, gym.spaces.Discrete(2)

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            return (np.array([1.0, -2.0, 0.0], dtype=np.float32),), {}

        def step(self, action):
            return (np.array([1.0, -2.0, 0.0], dtype=np.float32),), 0.0, False, False, {}

    with pytest.raises(ValueError, match="action_input=True needs feature-vector"):
        FQI(ExtraTreesRegressor(n_estimators=2), ObjectEnv(), action_input=True,
            eval_episodes=0, n_envs=1)
    # nor can a saved agent on object sets take it up when loaded (without an env)
    agent = FQI(BoxExtraTreesRegressor(n_estimators=2), ObjectEnv(), eval_episodes=0,
                n_envs=1)
    agent.save(tmp_path / "objects.joblib")
    with pytest.raises(ValueError, match="action_input=True needs feature-vector"):
        FQI.load(tmp_path / "objects.joblib", action_input=True)


def test_action_input_learns_offline_from_a_mapping():
    rng = np.random.default_rng(0)
    x = rng.uniform(-2.4, 2.4, size=(500, 4)).astype(np.float32)
    data = {"observations": x, "actions": rng.integers(0, 2, 500), "rewards": np.ones(500),
            "next_observations": x[::-1], "terminations": np.abs(x[:, 0]) > 2}
    agent = FQI(ExtraTreesRegressor(n_estimators=5, random_state=0), "CartPole-v1",
                action_input=True, eval_episodes=0, seed=0)
    agent.learn_offline(data, n_iterations=3)
    (model,) = agent.q_functions_
    assert model.n_features_in_ == 4 + 2 and len(agent.history) == 3
    q = agent.q_values(x[:10])
    one_hot = np.tile(np.float32([0, 1]), (10, 1))
    np.testing.assert_array_equal(q[:, 1], model.predict(np.hstack([x[:10], one_hot])))
    # three fits of a reward of 1 per step: values between 1 and 1 + 0.99 + 0.99 ** 2
    assert (q >= 1 - 1e-9).all() and (q <= 1 + 0.99 + 0.99**2 + 1e-9).all()


def _cartpole_one_hot(states, actions):
    """`action_input=True`'s encoding of CartPole's two actions, as a callable (module-level,
    so that a saved agent pickles it)."""
    return _with_actions(states, actions, 2)


def test_a_callable_action_input_encodes_the_regressors_input(cartpole_fqi, tmp_path):
    obs = np.random.default_rng(0).normal(size=(50, 4)).astype(np.float32)
    joint = cartpole_fqi(action_input=True).learn(total_timesteps=1000)
    encoded = cartpole_fqi(action_input=_cartpole_one_hot).learn(total_timesteps=1000)
    np.testing.assert_array_equal(encoded.q_values(obs), joint.q_values(obs))
    encoded.save(tmp_path / "encoded.joblib")
    loaded = FQI.load(tmp_path / "encoded.joblib")
    assert loaded.action_input is _cartpole_one_hot
    np.testing.assert_array_equal(loaded.q_values(obs), joint.q_values(obs))


class _OneObjectEnv(gym.Env):
    """Object sets of one object, type 0, anywhere in [-5, 5]^2; action 1 pays 1, action 0
    nothing; episodes of one step."""

    observation_space = gym.spaces.Sequence(gym.spaces.Box(-5.0, 5.0, shape=(3,)))
    action_space = gym.spaces.Discrete(2)

    def _observation(self):
        return (np.float32([*self.np_random.uniform(-5, 5, size=2), 0.0]),)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return self._observation(), {}

    def step(self, action):
        return self._observation(), float(action), True, False, {}


def _with_an_action_object(sets, actions):
    """Each set with one more object at the origin, of type ``1 + action``."""
    marks = np.zeros((len(sets), 3), dtype=sets.data.dtype)
    marks[:, 2] = 1 + np.asarray(actions)
    return ObjectSets.from_sequence([np.vstack([rows, mark]) for rows, mark in zip(sets, marks)])


def test_a_callable_action_input_learns_one_model_of_object_sets():
    agent = FQI(BoxExtraTreesRegressor(n_estimators=20, random_state=0), _OneObjectEnv(),
                action_input=_with_an_action_object, gamma=0.5, samples_per_iteration=400,
                n_envs=4, eval_episodes=0, seed=0)
    agent.learn(total_timesteps=800)
    (model,) = agent.q_functions_
    # the one forest tells the actions apart by the objects the encoding added: type 2
    # appears in its input only through the encoding
    assert model.n_types_ == 3
    probe = [np.float32([[x, -x, 0.0]]) for x in np.linspace(-4, 4, 9)]
    q = agent.q_values(probe)
    np.testing.assert_allclose(q[:, 0], 0.0, atol=0.05)
    np.testing.assert_allclose(q[:, 1], 1.0, atol=0.05)


def test_a_bad_action_input_is_refused(cartpole_fqi):
    with pytest.raises(TypeError, match="action_input must be a bool or a callable"):
        cartpole_fqi(action_input="yes")
    with pytest.raises(ValueError, match="double and action_input cannot be combined"):
        cartpole_fqi(action_input=_cartpole_one_hot, double=True)
    with pytest.raises(ValueError, match="must return one input per observation"):
        cartpole_fqi(action_input=lambda states, actions: _cartpole_one_hot(states, actions)[1:])
