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
    """Transitions ``(s, a, r, s', terminated)``, one per sample, in collection order."""

    states: ObjectSets
    actions: np.ndarray
    rewards: np.ndarray
    next_states: ObjectSets
    terminated: np.ndarray

    def __len__(self):
        return len(self.actions)

    def __getitem__(self, index):
        return _Transitions(self.states[index], self.actions[index], self.rewards[index],
                            self.next_states[index], self.terminated[index])

    @classmethod
    def concatenate(cls, parts):
        return cls(ObjectSets.concatenate([p.states for p in parts]),
                   np.concatenate([p.actions for p in parts]),
                   np.concatenate([p.rewards for p in parts]),
                   ObjectSets.concatenate([p.next_states for p in parts]),
                   np.concatenate([p.terminated for p in parts]))


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

    def collect(self, n_samples, policy):
        """Record the first `n_samples` transitions of ``ceil(n_samples / n_worlds)`` steps.

        Parameters
        ----------
        n_samples : int
        policy : callable
            ``policy(obs) -> actions``: one action per world for an ObjectSets of
            observations.

        Returns
        -------
        transitions : _Transitions
        """
        n_worlds = self.env.num_envs
        parts = []
        for _ in range(-(-n_samples // n_worlds)):
            if self._obs is None:
                seeds = self._rng.integers(_TRAINING_SEED_END, size=n_worlds)
                self._obs = _as_object_sets(self.env.reset(seed=seeds.tolist())[0])
            obs = self._obs
            actions = np.asarray(policy(obs), dtype=np.intp)
            next_obs, rewards, terminated, truncated, _ = self.env.step(actions)
            next_obs = _as_object_sets(next_obs)
            parts.append(_Transitions(obs, actions, rewards, next_obs, terminated.copy()))
            if (terminated | truncated).any():  # lockstep worlds: reset them all together
                self._obs = _as_object_sets(self.env.reset()[0])
            else:
                self._obs = next_obs
        return _Transitions.concatenate(parts)[:n_samples]
