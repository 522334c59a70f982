"""The types of fqi's public signatures: what it plays on, what it fits, what it calls."""
from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, Protocol, TypeAlias

import gymnasium as gym
from gymnasium.vector import VectorEnv

from boxtrees._typing import SetsOrMatrix

__all__ = ["Callback", "CallbackObject", "Dataset", "EnvLike", "EpisodeDataset", "Logger",
           "Observation", "Policy", "Regressor"]

# An env: a registered id, an env, a vector env, or a callable making one env.
EnvLike: TypeAlias = str | gym.Env | VectorEnv | Callable[[], gym.Env]
# One observation or a batch: an array, or object sets (one (n, d + 1) array, a list of them,
# an ObjectSets or any ragged batch).
Observation: TypeAlias = SetsOrMatrix


class Regressor(Protocol):
    """A scikit-learn regressor, as FQI uses it (it also clones it)."""

    def fit(self, X: Any, y: Any, /) -> Any: ...

    def predict(self, X: Any, /) -> Any: ...


class Policy(Protocol):
    """Anything `fqi.evaluate` plays: stable-baselines3's ``predict`` signature."""

    def predict(self, observation: Any, /, *, deterministic: bool) -> tuple[Any, Any]: ...


class Logger(Protocol):
    """The part of a stable-baselines3 ``Logger`` that FQI writes to."""

    def record(self, key: str, value: Any, /) -> object: ...

    def dump(self, step: int) -> object: ...


class CallbackObject(Protocol):
    """The methods of a stable-baselines3 ``BaseCallback`` that `FQI.learn` calls."""

    def init_callback(self, model: Any, /) -> None: ...

    def on_training_start(self, locals_: dict[str, Any], globals_: dict[str, Any], /) -> None: ...

    def update_locals(self, locals_: dict[str, Any], /) -> None: ...

    def on_step(self) -> bool: ...

    def on_training_end(self) -> None: ...


_OneCallback: TypeAlias = (CallbackObject
                           | Callable[[dict[str, Any], dict[str, Any]], bool | None])
Callback: TypeAlias = _OneCallback | Sequence[_OneCallback]


class EpisodeDataset(Protocol):
    """A Minari dataset, as `FQI.learn_offline` reads it."""

    def iterate_episodes(self) -> Iterable[Any]: ...


Dataset: TypeAlias = Mapping[str, Any] | EpisodeDataset
