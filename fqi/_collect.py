"""Rollouts on many worlds at once, and the transitions they produce."""
from dataclasses import dataclass

import numpy as np

from boxtrees import ObjectSets

from ._observations import _as_object_sets
from ._worlds import _batched_world

__all__ = []

# Training worlds draw their seeds below this (the reference worlds start at 2**40).
_TRAINING_SEED_END = 2**40


@dataclass
class _Transitions:
    """Transitions ``(s, a, r, s', terminated)``, one per sample, in collection order.

    ``next_values`` holds ``max_a Q(s', a)`` under the Q-function that collected them (None
    when unknown); they are the next iteration's bootstrap values for free, and stale as
    soon as Q changes.
    """

    states: ObjectSets
    actions: np.ndarray
    rewards: np.ndarray
    next_states: ObjectSets
    terminated: np.ndarray
    next_values: np.ndarray = None

    def __len__(self):
        return len(self.actions)

    def __getitem__(self, index):
        return _Transitions(self.states[index], self.actions[index], self.rewards[index],
                            self.next_states[index], self.terminated[index],
                            None if self.next_values is None else self.next_values[index])

    @classmethod
    def concatenate(cls, parts):
        values = [p.next_values for p in parts]
        return cls(ObjectSets.concatenate([p.states for p in parts]),
                   np.concatenate([p.actions for p in parts]),
                   np.concatenate([p.rewards for p in parts]),
                   ObjectSets.concatenate([p.next_states for p in parts]),
                   np.concatenate([p.terminated for p in parts]),
                   None if any(v is None for v in values) else np.concatenate(values))


class _Collector:
    """Plays `n_worlds` training worlds in lockstep and records their transitions.

    Episodes run on across calls to `collect`; when the worlds' episodes end (all together:
    `BatchedObjectWorld` truncates every world after ``max_steps``), the worlds are reset,
    each continuing its own generator. The first reset seeds the worlds from `rng` with
    seeds below ``2**40``, so the reference worlds are never trained on.
    """

    def __init__(self, rules, n_worlds, rng):
        self.env = _batched_world(rules, n_worlds)
        self._rng = rng
        self._obs = None

    def collect(self, n_samples, policy, q_values=None):
        """Record the first `n_samples` transitions of ``ceil(n_samples / n_worlds)`` steps.

        Parameters
        ----------
        n_samples : int
        policy : callable
            ``policy(obs, q) -> actions``, one action per world, for an ObjectSets of
            observations and their Q-values ``q = q_values(obs)`` (None without
            `q_values`).
        q_values : callable, default=None
            ``q_values(obs) -> (n_worlds, n_actions)`` array. The Q-values of each step's
            observations serve twice: to act, and as the previous step's next-state values
            (``next_values``); only episode ends and the last step need an extra call.

        Returns
        -------
        transitions : _Transitions
        """
        n_worlds = self.env.num_envs
        parts = []
        pending = None  # the step whose next states are the current observations
        for _ in range(-(-n_samples // n_worlds)):
            if self._obs is None:
                seeds = self._rng.integers(_TRAINING_SEED_END, size=n_worlds)
                self._obs = _as_object_sets(self.env.reset(seed=seeds.tolist())[0])
            obs = self._obs
            q = None if q_values is None else q_values(obs)
            if pending is not None:
                pending.next_values = q.max(axis=1)
            actions = np.asarray(policy(obs, q), dtype=np.intp)
            next_obs, rewards, terminated, truncated, _ = self.env.step(actions)
            part = _Transitions(obs, actions, rewards, _as_object_sets(next_obs),
                                terminated.copy())
            parts.append(part)
            done = bool((terminated | truncated).any())
            # lockstep worlds: reset them all together when an episode ends
            self._obs = _as_object_sets(self.env.reset()[0]) if done else part.next_states
            pending = part if q_values is not None and not done else None
            if q_values is not None and done:
                part.next_values = q_values(part.next_states).max(axis=1)
        if pending is not None:
            pending.next_values = q_values(pending.next_states).max(axis=1)
        return _Transitions.concatenate(parts)[:n_samples]
