"""The ObjectWorld game as a gymnasium environment (one world)."""
import copy
from numbers import Integral

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from ._engine import _check_layout, _Engine
from ._render import render_local, render_world
from ._rules import WorldRules

__all__ = ["ObjectWorldEnv"]

_RENDER_MODES = ["rgb_array"]
_RENDER_VIEWS = ("world", "local")


def _object_space(rules):
    """``Sequence(Box, stack=True)`` of agent-relative objects ``[dx, dy, type]``."""
    bound = rules.obs_bound
    row = spaces.Box(low=np.array([-bound, -bound, 0], dtype=np.float32),
                     high=np.array([bound, bound, rules.n_types - 1], dtype=np.float32),
                     dtype=np.float32)
    return spaces.Sequence(row, stack=True)


def _layout_from_options(options, rules, keys=("objects",)):
    """The explicit object layout of ``reset(options={"objects": rows})``, or None.

    `options` must be None or a dict of no keys but `keys`.
    """
    if options is None:
        return None
    if not isinstance(options, dict) or set(options) - set(keys):
        names = " and ".join(repr(key) for key in keys)
        raise ValueError(f"reset options must be None or a dict with the only "
                         f"key{'s' if len(keys) > 1 else ''} {names}, got {options!r}")
    return _check_layout(options["objects"], rules) if "objects" in options else None


def _check_render(render_mode, render_view):
    """Validate the rendering arguments of `ObjectWorldEnv` and `BatchedObjectWorld`."""
    if render_mode is not None and render_mode not in _RENDER_MODES:
        raise ValueError(f"unknown render_mode {render_mode!r}; expected None or one of "
                         f"{_RENDER_MODES}")
    if render_view not in _RENDER_VIEWS:
        raise ValueError(f"unknown render_view {render_view!r}; expected one of "
                         f"{_RENDER_VIEWS}")


def _can_render(env):
    """Whether `env` renders: False (with a warning) without render_mode; an error before reset."""
    if env.render_mode is None:
        gym.logger.warn("render() called without render_mode; pass render_mode='rgb_array'")
        return False
    if env._engine.observation is None:
        raise RuntimeError("call reset() before render()")
    return True


def _render_frame(env, i):
    """The frame of world `i` of `env`'s engine (see `ObjectWorldEnv.render`)."""
    engine = env._engine
    if env.render_view == "local":
        data, offsets = engine.observation
        return render_local(data[offsets[i]:offsets[i + 1]], env.rules)
    return render_world(engine.world_objects(i), engine.agent[i], env.rules)


class _OwnEpisodeLimit:
    """Gives an env's `spec` the env's own episode limit, ``max_episode_steps = max_steps``.

    The env truncates its episodes itself, after ``rules.max_steps`` steps. The spec that
    gymnasium sets on the env (``make``, ``make_vec``) would hold the id's registered
    ``max_episode_steps`` (``make_vec``) or none (``make``, which keeps it for the
    `TimeLimit` it wraps the env in), whatever ``max_steps`` was passed; it reports the
    env's limit instead.
    """

    _spec = None

    @property
    def spec(self):
        """The `EnvSpec` the env was made from (None if built directly), with its limit."""
        return self._spec

    @spec.setter
    def spec(self, spec):
        if spec is not None:
            spec = copy.copy(spec)
            spec.max_episode_steps = self.rules.max_steps
        self._spec = spec


def _check_action(action, n_actions):
    """Return `action` as an int after checking it is a valid action id.

    The actions accepted are those of ``Discrete(n_actions).contains`` except bools. One that
    is not an integer (a float such as ``1.0``, a bool, a str, None, an array of shape other
    than ``()``) raises a TypeError; an integer outside ``[0, n_actions)`` a ValueError.
    """
    is_bool = isinstance(action, (bool, np.bool_))
    if not is_bool and spaces.Discrete(n_actions).contains(action):
        return int(action)
    message = (f"invalid action {action!r}: expected an int in [0, {n_actions}) "
               f"(0 up, 1 right, 2 down, 3 left{', 4-7 swipes' if n_actions == 8 else ''})")
    is_integer = isinstance(action, Integral) or (
        isinstance(action, np.ndarray) and action.shape == ()
        and np.issubdtype(action.dtype, np.integer))
    if is_bool or not is_integer:
        raise TypeError(message)
    raise ValueError(message)


class ObjectWorldEnv(_OwnEpisodeLimit, gym.Env):
    """The thesis's ObjectWorld game: collect money, avoid enemies, don't hit walls.

    The world is the square ``[-size_w, size_w]^2`` with a wall-lined border, filled at reset
    with money (+100 when touched, then removed), walls (-50 when touched; they cancel the
    move), grass (no effect) and enemies (-300 when touched, then removed). Enemies inside
    the agent's view square chase it at `enemy_speed`. Each move goes 1 unit up, right, down
    or left plus uniform noise on each coordinate. With ``sword=True`` four swipes hit the
    ``swipe_size`` square next to the agent: exactly one enemy there: +300 and it dies; two
    or more: -900; none: -750. With ``treasure=True`` a stack of coins lies near the border.

    The rules run on the same vectorised engine as `BatchedObjectWorld`, here over one
    world, so both give identical transitions for the same seeds and actions.

    Parameters
    ----------
    render_mode : {None, "rgb_array"}, default=None
    render_view : {"world", "local"}, default="world"
        What `render` draws: the whole world with the agent's view square, or what the
        agent observes.
    **rules
        The rule constants, see `WorldRules` for their meaning and defaults: `sword`,
        `treasure`, `view`, `size_w`, `n_money`, `n_walls`, `n_grass`, `n_enemies`,
        `enemy_speed`, `contact_radius`, `move_noise`, `swipe_size`, `view_size`,
        `max_steps`, `n_treasure`, `treasure_radius`, `treasure_margin`, `start_clearance`.

    Raises
    ------
    TypeError
        If a rule constant is not of its type (see `WorldRules`), or is unknown.
    ValueError
        If a rule constant is out of range, or the rendering arguments are unknown.

    Attributes
    ----------
    rules : WorldRules
        The validated rule constants.
    n_types : int
        Type ids in observations lie in ``range(n_types)``.
    view_size : float
        Half-side of the view square.

    Notes
    -----
    Observation: a float32 array of shape ``(n, 3)``, one row ``[dx, dy, type]`` per object
    in view (see `WorldRules.view`), positions relative to the agent; space
    ``Sequence(Box(3,), stack=True)``. Actions: ``Discrete(4)``, ``0`` up, ``1`` right,
    ``2`` down, ``3`` left; ``Discrete(8)`` with the sword, ``4..7`` swiping in the same
    directions. Reward: the sum of the step's contacts and swipe. Episodes never terminate;
    they are truncated after `max_steps` steps, by the env itself. The registered ids declare
    the default limit, ``max_episode_steps=50`` (``gymnasium.spec(id)`` reports it), so
    ``gymnasium.make(id)`` wraps the env in a `TimeLimit` at 50 that truncates on the same
    step. gymnasium gives ``max_episode_steps`` to that `TimeLimit` and never to the env, so
    with ``gymnasium.make`` set another length with both, ``max_steps=k`` and
    ``max_episode_steps=k``: alone, a `max_steps` above 50 is cut at 50 by the `TimeLimit`,
    and a ``max_episode_steps`` above `max_steps` is never reached. ``gymnasium.make_vec``
    and the classes take `max_steps` alone; a made env's ``spec.max_episode_steps`` is its
    `TimeLimit`'s, and ``env.unwrapped.spec.max_episode_steps`` its `max_steps`. Each reset
    draws a new world from ``self.np_random``; ``reset(seed=s)`` sets ``np_random_seed`` to
    ``s``.

    Examples
    --------
    >>> import gymnasium as gym
    >>> import envs
    >>> env = gym.make("ObjectWorld-v0")
    >>> obs, info = env.reset(seed=0)
    >>> obs.shape[1], obs.dtype
    (3, dtype('float32'))
    >>> obs, reward, terminated, truncated, info = env.step(1)
    """

    metadata = {"render_modes": _RENDER_MODES, "render_fps": 8}

    def __init__(self, render_mode=None, render_view="world", **rules):
        self.rules = WorldRules(**rules)
        _check_render(render_mode, render_view)
        self.render_mode = render_mode
        self.render_view = render_view
        self.action_space = spaces.Discrete(self.rules.n_actions)
        self.observation_space = _object_space(self.rules)
        self._engine = _Engine(self.rules, 1)

    @property
    def n_types(self):
        """Number of object types the observations can hold (`WorldRules.n_types`).

        Returns
        -------
        n_types : int
            Type ids in observations (column 2) lie in ``range(n_types)``.
        """
        return self.rules.n_types

    @property
    def view_size(self):
        """Half-side of the agent's view square (`WorldRules.view_size`).

        Returns
        -------
        view_size : float
            The local view holds the objects with ``|dx|, |dy| <= view_size``.
        """
        return self.rules.view_size

    def reset(self, *, seed=None, options=None):
        """Draw a new world from ``self.np_random``.

        Parameters
        ----------
        seed : int, optional
            Reseeds ``self.np_random`` first.
        options : dict, optional
            ``{"objects": rows}``: an array of rows ``[x, y, type]`` (world coordinates,
            types `MONEY`, `WALL`, `GRASS`, `ENEMY`) placed instead of the random objects; the
            border walls, the treasure and the move noise are drawn as usual. For scripted
            situations and tests.

        Returns
        -------
        observation : ndarray of float32 of shape (n, 3)
        info : dict
        """
        super().reset(seed=seed)
        self._engine.reset([self.np_random], _layout_from_options(options, self.rules))
        return self._engine.observation[0], {}

    def step(self, action):
        """Apply `action`: move or swipe, then let the enemies chase the agent.

        Parameters
        ----------
        action : int
            An action id in ``[0, n_actions)``: ``0`` up, ``1`` right, ``2`` down, ``3``
            left; with the sword ``4..7`` swipe in the same directions. A numpy integer
            (or a 0-d integer array) is accepted too; bools are not.

        Returns
        -------
        observation : ndarray of float32 of shape (n, 3)
            The objects in view after the step, rows ``[dx, dy, type]``.
        reward : float
            The sum of the step's rewards: contacts (money +100, wall -50, enemy -300) and,
            with the sword, the swipe (+300, -900 or -750).
        terminated : bool
            Always False: the game has no terminal state.
        truncated : bool
            True on step `max_steps` of the episode.
        info : dict
            Empty.

        Raises
        ------
        TypeError
            If `action` is not an integer (a float such as ``1.0``, a bool, a str, None, an
            array of shape other than ``()``).
        ValueError
            If it is an integer outside ``[0, n_actions)``.
        RuntimeError
            If `reset` was never called, or the episode was truncated and not reset since.
        """
        action = _check_action(action, self.rules.n_actions)
        if self._engine.observation is None:
            raise RuntimeError("call reset() before step()")
        if self._engine.t[0] >= self.rules.max_steps:
            raise RuntimeError(f"the episode was truncated after {self.rules.max_steps} steps; "
                               "call reset()")
        rewards, truncated = self._engine.step(np.array([action]))
        return self._engine.observation[0], float(rewards[0]), False, bool(truncated[0]), {}

    def render(self):
        """An RGB frame (uint8, ``(side, side, 3)``) of the world or of the local view."""
        return _render_frame(self, 0) if _can_render(self) else None
