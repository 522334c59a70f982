"""The public API of boxtrees and fqi as a user calls it, type-checked by
tests/test_typing.py (which runs mypy on this file; it also runs as a script, in a few
seconds). ``assert_type`` pins what calls return, and each ``type: ignore[...]`` marks a call
the annotations must reject: mypy reports an ignore that is not needed (warn_unused_ignores).
"""
import tempfile
from pathlib import Path
from typing import assert_type

import gymnasium as gym
import numpy as np
from sklearn.ensemble import ExtraTreesRegressor
from sklearn.linear_model import Ridge
from sklearn.pipeline import make_pipeline

from boxtrees import (BoxExtraTreeRegressor, BoxExtraTreesClassifier, BoxExtraTreesRegressor,
                      BoxTree, GridCounts, ObjectSets, make_box_regression, region_importance,
                      type_importance)
from fqi import (FQI, CSVLogger, Evaluation, RandomPolicy, evaluate, make_box_forest,
                 make_grid_ridge)

# Object sets: rows [x, y, type]
rng = np.random.default_rng(0)
sets = [np.column_stack([rng.uniform(-3, 3, (k, 2)), rng.integers(0, 2, k)])
        for k in rng.integers(0, 12, 300)]
counts = [float(((np.abs(s[:, :2]).max(1) < 1) & (s[:, 2] == 0)).sum()) for s in sets]

forest = BoxExtraTreesRegressor(10, min_samples_split=5, test_type="bounded", view_bounds=3,
                                column_groups=[(0, 1)], random_state=0)
assert_type(forest.fit(sets, counts), BoxExtraTreesRegressor)
assert_type(forest.predict(sets), np.ndarray)
assert_type(forest.apply(sets), np.ndarray)
indicator, n_nodes_ptr = forest.decision_path(sets[:5])
assert_type(n_nodes_ptr, np.ndarray)
assert_type(forest.feature_importances_, np.ndarray)
assert_type(len(forest), int)
first_tree = forest[0]
print(first_tree.get_depth(), [tree.get_n_leaves() for tree in forest][:3])
score: float = forest.score(sets, counts)

labels = ["yes" if c else "no" for c in counts]
classifier = BoxExtraTreesClassifier(n_estimators=30, class_weight="balanced", oob_score=True,
                                     random_state=0).fit(sets, labels)
assert_type(classifier.predict(sets), np.ndarray)
assert_type(classifier.predict_proba(sets), np.ndarray | list[np.ndarray])

tree = BoxExtraTreeRegressor(min_samples_split=2, random_state=0).fit(sets, counts)
assert_type(tree.tree_, BoxTree)
assert_type(tree.tree_.split_gains(), np.ndarray)
assert_type(tree.get_depth(), int)

# Batches of sets: from a long table, from padded rows, by slicing, joined
frame = {"frame": [7, 7, 9], "x": [0.5, 2.0, 1.0], "y": [1.0, 0.0, 3.0],
         "label": ["car", "person", "car"]}
table = ObjectSets.from_frame(frame, sample="frame", columns=["x", "y"], type="label",
                              samples=[7, 8, 9])
assert_type(table, ObjectSets)
padded = rng.uniform(-3, 3, (4, 6, 3)).round()
batch = ObjectSets.from_padded(np.abs(padded), padded[:, :, 0] > 0)
assert_type(batch[0], np.ndarray)
assert_type(batch[1:], ObjectSets)
assert_type(batch[[0, 2]], ObjectSets)
assert_type(ObjectSets.concatenate([batch, batch[:2]]), ObjectSets)
assert_type(ObjectSets.from_sequence(sets).sizes, np.ndarray)
assert_type(ObjectSets.from_features(np.ones((2, 3))), ObjectSets)
print(forest.predict(batch), forest.predict([np.empty((0, 3))]))

# A feature matrix, a pipeline on the grid counts, the importances
X, y = make_box_regression(300, random_state=0)
assert_type(X, ObjectSets)
grid = GridCounts(4, view_bounds=10).fit(X)
assert_type(grid.transform(X), np.ndarray)
pipeline = make_pipeline(GridCounts(4, view_bounds=10), Ridge()).fit(X, y)
forest.fit(X[:200], y[:200])
by_type = type_importance(forest, X[200:], y[200:], method="drop")
by_region = region_importance(forest, X[200:], y[200:], n_bins=3, extent=10, types=[1])
print(by_type.importances_mean, by_region.importances_mean.shape)

# The agent on a Box env, evaluated; saved and loaded
agent = FQI(ExtraTreesRegressor(n_estimators=5, random_state=0), "CartPole-v1",
            samples_per_iteration=200, resample_every=2, n_envs=1, eval_episodes=2, seed=0)
assert_type(agent.learn(total_timesteps=400), FQI)
agent.learn(n_iterations=1, callback=lambda locals_, globals_: True, progress_bar=False)
action, state = agent.predict(agent.observation_space.sample())
assert_type(agent.q_values(agent.observation_space.sample()), np.ndarray)
print(agent.action_space.n, agent.history[-1]["reward"], agent.num_timesteps)

result = evaluate(agent, "CartPole-v1", n_episodes=2)
assert_type(result, Evaluation)
assert_type(result.total, float)
vector = gym.make_vec("CartPole-v1", 2, vectorization_mode="sync")
assert_type(evaluate(RandomPolicy(vector, seed=0), vector, seeds=[0, 1]).returns, np.ndarray)

x = rng.uniform(-2.4, 2.4, size=(100, 4)).astype(np.float32)
data = {"observations": x, "actions": rng.integers(0, 2, 100), "rewards": np.ones(100),
        "next_observations": x, "terminations": np.abs(x[:, 0]) > 2}
offline = FQI(ExtraTreesRegressor(n_estimators=5), "CartPole-v1", n_envs=1, eval_episodes=0)
assert_type(offline.learn_offline(data, n_iterations=2), FQI)

with tempfile.TemporaryDirectory() as folder:
    agent.save(Path(folder) / "agent.joblib")
    assert_type(FQI.load(Path(folder) / "agent.joblib", n_jobs=1), FQI)
    CSVLogger(Path(folder) / "log.csv").write({"iteration": 0, "reward": 1.0})

# The thesis's regressors, for an env observing object sets (built here from their bounds)
assert_type(make_box_forest(view_bounds=(-10, 10, -10, 10)), BoxExtraTreesRegressor)
assert_type(make_box_forest(view_bounds={1: 2.0, 3: (-4, 4, -2, 6)}), BoxExtraTreesRegressor)
print(make_grid_ridge(view_bounds=(-10, 10, -10, 10), n_types=4)[0].n_bins)


def _rejected() -> None:
    """Calls the annotations reject (never run)."""
    BoxExtraTreesRegressor(test_type="square")  # type: ignore[arg-type]
    forest.fit(sets)  # type: ignore[call-arg]
    ObjectSets.from_frame(frame, sample="frame", columns=["x", "y"])  # type: ignore[call-arg]
    make_box_regression(random_state="seed")  # type: ignore[arg-type]
    agent.learn(total_timesteps="400")  # type: ignore[arg-type]
    evaluate(object(), "CartPole-v1")  # type: ignore[arg-type]
    FQI(ExtraTreesRegressor(), "CartPole-v1", gamma="0.9")  # type: ignore[arg-type]
