"""Rule constants of the ObjectWorld game: type ids, actions, rewards and `WorldRules`.

Everything here is plain data; the dynamics live in `envs._engine`.
"""
import math
from dataclasses import dataclass
from numbers import Integral, Real

import numpy as np

__all__ = [
    "MONEY", "WALL", "GRASS", "ENEMY", "MONEY_MARKER", "TREASURE_MARKER", "ARROW",
    "TYPE_NAMES", "ACTION_NAMES", "VIEWS", "WorldRules", "reference_worlds",
    "REFERENCE_SEED_START",
]

# Object type ids (column 2 of an observation row).
MONEY, WALL, GRASS, ENEMY, MONEY_MARKER, TREASURE_MARKER, ARROW = range(7)
TYPE_NAMES = ("money", "wall", "grass", "enemy", "money_marker", "treasure_marker", "arrow")

# Action ids: four moves, then (sword variant) four swipes in the same directions.
ACTION_NAMES = ("up", "right", "down", "left",
                "swipe_up", "swipe_right", "swipe_down", "swipe_left")
_DIRECTIONS = np.array([[0.0, 1.0], [1.0, 0.0], [0.0, -1.0], [-1.0, 0.0]])

# Rewards of thesis Table 1.1 and section 3.3 (fixed by the thesis, not tunable).
_REWARD_MONEY = 100.0
_REWARD_WALL = -50.0
_REWARD_ENEMY = -300.0
_REWARD_SWIPE_ONE = 300.0
_REWARD_SWIPE_MANY = -900.0
_REWARD_SWIPE_NONE = -750.0

VIEWS = ("local", "global", "minimap", "arrow")

# Reference (evaluation) worlds use seeds from here on; see `reference_worlds`.
REFERENCE_SEED_START = 2**40


def reference_worlds(n=400):
    """Seeds of the fixed evaluation worlds, disjoint from any seed training uses.

    The seeds are ``REFERENCE_SEED_START + arange(n)`` with ``REFERENCE_SEED_START = 2**40``.
    Training must draw its world seeds below ``2**40``: resetting with ``seed=None`` (the
    generators' own streams), with seeds from ``rng.integers(2**32)``, or with small
    literal seeds all stay clear of them.

    Parameters
    ----------
    n : int, default=400
        Number of worlds; 400 episodes of 50 steps are the thesis's 20,000 evaluation steps.

    Returns
    -------
    seeds : list of int
        Pass them to ``BatchedObjectWorld(n).reset(seed=seeds)``, or one at a time to
        ``ObjectWorldEnv.reset(seed=s)``.

    Raises
    ------
    TypeError
        If `n` is not an int (bools and floats such as ``2.0`` included).
    ValueError
        If `n` is negative.
    """
    if not isinstance(n, Integral) or isinstance(n, bool):
        raise TypeError(f"n must be a non-negative int, got {n!r}")
    if n < 0:
        raise ValueError(f"n must be a non-negative int, got {n!r}")
    return [REFERENCE_SEED_START + i for i in range(int(n))]


def _check_int(name, value, low):
    """`value` as an int ``>= low``.

    As scikit-learn's parameter checks: a value that is not an int (a float such as 1.5 or
    even 2.0, a bool, a str) raises a TypeError; an int below `low` raises a ValueError.
    """
    if not isinstance(value, Integral) or isinstance(value, bool):
        raise TypeError(f"{name} must be an int, got {value!r}")
    if value < low:
        raise ValueError(f"{name} must be >= {low}, got {value}")
    return int(value)


def _check_float(name, value, low, high=math.inf, low_inclusive=True):
    """`value` as a float in ``[low, high]`` (``(low, high]`` unless `low_inclusive`).

    A value that is not a real number (a bool, a str, None) raises a TypeError; NaN, an
    infinity or a number out of range raises a ValueError.
    """
    if not isinstance(value, Real) or isinstance(value, bool):
        raise TypeError(f"{name} must be a finite number, got {value!r}")
    if not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    if value < low or (value == low and not low_inclusive) or value > high:
        bound = "[" if low_inclusive else "("
        raise ValueError(f"{name} must lie in {bound}{low}, {high}], got {value}")
    return float(value)


@dataclass(frozen=True)
class WorldRules:
    """Every rule constant of the ObjectWorld game, validated.

    `ObjectWorldEnv(**rules)` and `BatchedObjectWorld(n_worlds, **rules)` take these fields as
    keyword arguments. The defaults are the thesis game (section 1.2) with the constants the
    thesis leaves open calibrated so that the uniform random policy scores about -5 per step
    (see docs/game.md, section "Calibration").

    Parameters
    ----------
    sword : bool, default=False
        Add the four swipe actions (thesis 3.3): ``Discrete(8)`` instead of ``Discrete(4)``.
    treasure : bool, default=False
        Add a stack of `n_treasure` coins near a random border (thesis 3.2.1).
    view : {"local", "global", "minimap", "arrow"}, default="local"
        What the agent observes. ``"local"``: the objects with ``|dx|, |dy| <= view_size``.
        ``"global"``: every object of the world. ``"minimap"``: the local view plus one
        `MONEY_MARKER` per unvisited view-sized cell holding money and one `TREASURE_MARKER`
        for the treasure's cell until visited, at the cell centre's agent-relative position
        scaled by ``view_size / (2 * size_w)`` (a compact agent-centred minimap inside the
        view). ``"arrow"``: the local view plus one `ARROW` object at distance
        ``0.9 * view_size`` from the agent in the direction of the treasure. ``"minimap"``
        and ``"arrow"`` need ``treasure=True``.
    size_w : float, default=30.0
        The world is the square ``[-size_w, size_w]^2``, its border lined with walls at most
        1 unit apart; the agent starts at the centre.
    n_money, n_walls, n_grass, n_enemies : int, defaults 40, 30, 30, 13
        Numbers of objects spawned uniformly in the world (walls besides the border).
    enemy_speed : float, default=0.2
        Distance per step that an enemy inside the agent's view square moves toward the
        agent (the agent moves 1). 0 gives static enemies.
    contact_radius : float, default=0.6
        An object is touched when it lies within this distance of the agent's path from its
        old to its new position (so a move can neither skip an object nor slip between two
        border walls, which needs at least 0.5), or, for an enemy, of the agent after the
        enemy's move.
    move_noise : float, default=0.1
        A move adds noise uniform in ``[-move_noise, move_noise]`` to each coordinate.
    swipe_size : float, default=3.0
        A swipe hits the ``swipe_size x swipe_size`` square adjacent to the agent on that side.
    view_size : float, default=10.0
        Half-side of the agent's view square; enemies inside it chase the agent.
    max_steps : int, default=50
        Episodes are truncated after this many steps.
    n_treasure : int, default=20
        Coins in the treasure stack (``treasure=True`` only).
    treasure_radius : float, default=1.0
        The coins lie uniformly in the disc of this radius around the stack's centre.
    treasure_margin : float, default=3.0
        The stack's centre lies this far inside a random border side.
    start_clearance : float, default=1.5
        No object spawns within this distance of the agent's start (the centre); at least
        `contact_radius`, so that the agent never starts touching a wall.

    Attributes
    ----------
    n_actions : int
        4, or 8 with the sword.
    n_types : int
        Type ids of observed objects lie in ``range(n_types)``: 4, 6 (minimap) or 7 (arrow).
    obs_bound : float
        Bound on ``|dx|`` and ``|dy|`` of observed objects.

    Raises
    ------
    TypeError
        If a constant is not of its type: `sword` and `treasure` bools, the counts and
        `max_steps` ints (not bools, not floats such as ``1.5`` or ``2.0``), the other
        constants real numbers (not bools).
    ValueError
        If a constant is out of its range (a negative count, ``max_steps < 1``, NaN or an
        infinite size, ...), `view` is unknown, or ``view="minimap"`` or ``"arrow"`` is
        asked for without ``treasure=True``.
    """

    sword: bool = False
    treasure: bool = False
    view: str = "local"
    size_w: float = 30.0
    n_money: int = 40
    n_walls: int = 30
    n_grass: int = 30
    n_enemies: int = 13
    enemy_speed: float = 0.2
    contact_radius: float = 0.6
    move_noise: float = 0.1
    swipe_size: float = 3.0
    view_size: float = 10.0
    max_steps: int = 50
    n_treasure: int = 20
    treasure_radius: float = 1.0
    treasure_margin: float = 3.0
    start_clearance: float = 1.5

    def __post_init__(self):
        checked = {}
        for name in ("sword", "treasure"):
            value = getattr(self, name)
            if not isinstance(value, (bool, np.bool_)):
                raise TypeError(f"{name} must be a bool, got {value!r}")
            checked[name] = bool(value)
        if self.view not in VIEWS:
            raise ValueError(f"unknown view {self.view!r}; expected one of {VIEWS}")
        if self.view in ("minimap", "arrow") and not self.treasure:
            raise ValueError(f"view={self.view!r} shows the treasure and needs treasure=True")
        for name in ("n_money", "n_walls", "n_grass", "n_enemies", "n_treasure"):
            checked[name] = _check_int(name, getattr(self, name), 0)
        checked["max_steps"] = _check_int("max_steps", self.max_steps, 1)
        checked["size_w"] = _check_float("size_w", self.size_w, 2.0)
        checked["view_size"] = _check_float("view_size", self.view_size, 0.0, low_inclusive=False)
        checked["contact_radius"] = _check_float(
            "contact_radius", self.contact_radius, 0.5, checked["view_size"])
        checked["enemy_speed"] = _check_float("enemy_speed", self.enemy_speed, 0.0)
        checked["move_noise"] = _check_float("move_noise", self.move_noise, 0.0, 0.5)
        checked["swipe_size"] = _check_float("swipe_size", self.swipe_size, 0.0,
                                             low_inclusive=False)
        half = checked["size_w"]
        checked["start_clearance"] = _check_float(
            "start_clearance", self.start_clearance, checked["contact_radius"], half / 2)
        checked["treasure_radius"] = _check_float("treasure_radius", self.treasure_radius, 0.0,
                                                  half / 2)
        checked["treasure_margin"] = _check_float(
            "treasure_margin", self.treasure_margin, checked["treasure_radius"], half / 2)
        for name, value in checked.items():
            object.__setattr__(self, name, value)

    @property
    def n_actions(self):
        """Number of actions: 4 moves, or 8 with the sword (the moves, then the swipes).

        Returns
        -------
        n_actions : int
            4, or 8 if `sword`; the action space is ``Discrete(n_actions)``.
        """
        return 8 if self.sword else 4

    @property
    def n_types(self):
        """Number of object types an observation can hold.

        Returns
        -------
        n_types : int
            Type ids of observed objects lie in ``range(n_types)``: 4 (`MONEY`, `WALL`,
            `GRASS`, `ENEMY`) for the ``"local"`` and ``"global"`` views, 6 for
            ``"minimap"`` (plus `MONEY_MARKER` and `TREASURE_MARKER`), 7 for ``"arrow"``
            (ids up to `ARROW`; the markers never appear in this view).
        """
        return {"minimap": TREASURE_MARKER + 1, "arrow": ARROW + 1}.get(self.view, ENEMY + 1)

    @property
    def obs_bound(self):
        """Bound on the agent-relative coordinates of observed objects.

        Returns
        -------
        obs_bound : float
            Every observed row ``[dx, dy, type]`` has ``|dx|, |dy| <= obs_bound``:
            ``2 * size_w`` for the ``"global"`` view (the width of the world), `view_size`
            for the others. It bounds the observation space's `Box`.
        """
        return 2.0 * self.size_w if self.view == "global" else self.view_size
