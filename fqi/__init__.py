"""Fitted Q-iteration on the ObjectWorld game, stable-baselines3 style, plus baselines.

- `FQI`: the agent (``learn``, ``predict``, ``save`` / ``load``, a CSV log);
- `evaluate`: total greedy reward over 20,000 steps on the fixed reference worlds, for any
  policy with a ``predict`` method (`RandomPolicy`, `envs.GreedyPolicy`, DQN, `FQI`);
- baselines: `make_box_forest` (thesis parameters; ``test_type="classic"``),
  `make_grid_ridge` (``GridCounts`` + ``Ridge``), `GridObservation` (a fixed-size
  observation wrapper) and `train_dqn` (stable-baselines3 DQN on it).
"""
from ._agent import FQI
from ._baselines import DQNResult, make_box_forest, make_grid_ridge, train_dqn
from ._evaluate import RandomPolicy, evaluate
from ._logger import CSVLogger
from ._wrappers import GridObservation

__all__ = ["FQI", "evaluate", "RandomPolicy", "GridObservation", "make_box_forest",
           "make_grid_ridge", "train_dqn", "DQNResult", "CSVLogger"]
