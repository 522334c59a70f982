"""Fitted Q-iteration for any gymnasium env with discrete actions, stable-baselines3 style,
plus the baselines of the thesis.

- `FQI`: the agent (``learn``, ``predict``, ``save`` / ``load``, a CSV log), on ``Box``
  observations (a feature matrix: any scikit-learn regressor) or object sets
  (``Sequence(Box(shape=(d + 1,)))``, rows ``[f_1, ..., f_d, type]``:
  `boxtrees.BoxExtraTreesRegressor`); ``learn_offline`` learns from a fixed data set (a
  mapping of arrays, Minari's or d3rlpy's), its backups and greedy actions kept to the
  actions the data support (``support_threshold``);
- `evaluate`: one greedy episode per fixed reset seed, total and mean return, for any policy
  with a ``predict`` method (`RandomPolicy`, DQN, `FQI`);
- baselines: `make_box_forest` (thesis parameters; ``test_type="classic"``),
  `make_grid_ridge` (``GridCounts`` + ``Ridge``), `GridObservation` (a fixed-size
  observation wrapper, for stable-baselines3 agents) and `SetEncoder` (a stable-baselines3
  features extractor for padded object sets; imported on first use, as it needs torch).

`fqi` talks to its env through gymnasium's API only and knows no particular game.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from ._agent import FQI
from ._baselines import make_box_forest, make_grid_ridge
from ._evaluate import Evaluation, RandomPolicy, evaluate
from ._logger import CSVLogger
from ._wrappers import GridObservation

if TYPE_CHECKING:
    from ._set_encoder import SetEncoder

__all__ = ["FQI", "evaluate", "Evaluation", "RandomPolicy", "GridObservation",
           "make_box_forest", "make_grid_ridge", "CSVLogger", "SetEncoder"]


def __getattr__(name: str) -> type[SetEncoder]:
    if name == "SetEncoder":    # torch is imported only by those who use it
        from ._set_encoder import SetEncoder

        return SetEncoder
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
