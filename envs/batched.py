"""Many ObjectWorlds stepped at once: a gymnasium `VectorEnv` over the numpy engine."""
from numbers import Integral

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ._engine import _Engine
from ._rules import WorldRules
from .object_world import _layout_from_options, _object_space

__all__ = ["BatchedObjectWorld", "RaggedBatch"]


class RaggedBatch:
    """Observations of many worlds: one array of object rows plus offsets.

    World ``i`` observes ``data[offsets[i]:offsets[i + 1]]``. The layout is the one of
    ``boxtrees.ObjectSets``, so a regressor predicts for all worlds in one call.

    Parameters
    ----------
    data : ndarray of float32 of shape (N, 3)
        Rows ``[dx, dy, type]``, world after world.
    offsets : ndarray of intp of shape (n_worlds + 1,)
        Non-decreasing, from 0 to ``N``.

    Examples
    --------
    >>> import numpy as np
    >>> from envs import RaggedBatch
    >>> obs = RaggedBatch(np.zeros((3, 3), np.float32), np.array([0, 1, 1, 3]))
    >>> len(obs), obs[2].shape, obs.sizes.tolist()
    (3, (2, 3), [1, 0, 2])
    """

    __slots__ = ("data", "offsets")

    def __init__(self, data, offsets):
        data = np.ascontiguousarray(data, dtype=np.float32)
        offsets = np.asarray(offsets, dtype=np.intp)
        if data.ndim != 2 or data.shape[1] != 3:
            raise ValueError(f"data must have shape (N, 3), got {data.shape}")
        if (offsets.ndim != 1 or len(offsets) == 0 or offsets[0] != 0
                or offsets[-1] != len(data) or (np.diff(offsets) < 0).any()):
            raise ValueError("offsets must be non-decreasing from 0 to len(data)")
        self.data = data
        self.offsets = offsets

    def __len__(self):
        return len(self.offsets) - 1

    def __getitem__(self, i):
        if not isinstance(i, Integral):
            raise TypeError(f"RaggedBatch indices must be ints, got {type(i).__name__}")
        n = len(self)
        if not -n <= i < n:
            raise IndexError(f"world {i} out of range for {n} worlds")
        i %= n
        return self.data[self.offsets[i]:self.offsets[i + 1]]

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    @property
    def sizes(self):
        """Number of objects each world observes."""
        return np.diff(self.offsets)

    def __repr__(self):
        return f"RaggedBatch(n_worlds={len(self)}, n_objects={len(self.data)})"


def _world_seeds(seed, n):
    """Per-world seeds from `seed`: an int (world i gets seed + i) or n ints."""
    if isinstance(seed, Integral) and not isinstance(seed, bool):
        seeds = [int(seed) + i for i in range(n)]
    else:
        try:
            seeds = list(seed)
        except TypeError:
            raise ValueError(f"seed must be None, an int or a sequence of {n} ints, "
                             f"got {seed!r}") from None
        if len(seeds) != n:
            raise ValueError(f"seed has {len(seeds)} entries for {n} worlds")
    for s in seeds:
        if not isinstance(s, Integral) or isinstance(s, bool) or s < 0:
            raise ValueError(f"world seeds must be non-negative ints, got {s!r}")
    return [int(s) for s in seeds]


def _make_vec(num_envs, **rules):
    """Vector entry point of the registered ids: ``gymnasium.make_vec(id, num_envs)``."""
    return BatchedObjectWorld(num_envs, **rules)


class BatchedObjectWorld(VectorEnv):
    """`n_worlds` ObjectWorlds stepped together by one vectorised numpy engine.

    World ``i`` reset with seed ``s`` and given the same actions goes through exactly the
    transitions of ``ObjectWorldEnv(**rules)`` reset with ``seed=s``: both run the same
    engine, and every world draws its layout and the move noise of the whole episode from
    its own generator at reset.

    Parameters
    ----------
    n_worlds : int
        Number of worlds (``num_envs``).
    **rules
        The keyword arguments of `ObjectWorldEnv` (see `WorldRules`).

    Attributes
    ----------
    num_envs : int
    rules : WorldRules
    n_types : int
    view_size : float
    single_observation_space : gymnasium.spaces.Sequence
        The space of ``obs[i]``.
    single_action_space : gymnasium.spaces.Discrete

    Notes
    -----
    Observations are a `RaggedBatch` (``obs.data``, ``obs.offsets``; ``obs[i]`` is world
    ``i``'s ``(n_i, 3)`` array; ``tuple(obs)`` lies in `observation_space`). Rewards are
    float64 of shape ``(num_envs,)``; episodes never terminate and all worlds are truncated
    together after `max_steps` steps; that step returns the true final observations.
    Autoreset follows gymnasium's next-step mode: the step after a truncation resets every
    world (continuing its generator), ignores the actions and returns zero rewards; calling
    `reset` explicitly instead is equivalent.

    Examples
    --------
    >>> import numpy as np
    >>> from envs import BatchedObjectWorld
    >>> worlds = BatchedObjectWorld(400)
    >>> obs, info = worlds.reset(seed=0)
    >>> obs, rewards, terminated, truncated, info = worlds.step(np.zeros(400, dtype=int))
    >>> len(obs), rewards.shape
    (400, (400,))
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, n_worlds, **rules):
        if not isinstance(n_worlds, Integral) or isinstance(n_worlds, bool) or n_worlds < 1:
            raise ValueError(f"n_worlds must be a positive int, got {n_worlds!r}")
        self.rules = WorldRules(**rules)
        self.num_envs = int(n_worlds)
        self.single_action_space = spaces.Discrete(self.rules.n_actions)
        self.action_space = spaces.MultiDiscrete(np.full(self.num_envs, self.rules.n_actions))
        self.single_observation_space = _object_space(self.rules)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._engine = _Engine(self.rules, self.num_envs)
        self._rngs = None
        self._autoreset = False

    @property
    def n_types(self):
        return self.rules.n_types

    @property
    def view_size(self):
        return self.rules.view_size

    def reset(self, *, seed=None, options=None):
        """Draw a new world in every slot.

        Parameters
        ----------
        seed : None, int or sequence of int, default=None
            An int ``s`` seeds world ``i`` with ``s + i``; a sequence gives one seed per
            world. None continues each world's generator (fresh entropy the first time).
        options : dict, optional
            ``{"objects": rows}`` places the same objects in every world instead of the
            random ones, as in `ObjectWorldEnv.reset`.

        Returns
        -------
        obs : RaggedBatch
        info : dict
        """
        layout = _layout_from_options(options, self.rules)
        if seed is not None:
            self._rngs = [seeding.np_random(s)[0] for s in _world_seeds(seed, self.num_envs)]
        elif self._rngs is None:
            self._rngs = [seeding.np_random()[0] for _ in range(self.num_envs)]
        self._engine.reset(self._rngs, layout)
        self._autoreset = False
        return RaggedBatch(*self._engine.observation), {}

    def step(self, actions):
        """Apply one action per world.

        Parameters
        ----------
        actions : array-like of int of shape (num_envs,)

        Returns
        -------
        obs : RaggedBatch
        rewards : ndarray of float64 of shape (num_envs,)
        terminated, truncated : ndarray of bool of shape (num_envs,)
        info : dict
        """
        actions = self._check_actions(actions)
        if self._engine.observation is None:
            raise RuntimeError("call reset() before step()")
        n = self.num_envs
        if self._autoreset:
            obs, info = self.reset()
            return obs, np.zeros(n), np.zeros(n, dtype=bool), np.zeros(n, dtype=bool), info
        rewards, truncated = self._engine.step(actions)
        self._autoreset = truncated
        return (RaggedBatch(*self._engine.observation), rewards, np.zeros(n, dtype=bool),
                np.full(n, truncated), {})

    def _check_actions(self, actions):
        array = np.asarray(actions)
        if array.shape != (self.num_envs,):
            raise ValueError(f"actions must have shape ({self.num_envs},), one per world; "
                             f"got shape {array.shape}")
        if not np.issubdtype(array.dtype, np.integer):
            raise ValueError(f"actions must be ints, got dtype {array.dtype}")
        n_actions = self.rules.n_actions
        if array.size and (array.min() < 0 or array.max() >= n_actions):
            bad = array[(array < 0) | (array >= n_actions)][0]
            raise ValueError(f"invalid action {bad}: actions must lie in [0, {n_actions})")
        return array.astype(np.intp, copy=False)
