"""Double FQI (``FQI(double=True)``): two Q-functions fitted on the two halves of a random
split of the data set, each valuing the actions the other's half chooses at the next states;
with leaf backups, each half's leaves holding its own transitions' targets."""
import numpy as np
import pytest
from sklearn.ensemble import ExtraTreesRegressor
from sklearn.linear_model import Ridge

from fqi._q_function import _crossed, _DoubleQFunction, _QFunction


def test_crossed_values_take_the_other_halfs_value_of_the_own_halfs_best_action():
    first = np.array([[1.0, 5.0, 2.0], [9.0, 0.0, 1.0], [3.0, 4.0, 8.0]])
    second = np.array([[7.0, 0.5, 6.0], [2.0, 3.0, 4.0], [6.0, 1.0, 0.0]])
    split = np.array([True, False, False])
    # row 0 (first half): second at first's argmax (1); rows 1, 2: first at second's argmax
    np.testing.assert_array_equal(_crossed(first, second, split), [0.5, 1.0, 3.0])


def test_each_half_is_fitted_on_its_own_transitions_only(random_transitions):
    data = random_transitions(200, 3, 2)
    targets = np.random.default_rng(1).normal(size=200)
    split = np.random.default_rng(2).random(200) < 0.5
    q = _DoubleQFunction.fit(Ridge(), data, targets, 2, np.random.default_rng(0), None, 3,
                             split)
    assert len(q.models) == 4 and q.iteration == 3
    probe = np.random.default_rng(3).normal(size=(20, 3))
    for half, rows in enumerate((split, ~split)):
        for action in range(2):
            mine = rows & (data.actions == action)
            expected = Ridge().fit(data.states[mine], targets[mine]).predict(probe)
            np.testing.assert_allclose(q.models[2 * half + action].predict(probe), expected)
    both = [half.values(probe) for half in q.halves]
    np.testing.assert_allclose(q.values(probe), (both[0] + both[1]) / 2)
    np.testing.assert_allclose(q.future(data, split=split),
                               _crossed(*(half.values(data.next_states) for half in q.halves),
                                        split))


def test_double_leaf_backups_hold_each_halfs_own_targets(random_transitions):
    data = random_transitions(160, 3, 2)
    rng = np.random.default_rng(1)
    split = rng.random(160) < 0.5
    fitted_on = rng.normal(size=160)
    forest = ExtraTreesRegressor(n_estimators=3, min_samples_split=10, random_state=0)
    q = _DoubleQFunction.fit(forest, data, fitted_on, 2, rng, None, 0, split)
    discounts = np.where(data.terminated, 0.0, 0.9)
    # on the targets the halves were fitted on, a backup is the crossed fitted values
    np.testing.assert_allclose(q.backups(data, fitted_on, discounts, 1, split),
                               data.rewards + discounts * q.future(data, split=split))
    # on others, each half's leaf means of its own transitions' targets, crossed
    targets = rng.normal(size=160)
    halves = []
    for half, rows in zip(q.halves, (split, ~split)):
        own = np.where(rows, targets, np.nan)  # the other half's targets must not count
        future = np.empty((160, 2))
        for action, model in enumerate(half.models):
            mine = rows & (data.actions == action)
            leaves, next_leaves = model.apply(data.states[mine]), model.apply(data.next_states)
            for i in range(160):
                means = [own[mine][leaves[:, t] == next_leaves[i, t]].mean()
                         for t in range(3) if (leaves[:, t] == next_leaves[i, t]).any()]
                future[i, action] = (np.mean(means) if means
                                     else model.predict(data.next_states[i:i + 1])[0])
        halves.append(future)
    np.testing.assert_allclose(q.backups(data, targets, discounts, 1, split),
                               data.rewards + discounts * _crossed(*halves, split))


@pytest.mark.parametrize("leaf_backups", [0, 3])
def test_double_fqi_repeats_with_its_seed_and_differs_from_fqi(cartpole_fqi, leaf_backups):
    obs = np.random.default_rng(0).normal(size=(50, 4))
    first, again, single = (cartpole_fqi(leaf_backups=leaf_backups, double=double)
                            .learn(total_timesteps=1000).q_values(obs)
                            for double in (True, True, False))
    np.testing.assert_array_equal(again, first)
    assert not np.allclose(single, first)
