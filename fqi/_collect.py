"""Rollouts on a gymnasium vector env, and the transitions they produce."""
from collections import deque
from dataclasses import dataclass

import numpy as np
from gymnasium.vector import AutoresetMode

from ._envs import _TRAINING_SEED_END, _autoreset_mode, _checked_step, _seeded_reset

__all__ = []

# The training episodes whose mean return is reported (stable-baselines3's
# ``stats_window_size``).
_EPISODES_KEPT = 100


@dataclass
class _Transitions:
    """Transitions ``(s, a, r, s', terminated)``, one per sample, in collection order.

    ``states`` and ``next_states`` are batches in the regressor's format (a float matrix or
    a `boxtrees.ObjectSets`). ``next_values`` holds ``max_a Q(s', a)`` under the Q-function
    that collected them (None when unknown); they are the next iteration's bootstrap values
    for free, and stale as soon as Q changes.
    """

    states: object
    actions: np.ndarray
    rewards: np.ndarray
    next_states: object
    terminated: np.ndarray
    next_values: np.ndarray | None = None

    def __len__(self):
        return len(self.actions)

    def __getitem__(self, index):
        return _Transitions(self.states[index], self.actions[index], self.rewards[index],
                            self.next_states[index], self.terminated[index],
                            None if self.next_values is None else self.next_values[index])

    @classmethod
    def concatenate(cls, parts, join):
        """`parts` joined in order; `join` concatenates their state batches."""
        values = [p.next_values for p in parts]
        return cls(join([p.states for p in parts]), np.concatenate([p.actions for p in parts]),
                   np.concatenate([p.rewards for p in parts]),
                   join([p.next_states for p in parts]),
                   np.concatenate([p.terminated for p in parts]),
                   None if any(v is None for v in values) else np.concatenate(values))


class _Collector:
    """Plays the envs of a gymnasium `VectorEnv` and records their transitions.

    Episodes run on across calls to `collect`, each env at its own pace, and restart through
    the vector env's autoreset (``metadata["autoreset_mode"]``): in gymnasium's ``NEXT_STEP``
    mode the step after an episode's end only resets that env and is not a transition; in
    ``SAME_STEP`` mode the final observation comes from ``info["final_obs"]``; with
    ``DISABLED`` the ended envs are reset through ``reset_mask``. The first reset seeds each
    env with a seed drawn from `rng` below ``2**40``.

    Parameters
    ----------
    env : gymnasium.vector.VectorEnv
    observations : _FeatureRows or _ObjectRows
        Reads the env's observations.
    rng : numpy.random.Generator
    """

    def __init__(self, env, observations, rng):
        self.env = env
        self.observations = observations
        self.mode = _autoreset_mode(env)
        self._rng = rng
        self._obs = None
        self._resetting = None  # NEXT_STEP: the envs whose next step is a reset
        self._returns = np.zeros(env.num_envs)  # of each env's episode so far
        self._ended = deque(maxlen=_EPISODES_KEPT)  # returns of the last episodes that ended

    def mean_episode_return(self):
        """Mean undiscounted return of the last 100 episodes that ended (NaN before one)."""
        return float(np.mean(self._ended)) if self._ended else np.nan

    def collect(self, n_samples, policy, q_values=None):
        """Record the first `n_samples` transitions of the steps it takes to get them.

        Parameters
        ----------
        n_samples : int
        policy : callable
            ``policy(obs, q, envs) -> actions`` for a batch of observations, those of the
            envs that play this step (``envs``: their indices), and their Q-values ``q``
            (None without `q_values`).
        q_values : callable, default=None
            ``q_values(obs) -> (n, n_actions)`` array. In ``NEXT_STEP`` mode the Q-values of
            each step's observations serve twice: to act, and as the previous step's
            next-state values (``next_values``), so only the last step needs an extra call.

        Returns
        -------
        transitions : _Transitions
        n_steps : int
            Transitions taken, including those beyond `n_samples` of the last step.
        """
        n_envs = self.env.num_envs
        reuse = q_values is not None and self.mode is AutoresetMode.NEXT_STEP
        parts, count = [], 0
        pending = None  # (transitions, their envs): next states are the current observations
        while count < n_samples:
            if self._obs is None:
                seeds = self._rng.integers(_TRAINING_SEED_END, size=n_envs).tolist()
                self._obs = self.observations.batch(_seeded_reset(self.env, seeds))
                self._resetting = np.zeros(n_envs, dtype=bool)
                self._returns[:] = 0.0
            obs, live = self._obs, ~self._resetting
            everyone = live.all()
            q = None
            if q_values is not None and (pending is not None or live.any()):
                q = q_values(obs)
            if pending is not None:
                pending[0].next_values = q[pending[1]].max(axis=1)
                pending = None
            actions = np.zeros(n_envs, dtype=np.intp)
            if everyone:
                actions[:] = policy(obs, q, np.arange(n_envs))
            elif live.any():
                actions[live] = policy(obs[live], None if q is None else q[live],
                                       np.flatnonzero(live))
            next_obs, rewards, terminated, truncated = self._step(actions)
            if live.any():
                part = _Transitions(obs, actions, rewards, next_obs, terminated)
                part = part if everyone else part[live]
                parts.append(part)
                count += len(part)
                if reuse:
                    pending = (part, slice(None) if everyone else live)
        if pending is not None:
            pending[0].next_values = q_values(pending[0].next_states).max(axis=1)
        data = _Transitions.concatenate(parts, self.observations.concatenate)
        return data[:n_samples], count

    def _step(self, actions):
        """Step every env; returns the true next states, rewards, terminations and
        truncations, and leaves the observations to act on next in ``self._obs``."""
        obs, rewards, terminated, truncated, info = self.env.step(actions)
        rewards, terminated, truncated = _checked_step(rewards, terminated, truncated,
                                                       self.env.num_envs)
        ended = terminated | truncated
        live = ~self._resetting if self.mode is AutoresetMode.NEXT_STEP else slice(None)
        self._returns[live] += rewards[live]
        self._ended.extend(self._returns[ended])
        self._returns[ended] = 0.0
        self._obs = self.observations.batch(obs)
        next_obs = self._obs
        if self.mode is AutoresetMode.NEXT_STEP:
            self._resetting = ended
        elif ended.any() and self.mode is AutoresetMode.SAME_STEP:
            next_obs = self.observations.replaced(self._obs, ended, info["final_obs"][ended])
        elif ended.any():  # DISABLED: reset the ended envs ourselves
            obs, _ = self.env.reset(options={"reset_mask": ended})
            self._obs = self.observations.batch(obs)
        return next_obs, rewards, terminated, truncated
