"""Fixed data sets of transitions for `FQI.learn_offline`: a mapping of arrays, or a Minari
dataset."""
from collections.abc import Mapping

import numpy as np

from ._collect import _Transitions

__all__ = []

_KEYS = ("observations", "actions", "rewards", "next_observations", "terminations")


def _dataset_transitions(dataset, observations, observation_space, action_space):
    """The transitions of `dataset` in the agent's formats, checked.

    Parameters
    ----------
    dataset : mapping or minari.MinariDataset
        A mapping with ``observations``, ``actions``, ``rewards``, ``next_observations`` and
        ``terminations`` (and optionally ``truncations``), one entry per transition; or
        anything with Minari's ``iterate_episodes()`` (episodes of ``observations`` one
        longer than their ``actions``, ``rewards``, ``terminations``, ``truncations``).
    observations : _FeatureRows or _ObjectRows
        The agent's reader of its observation space.
    observation_space, action_space : gymnasium.spaces.Space
        The agent's; a Minari dataset's must be equal.

    Returns
    -------
    transitions : _Transitions
    """
    if hasattr(dataset, "iterate_episodes"):
        for name, space in (("observation", observation_space), ("action", action_space)):
            theirs = getattr(dataset, f"{name}_space", space)
            if theirs != space:
                raise ValueError(f"the dataset's {name} space {theirs} is not the agent's "
                                 f"{space}")
        columns = _episode_columns(dataset)
    elif isinstance(dataset, Mapping):
        missing = [key for key in _KEYS if key not in dataset]
        if missing:
            raise ValueError(f"the dataset lacks {', '.join(missing)}; a mapping needs "
                             f"{', '.join(_KEYS)} (and optionally truncations), one entry per "
                             f"transition")
        columns = dataset
    else:
        raise TypeError(f"dataset must be a mapping of arrays ({', '.join(_KEYS)}) or a Minari "
                        f"dataset; got {type(dataset).__name__}")
    n = len(columns["observations"])
    if n == 0 or len(columns["next_observations"]) != n:
        raise ValueError(f"the dataset has {n} observations and "
                         f"{len(columns['next_observations'])} next observations; it needs the "
                         f"same number, at least one")
    states, next_states = (_observations(columns, key, observations)
                           for key in ("observations", "next_observations"))
    actions = _column(columns, "actions", n, "iu")
    if actions.size and (actions.min() < 0 or actions.max() >= action_space.n):
        raise ValueError(f"the dataset's actions must lie in [0, {action_space.n}) (the action "
                         f"space {action_space}); found {actions.min()} to {actions.max()}")
    rewards = _column(columns, "rewards", n, "biuf").astype(np.float64)
    if not np.isfinite(rewards).all():
        raise ValueError("the dataset's rewards must be finite (no NaN or inf)")
    terminated = _column(columns, "terminations", n, "b")
    if "truncations" in columns:  # bootstrapped through, as in online collection
        _column(columns, "truncations", n, "b")
    return _Transitions(states, actions.astype(np.intp), rewards, next_states, terminated)


def _observations(columns, key, observations):
    """``columns[key]`` as a batch in the agent's format."""
    try:
        return observations.batch(columns[key], f"the dataset's {key} are a batch")
    except (TypeError, ValueError) as error:
        if "the dataset's" in str(error):
            raise
        raise type(error)(f"the dataset's {key}: {error}") from None


def _column(columns, key, n, kinds):
    """``columns[key]`` as a flat array of `n` values of a dtype kind in `kinds`."""
    values = np.asarray(columns[key])
    if values.ndim == 2 and values.shape[1] == 1:
        values = values[:, 0]
    if values.shape != (n,):
        raise ValueError(f"the dataset's {key} have shape {values.shape}; expected ({n},), one "
                         f"per observation")
    if values.dtype.kind not in kinds:
        expected = {"iu": "ints", "biuf": "numbers", "b": "bools"}[kinds]
        raise TypeError(f"the dataset's {key} must be {expected}, got dtype {values.dtype}")
    return values


def _episode_columns(dataset):
    """A Minari dataset's episodes as one column per key (each episode's observations split
    into the states and the next states)."""
    columns = {key: [] for key in (*_KEYS, "truncations")}
    for episode in dataset.iterate_episodes():
        observations = episode.observations
        columns["observations"].extend(observations[:-1])
        columns["next_observations"].extend(observations[1:])
        for key in ("actions", "rewards", "terminations", "truncations"):
            columns[key].append(np.asarray(getattr(episode, key)))
    if not columns["actions"]:
        raise ValueError("the dataset holds no episode")
    return {key: (values if key.endswith("observations") else np.concatenate(values))
            for key, values in columns.items()}
