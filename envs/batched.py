"""Many ObjectWorlds stepped at once: a gymnasium `VectorEnv` over the numpy engine."""
from numbers import Integral

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ._engine import _Engine
from ._rules import WorldRules, _check_int
from .object_world import (
    _RENDER_MODES, ObjectWorldEnv, _can_render, _check_render, _layout_from_options,
    _object_space, _OwnEpisodeLimit, _render_frame,
)

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
        if data.ndim != 2 or data.shape[1] != 3:
            raise ValueError(f"data must have shape (N, 3), got {data.shape}")
        self.data = data
        self.offsets = _check_offsets(offsets, len(data))

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


def _check_offsets(offsets, n_rows):
    """Offsets of a ragged batch of `n_rows` rows, as intp, checked."""
    offsets = np.asarray(offsets, dtype=np.intp)
    if (offsets.ndim != 1 or len(offsets) == 0 or offsets[0] != 0
            or offsets[-1] != n_rows or (np.diff(offsets) < 0).any()):
        raise ValueError("offsets must be non-decreasing from 0 to len(data)")
    return offsets


class _RaggedBatchSpace(spaces.Tuple):
    """gymnasium's batch of a `Sequence` space, one per world, that holds `RaggedBatch` too.

    A `RaggedBatch` is checked as the tuple of its worlds ``obs[i]``.
    """

    def contains(self, x):
        return super().contains(tuple(x) if isinstance(x, RaggedBatch) else x)


def _world_seeds(seed, n):
    """Per-world seeds from `seed`: None (no world gets one), an int (world i gets seed + i)
    or a sequence of n entries, each an int or None.

    A `seed` that is neither None, an int nor a sequence, or a world seed that is neither
    None nor an int (bools and floats included), raises a TypeError; a sequence of the
    wrong length or a negative seed raises a ValueError.
    """
    if seed is None:
        return [None] * n
    if isinstance(seed, Integral) and not isinstance(seed, bool):
        seeds = [int(seed) + i for i in range(n)]
    else:
        try:
            seeds = list(seed)
        except TypeError:
            raise TypeError(f"seed must be None, an int or a sequence of {n} ints (or "
                            f"Nones), got {seed!r}") from None
        if len(seeds) != n:
            raise ValueError(f"seed has {len(seeds)} entries for {n} worlds")
    for s in seeds:
        if s is not None and (not isinstance(s, Integral) or isinstance(s, bool)):
            raise TypeError(f"world seeds must be None or non-negative ints, got {s!r}")
        if s is not None and s < 0:
            raise ValueError(f"world seeds must be None or non-negative ints, got {s!r}")
    return [None if s is None else int(s) for s in seeds]


def _check_reset_mask(mask, n):
    """``options["reset_mask"]`` as an array of n bools, at least one True: the worlds to reset.

    A mask that is not of bools raises a TypeError; one of another shape, or with no True,
    a ValueError.
    """
    mask = np.asarray(mask)
    if mask.shape != (n,):
        raise ValueError(f"options['reset_mask'] must have shape ({n},), one bool per world; "
                         f"got shape {mask.shape}")
    if mask.dtype != np.bool_:
        raise TypeError(f"options['reset_mask'] must be bools, got dtype {mask.dtype}")
    if not mask.any():
        raise ValueError("options['reset_mask'] resets no world: it needs at least one True")
    return mask


def _make_vec(num_envs, max_episode_steps=None, **kwargs):
    """Vector entry point of the registered ids: ``gymnasium.make_vec(id, num_envs)``.

    gymnasium passes ``max_episode_steps`` to a vector entry point: the one given to
    ``make_vec`` or recorded in the spec it remakes, else the id's registered one, the
    default `max_steps`. It is the `max_steps` rule, which the batched env applies itself;
    a `max_steps` given beside the default wins, another ``max_episode_steps`` must agree.
    """
    if max_episode_steps is not None and max_episode_steps != WorldRules.max_steps:
        max_steps = kwargs.setdefault("max_steps", max_episode_steps)
        if max_steps != max_episode_steps:
            raise ValueError(f"max_episode_steps={max_episode_steps!r} and max_steps="
                             f"{max_steps!r} disagree; both are the episode limit")
    return BatchedObjectWorld(num_envs, **kwargs)


class BatchedObjectWorld(_OwnEpisodeLimit, VectorEnv):
    """`n_worlds` ObjectWorlds stepped together by one vectorised numpy engine.

    World ``i`` reset with seed ``s`` and given the same actions goes through exactly the
    transitions of ``ObjectWorldEnv(**rules)`` reset with ``seed=s``: both run the same
    engine, and every world draws its layout and its move noise from its own generator only.

    Parameters
    ----------
    n_worlds : int
        Number of worlds (``num_envs``).
    render_mode : {None, "rgb_array"}, default=None
    render_view : {"world", "local"}, default="world"
        What `render` draws for each world, as in `ObjectWorldEnv`.
    **rules
        The rule constants of `ObjectWorldEnv` (see `WorldRules`).

    Raises
    ------
    TypeError
        If `n_worlds` is not an int (bools and floats such as ``2.0`` included), or a rule
        constant is not of its type (see `WorldRules`).
    ValueError
        If `n_worlds` is below 1, a rule constant is out of range, or the rendering
        arguments are unknown.

    Attributes
    ----------
    num_envs : int
    rules : WorldRules
    n_types : int
    view_size : float
    single_observation_space : gymnasium.spaces.Sequence
        The space of ``obs[i]``.
    observation_space : gymnasium.spaces.Tuple
        gymnasium's batch of `single_observation_space`, one per world; it holds the
        `RaggedBatch` observations (and the tuples of per-world arrays).
    single_action_space : gymnasium.spaces.Discrete
    np_random_seed : int or tuple of int
        The seed of the last seeded reset of every world: the int ``s`` (world ``i`` got
        ``s + i``), as gymnasium's vector envs record it; after a sequence of seeds or a
        seeded partial reset, the tuple of the seeds the worlds' generators were last
        seeded with. ``np_random`` is seeded with it; the worlds draw from generators of
        their own.

    Notes
    -----
    Observations are a `RaggedBatch` (``obs.data``, ``obs.offsets``; ``obs[i]`` is world
    ``i``'s ``(n_i, 3)`` array; ``obs`` lies in `observation_space`). Rewards are
    float64 of shape ``(num_envs,)``; episodes never terminate and each world is truncated
    after `max_steps` steps of its episode, by the env itself (``spec.max_episode_steps``
    reports it); that step returns the true final observations. Worlds reset together stay
    in step; ``reset(options={"reset_mask": mask})`` resets some of them only, as gymnasium's
    vector envs do.
    Autoreset follows gymnasium's next-step mode: the step after a world's truncation resets
    that world (continuing its generator), ignores its action and returns a zero reward for
    it, while the other worlds step; calling `reset` explicitly instead is equivalent.
    `render` returns a tuple of one frame per world, as gymnasium's vector envs do (drawing
    every world: render few of them).

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

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": _RENDER_MODES,
                "render_fps": 8}

    def __init__(self, n_worlds, render_mode=None, render_view="world", **rules):
        n_worlds = _check_int("n_worlds", n_worlds, 1)
        self.rules = WorldRules(**rules)
        _check_render(render_mode, render_view)
        self.render_mode = render_mode
        self.render_view = render_view
        self.num_envs = int(n_worlds)
        self.single_action_space = spaces.Discrete(self.rules.n_actions)
        self.action_space = spaces.MultiDiscrete(np.full(self.num_envs, self.rules.n_actions))
        self.single_observation_space = _object_space(self.rules)
        self.observation_space = _RaggedBatchSpace(
            batch_space(self.single_observation_space, self.num_envs).spaces)
        self._engine = _Engine(self.rules, self.num_envs)
        self._rngs = None  # each world's generator
        self._seeds = None  # the seed each world's generator was last seeded with
        self._autoreset = np.zeros(self.num_envs, dtype=bool)  # truncated by the last step
        self._placed = False  # whether the worlds hold the objects of options["objects"]

    @property
    def n_types(self):
        """Number of object types the observations can hold (`WorldRules.n_types`).

        Returns
        -------
        n_types : int
            Type ids in every world's observation lie in ``range(n_types)``.
        """
        return self.rules.n_types

    @property
    def view_size(self):
        """Half-side of each world's view square (`WorldRules.view_size`).

        Returns
        -------
        view_size : float
            The local view holds the objects with ``|dx|, |dy| <= view_size``.
        """
        return self.rules.view_size

    def reset(self, *, seed=None, options=None):
        """Draw a new world in every slot, or in the slots of ``options["reset_mask"]``.

        Parameters
        ----------
        seed : None, int or sequence of (int or None), default=None
            An int ``s`` seeds world ``i`` with ``s + i``; a sequence gives one seed per
            world; None (for a world or for all) continues the world's generator. The first
            reset seeds the worlds given none from fresh entropy: world ``i`` with ``e + i``
            for one drawn int ``e``, which ``seed=None`` records as its seed (so
            `np_random_seed` reproduces the reset). With a ``reset_mask``, only the seeds of
            the worlds reset are used, as in gymnasium's vector envs.
        options : dict, optional
            ``{"objects": rows}`` places the same objects in every world instead of the
            random ones, as in `ObjectWorldEnv.reset`. ``{"reset_mask": mask}``, an array of
            ``num_envs`` bools with at least one True, resets only the worlds where `mask`
            is True: the others keep their state and go on with their episodes, and one
            truncated by the last step is still reset by the next (gymnasium's partial
            reset). A partial reset draws random worlds, so it takes no ``"objects"`` and
            needs every world reset before, without ``"objects"``: all worlds hold as many
            objects of each type.

        Returns
        -------
        obs : RaggedBatch
            Every world's observation, the worlds not reset included.
        info : dict

        Raises
        ------
        TypeError
            If `seed` is neither None, an int nor a sequence, a world seed is neither None
            nor an int, or the reset mask is not of bools.
        ValueError
            If a world seed is negative, a sequence does not hold one seed per world,
            `options` is malformed, the reset mask is not of shape ``(num_envs,)`` or resets
            no world, or a partial reset is given ``"objects"`` or follows a reset with
            ``"objects"``.
        RuntimeError
            If a partial reset comes before the first reset.
        """
        n = self.num_envs
        layout = _layout_from_options(options, self.rules, ("objects", "reset_mask"))
        mask = np.ones(n, dtype=bool)
        if options is not None and "reset_mask" in options:
            mask = _check_reset_mask(options["reset_mask"], n)
        if not mask.all():
            self._check_partial_reset(layout)
        seeds = _world_seeds(seed, n)
        if self._rngs is None:  # the first reset gives every world a generator
            entropy = np.random.SeedSequence().entropy
            seed = entropy if seed is None else seed
            seeds = [entropy + i if s is None else s
                     for i, s in enumerate(_world_seeds(seed, n))]
            self._rngs, self._seeds = [None] * n, [None] * n
        seeded = [i for i in np.flatnonzero(mask) if seeds[i] is not None]
        for i in seeded:
            self._rngs[i] = seeding.np_random(seeds[i])[0]
            self._seeds[i] = seeds[i]
        if seeded:
            whole = isinstance(seed, Integral) and mask.all()
            self._np_random_seed = seeds[0] if whole else tuple(self._seeds)
            self._np_random = np.random.default_rng(self._np_random_seed)
        self._reset_worlds(mask, layout)
        self._autoreset &= ~mask
        return RaggedBatch(*self._engine.observation), {}

    def step(self, actions):
        """Apply one action per world.

        A world truncated by the last step is reset instead (next-step autoreset): its
        action is ignored, its reward is 0 and it is not truncated.

        Parameters
        ----------
        actions : array-like of int of shape (num_envs,)

        Returns
        -------
        obs : RaggedBatch
        rewards : ndarray of float64 of shape (num_envs,)
        terminated, truncated : ndarray of bool of shape (num_envs,)
        info : dict

        Raises
        ------
        TypeError
            If the actions are not ints (a float or bool dtype).
        ValueError
            If they are not of shape ``(num_envs,)`` or not in ``[0, n_actions)``.
        RuntimeError
            If `reset` was never called.
        """
        actions = self._check_actions(actions)
        if self._engine.observation is None:
            raise RuntimeError("call reset() before step()")
        n = self.num_envs
        pending = self._autoreset.copy()  # truncated by the last step: reset, not stepped
        live = np.flatnonzero(~pending)
        rewards, truncated = np.zeros(n), np.zeros(n, dtype=bool)
        if len(live) == n:
            rewards, truncated = self._engine.step(actions)
        elif len(live):
            moved = self._engine.take(live)
            rewards[live], truncated[live] = moved.step(actions[live])
            self._engine = self._engine.replaced(live, moved)
        if pending.any():
            self.reset(options={"reset_mask": pending})
        self._autoreset = truncated.copy()
        return (RaggedBatch(*self._engine.observation), rewards, np.zeros(n, dtype=bool),
                truncated, {})

    def render(self):
        """One RGB frame per world (see `ObjectWorldEnv.render`), or None without render_mode.

        Returns
        -------
        frames : tuple of ndarray of uint8 of shape (side, side, 3)
        """
        if not _can_render(self):
            return None
        return tuple(_render_frame(self, i) for i in range(self.num_envs))

    def _reset_worlds(self, mask, layout):
        """Draw new worlds in the slots `mask`, each from its generator; the others go on."""
        if mask.all():
            self._engine.reset(list(self._rngs), layout)
            self._placed = layout is not None
        else:
            worlds = np.flatnonzero(mask)
            fresh = _Engine(self.rules, len(worlds))
            fresh.reset([self._rngs[i] for i in worlds], layout)
            self._engine = self._engine.replaced(worlds, fresh)

    def _check_partial_reset(self, layout):
        """Raise unless some worlds can be reset without the others (see `reset`).

        The engine holds as many objects of each type in every world, so a partial reset
        draws random worlds beside random worlds only.
        """
        if self._rngs is None:
            raise RuntimeError("call reset() on every world before a partial reset "
                               "(options['reset_mask'])")
        if layout is not None:
            raise ValueError("options['objects'] places the objects of every world: reset "
                             "every world with it, not a part (options['reset_mask'])")
        if self._placed:
            raise ValueError("the worlds hold the objects of options['objects']: reset every "
                             "world before resetting a part of them (options['reset_mask'])")

    def _check_actions(self, actions):
        array = np.asarray(actions)
        if array.shape != (self.num_envs,):
            raise ValueError(f"actions must have shape ({self.num_envs},), one per world; "
                             f"got shape {array.shape}")
        if not np.issubdtype(array.dtype, np.integer):
            raise TypeError(f"actions must be ints, got dtype {array.dtype}")
        n_actions = self.rules.n_actions
        if array.size and (array.min() < 0 or array.max() >= n_actions):
            bad = array[(array < 0) | (array >= n_actions)][0]
            raise ValueError(f"invalid action {bad}: actions must lie in [0, {n_actions})")
        return array.astype(np.intp, copy=False)


def _unwrapped_world(env, player):
    """`env` unwrapped, which must be an `ObjectWorldEnv` or a `BatchedObjectWorld`: a
    TypeError naming `player` otherwise."""
    base = getattr(env, "unwrapped", env)
    if not isinstance(base, (ObjectWorldEnv, BatchedObjectWorld)):
        raise TypeError(f"{player} plays an ObjectWorldEnv or a BatchedObjectWorld (possibly "
                        f"wrapped), got {type(env).__name__}; for many worlds use "
                        f"envs.BatchedObjectWorld(n) or gymnasium.make_vec(id, num_envs=n)")
    return base
