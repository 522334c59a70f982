"""Fixed data sets of transitions for `FQI.learn_offline`: a mapping of arrays, a Minari
dataset, or d3rlpy's consecutive rows (an ``MDPDataset``, or anything with its arrays)."""
from collections.abc import Mapping

import numpy as np

from ._collect import _Transitions

__all__ = []

_KEYS = ("observations", "actions", "rewards", "next_observations", "terminations")
# Other libraries' names of the end flags (D4RL's and d3rlpy's), read as these.
_ALIASES = {"terminations": "terminals", "truncations": "timeouts"}
# d3rlpy's rows (its MDPDataset's arrays): one step per row, episodes one after the other.
_ROW_KEYS = ("observations", "actions", "rewards", "terminals")


def _dataset_transitions(dataset, observations, observation_space, action_space):
    """The transitions of `dataset` in the agent's formats, checked.

    Parameters
    ----------
    dataset : mapping, minari.MinariDataset, d3rlpy.dataset.MDPDataset or object
        A mapping with ``observations``, ``actions``, ``rewards``, ``next_observations`` and
        ``terminations`` (or D4RL's ``terminals``), and optionally ``truncations`` (or
        ``timeouts``), one entry per transition. Anything with Minari's
        ``iterate_episodes()`` (episodes of ``observations`` one longer than their
        ``actions``, ``rewards``, ``terminations``, ``truncations``). Anything with
        d3rlpy 2's ``episodes`` (each with ``observations``, ``actions``, ``rewards``,
        ``terminated``, one row per step). Or anything with the arrays of d3rlpy's
        ``MDPDataset(observations, actions, rewards, terminals, timeouts)`` as
        attributes (`_row_transitions`). End flags are bools, or numbers 0 and 1.
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
        columns = _checked_mapping(dataset)
    elif hasattr(dataset, "episodes"):
        return _row_transitions(_d3rlpy_episode_rows(dataset), observations, action_space)
    elif all(hasattr(dataset, key) for key in _ROW_KEYS[:3]):
        missing = [key for key in _ROW_KEYS if not hasattr(dataset, key)]
        if missing:
            raise ValueError(f"the dataset lacks {', '.join(missing)}; d3rlpy's rows need "
                             f"{', '.join(_ROW_KEYS)} (and optionally timeouts), one per "
                             f"step")
        rows = {key: getattr(dataset, key) for key in (*_ROW_KEYS, "timeouts")
                if getattr(dataset, key, None) is not None}
        return _row_transitions(rows, observations, action_space)
    else:
        raise TypeError(f"dataset must be a mapping of arrays ({', '.join(_KEYS)}), a Minari "
                        f"dataset or d3rlpy's rows ({', '.join(_ROW_KEYS)}, timeouts); got "
                        f"{type(dataset).__name__}")
    n = len(columns["observations"])
    if n == 0 or len(columns["next_observations"]) != n:
        raise ValueError(f"the dataset has {n} observations and "
                         f"{len(columns['next_observations'])} next observations; it needs the "
                         f"same number, at least one")
    states, next_states = (_observations(columns, key, observations)
                           for key in ("observations", "next_observations"))
    actions, rewards = _actions_rewards(columns, n, action_space)
    terminated = _flags(columns, _named(columns, "terminations"), n)
    if _named(columns, "truncations") in columns:  # bootstrapped through, as online
        _flags(columns, _named(columns, "truncations"), n)
    return _Transitions(states, actions, rewards, next_states, terminated)


def _named(columns, key):
    """The name `columns` give the flags `key`: its other name (`_ALIASES`) if they have
    it, else `key`."""
    alias = _ALIASES.get(key)
    return alias if alias in columns else key


def _checked_mapping(columns):
    """`columns`, a mapping of transitions, checked to hold the keys `_KEYS` (a flag under
    one of its names)."""
    for key, alias in _ALIASES.items():
        if key in columns and alias in columns:
            raise ValueError(f"the dataset has both {key} and {alias}, two names of the "
                             f"same flags; keep one")
    missing = [key for key in _KEYS if _named(columns, key) not in columns]
    if missing:
        raise ValueError(f"the dataset lacks {', '.join(missing)}; a mapping needs "
                         f"{', '.join(_KEYS)} (terminations or terminals; and optionally "
                         f"truncations or timeouts), one entry per transition")
    return columns


def _row_transitions(rows, observations, action_space):
    """The transitions of d3rlpy's rows: one step per row, each episode's rows one after
    the other, ending at a row flagged in ``terminals`` or ``timeouts``.

    A row's next observation is the next row's. A terminal row is a transition that ends
    its episode (nothing bootstraps from its next observation, the row's own here). A
    timeout row, and the data's last row if it ends no episode, holds only the previous
    row's next observation (as d3rlpy reads it): the row before it is a truncated
    transition.

    Parameters
    ----------
    rows : mapping
        ``observations``, ``actions``, ``rewards``, ``terminals`` and optionally
        ``timeouts``, one per row.
    observations : _FeatureRows or _ObjectRows
    action_space : gymnasium.spaces.Discrete

    Returns
    -------
    transitions : _Transitions
    """
    n = len(rows["observations"])
    if n == 0:
        raise ValueError("the dataset has no observations; it needs at least one transition")
    batch = _observations(rows, "observations", observations)
    actions, rewards = _actions_rewards(rows, n, action_space)
    terminals = _flags(rows, "terminals", n)
    timeouts = _flags(rows, "timeouts", n) if "timeouts" in rows else np.zeros(n, dtype=bool)
    timeouts[-1] = True  # the data end every episode
    transitions = np.flatnonzero(terminals | ~timeouts)
    if transitions.size == 0:
        raise ValueError(f"the dataset's {n} rows hold no transition: each ends an episode "
                         f"by a timeout (then it is only the previous row's next "
                         f"observation)")
    next_rows = np.where(terminals[transitions], transitions, transitions + 1)
    return _Transitions(batch[transitions], actions[transitions], rewards[transitions],
                        batch[next_rows], terminals[transitions])


def _d3rlpy_episode_rows(dataset):
    """The episodes of a d3rlpy 2 dataset (its ``episodes``: ``observations``,
    ``actions``, ``rewards``, ``terminated``) as d3rlpy's rows: each episode's last row
    flagged terminal if it terminated, else as a timeout."""
    rows = {key: [] for key in ("observations", "actions", "rewards", "terminals",
                                "timeouts")}
    for episode in dataset.episodes:
        length = len(episode.observations)
        ends = np.zeros(length, dtype=bool)
        ends[-1] = True
        terminated = bool(episode.terminated)
        for key, value in zip(rows, (episode.observations, episode.actions, episode.rewards,
                                     ends & terminated, ends & ~terminated)):
            rows[key].append(np.asarray(value))
    if not rows["actions"]:
        raise ValueError("the dataset holds no episode")
    return {key: np.concatenate(values) for key, values in rows.items()}


def _observations(columns, key, observations):
    """``columns[key]`` as a batch in the agent's format."""
    try:
        return observations.batch(columns[key], f"the dataset's {key} are a batch")
    except (TypeError, ValueError) as error:
        if "the dataset's" in str(error):
            raise
        raise type(error)(f"the dataset's {key}: {error}") from None


def _actions_rewards(columns, n, action_space):
    """The `n` ``actions`` (checked to be the action space's) and ``rewards`` (finite) of
    `columns`."""
    actions = _column(columns, "actions", n, "iu")
    if actions.min() < 0 or actions.max() >= action_space.n:
        raise ValueError(f"the dataset's actions must lie in [0, {action_space.n}) (the action "
                         f"space {action_space}); found {actions.min()} to {actions.max()}")
    rewards = _column(columns, "rewards", n, "biuf").astype(np.float64)
    if not np.isfinite(rewards).all():
        raise ValueError("the dataset's rewards must be finite (no NaN or inf)")
    return actions.astype(np.intp), rewards


def _flags(columns, key, n):
    """``columns[key]``, `n` flags given as bools or as numbers 0 and 1, as bools."""
    values = _column(columns, key, n, "biuf")
    if values.dtype.kind != "b":
        other = values[(values != 0) & (values != 1)]
        if other.size:
            raise ValueError(f"the dataset's {key} must be bools or 0/1 numbers; found "
                             f"{other[0].item()!r}")
    return values.astype(bool)


def _column(columns, key, n, kinds):
    """``columns[key]`` as a flat array of `n` values of a dtype kind in `kinds`."""
    values = np.asarray(columns[key])
    if values.ndim == 2 and values.shape[1] == 1:
        values = values[:, 0]
    if values.shape != (n,):
        raise ValueError(f"the dataset's {key} have shape {values.shape}; expected ({n},), one "
                         f"per observation")
    if values.dtype.kind not in kinds:
        expected = {"iu": "ints", "biuf": "numbers"}[kinds]
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
