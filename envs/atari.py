"""Atari 2600 games as sets of typed objects, read by OCAtari from the console's RAM.

Needs the optional extra ``atari`` (``pip install 'boxtrees[atari]'``): OCAtari (package
``ocatari``) and the Arcade Learning Environment (package ``ale-py``, whose wheels carry the
game ROMs). Importing `envs` does not import them; this module does, on first use.
"""
import copy
import functools
import importlib
import inspect
import os
import re

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from ._optional import missing_extra

__all__ = ["AtariObjects", "atari_games"]

# Bounds of the attributes: the screen is 160 x 210 pixels and the RAM places a few objects
# just off it, so no position, size or motion read so far came near them (values beyond
# are clipped).
_BOUND = 512.0
_SCREEN_CENTRE = (80.0, 105.0)
# The category of the object the agent moves, where it is not called "Player"
_PLAYERS = {"Freeway": "Chicken", "KeystoneKapers": "Kop"}
_MODES = ("ram", "vision")
_ID = re.compile(r"(?:ALE/)?([A-Za-z0-9]+?)(?:NoFrameskip|Deterministic)?(?:-ram)?-v\d+")


@functools.cache
def _ocatari():
    """OCAtari's env class and its games' base object class, imported on first use."""
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")  # pygame's banner on stdout
    try:
        from ocatari.core import AVAILABLE_GAMES, OCAtari
        from ocatari.ram.extract_ram_info import detect_objects_ram
    except ImportError as exc:
        raise missing_extra("envs.AtariObjects", "OCAtari and ALE (ocatari, ale-py)", "atari",
                            exc) from exc

    class _OCAtari(OCAtari):
        """OCAtari, reading the RAM as Python integers (see `_IntegerRam`)."""

        def _detect_objects_ram(self):
            detect_objects_ram(self.objects, self.get_ram().astype(np.int64).view(_IntegerRam),
                               self.game_name, self.hud)

    return _OCAtari, tuple(AVAILABLE_GAMES)


class _IntegerRam(np.ndarray):
    """The console's RAM, whose single bytes read as Python ints.

    OCAtari's extraction computes positions with bytes of the RAM and Python integers
    (``161 - 13 * ram[44]``), written for NumPy 1, which widened such mixes. NumPy 2 keeps
    the byte's type and raises OverflowError (Enduro, Frogger, Seaquest and others), and
    a comparison of bytes gives a NumPy bool that cannot index a list (AirRaid). With
    Python ints the arithmetic is exact, as the extraction means it.
    """

    def __getitem__(self, key):
        value = super().__getitem__(key)
        return int(value) if isinstance(value, np.integer) else value


def _object_module(game, mode):
    """OCAtari's module of `game`'s object classes in `mode`, or None."""
    try:
        return importlib.import_module(f"ocatari.{mode}.{game.lower()}")
    except ModuleNotFoundError:
        return None


def atari_games(mode="ram"):
    """The games `AtariObjects` plays: OCAtari's, less those it has no objects for in `mode`.

    Parameters
    ----------
    mode : {"ram", "vision"}, default="ram"

    Returns
    -------
    games : tuple of str
        Game names as ALE writes them (``"Pong"``, ``"MontezumaRevenge"``).

    Raises
    ------
    ImportError
        If OCAtari is not installed (the extra ``atari``).
    """
    _check_mode(mode)
    return tuple(game for game in _ocatari()[1] if _object_module(game, mode) is not None)


def _check_mode(mode):
    if mode not in _MODES:
        raise ValueError(f"mode must be one of {_MODES}, got {mode!r}")


def _game_and_id(game, mode):
    """``(game name, ALE id)`` of a game name or an ALE id; a bare name plays ALE's v5."""
    if not isinstance(game, str):
        raise TypeError(f"game must be a str (a game name such as 'Pong' or an ALE id such as "
                        f"'ALE/Pong-v5'), got {game!r}")
    match = _ID.fullmatch(game)
    name = match.group(1) if match else game
    games = {g.lower(): g for g in atari_games(mode)}
    if name.lower() not in games:
        raise ValueError(f"OCAtari has no objects for {game!r} in {mode} mode; the games are "
                         f"{', '.join(games.values())}")
    name = games[name.lower()]
    return name, game if match else f"ALE/{name}-v5"


def _type_names(game, mode):
    """The object categories of `game`: the object classes of its OCAtari module, sorted."""
    module = _object_module(game, mode)
    base = importlib.import_module(f"ocatari.{mode}.game_objects").GameObject
    return tuple(sorted(name for name, cls in inspect.getmembers(module, inspect.isclass)
                        if issubclass(cls, base) and cls.__module__ == module.__name__))


class AtariObjects(gym.Env):
    """An Atari 2600 game whose observation is the set of objects on screen (OCAtari).

    Each step plays one action in the Arcade Learning Environment, after which OCAtari reads
    every object's category, position and size off the console's RAM (or, in ``"vision"``
    mode, off the screen). The observation has one row per object present, ``[x, y, w, h,
    dx, dy, type]`` (``d = 6`` attributes, then the type id):

    - ``x, y``: the centre of the object's box, in pixels, relative to the centre of the
      player's box (the first object of the `player` category present; while it is absent,
      where it was last seen in the episode, the screen's centre until then); in screen
      coordinates (``x`` right, ``y`` down) for games without a player (``player=None``);
    - ``w, h``: the box's width and height in pixels;
    - ``dx, dy``: the box's move on screen since the previous step (0 after a reset);
    - ``type``: the index of the object's category in `type_names`.

    Values are clipped to ``[-512, 512]`` (sizes to ``[0, 512]``), far beyond the screen.
    The scores, lives, clocks and other parts of the heads-up display (HUD) are left out
    unless ``hud=True``.

    Parameters
    ----------
    game : str
        A game name (``"Pong"``, ``"MsPacman"``; any of `atari_games`, case-insensitive),
        played as ``ALE/<Game>-v5``, or an ALE id (``"ALE/Pong-v5"``,
        ``"PongNoFrameskip-v4"``).
    mode : {"ram", "vision"}, default="ram"
        Where OCAtari reads the objects: the RAM (exact, about 1,000-3,000 steps per second)
        or the screen's pixels.
    hud : bool, default=False
        Keep the HUD's objects.
    player : str or None, default="auto"
        The category the positions are relative to: ``"auto"`` is ``"Player"`` where the
        game has that category (``"Chicken"`` in Freeway, ``"Kop"`` in KeystoneKapers),
        else None; None gives screen coordinates.
    frameskip : int, default=None
        Frames each action is repeated for.
    repeat_action_probability : float, default=None
        The probability, at every frame, that the console repeats the previous action
        instead of the new one ("sticky actions").
    full_action_space : bool, default=None
        All 18 actions of the joystick, instead of the game's minimal set.
    max_num_frames_per_episode : int, default=None
        Frames after which an episode is truncated.

        These four are ALE's settings, as ``gymnasium.make(id, ...)`` takes them; None keeps
        the id's. ALE's v5 ids, which a game name plays, have ``frameskip=4``,
        ``repeat_action_probability=0.25``, the minimal action set and 108,000 frames
        (27,000 steps).
    render_mode : {None, "rgb_array"}, default=None

    Raises
    ------
    ImportError
        If OCAtari or ALE is not installed (the extra ``atari``).
    TypeError
        If `game` is not a str.
    ValueError
        If OCAtari has no objects for the game in `mode`, or `mode`, `player` or
        `render_mode` is unknown.

    Attributes
    ----------
    game : str
        The game's name.
    attribute_names : tuple of str
        ``("x", "y", "w", "h", "dx", "dy")``, the names of the columns before the type.
    type_names : tuple of str
        OCAtari's categories of the game (the object classes it defines, HUD's included),
        sorted; type id ``i`` is ``type_names[i]``, the same in every episode and every env
        of the game.
    n_types : int
    action_names : tuple of str
        ALE's name of each action (``"NOOP"``, ``"FIRE"``, ``"UP"``, ...).

    Notes
    -----
    OCAtari's ``step`` returns ``terminated`` and ``truncated`` in each other's place; this
    env returns them in gymnasium's order: ``terminated`` when the game is over,
    ``truncated`` at ALE's frame limit. A ``reset(seed=s)`` seeds ALE (its sticky actions
    and the game's start), so a seed and a sequence of actions give the same episode.

    The emulator cannot be copied (``copy.deepcopy`` fails), so the env records its
    arguments in its ``spec``: ``gymnasium.make(env.spec)`` and
    ``gymnasium.make_vec(env.spec, n)`` build new ones, as `fqi.FQI` does. The id
    ``"AtariObjects-v0"`` takes the same arguments: ``gymnasium.make_vec("AtariObjects-v0",
    4, vectorization_mode="async", game="Pong")``.

    OCAtari 2.2.1 asks for NumPy < 2; with NumPy 2 this env gives its extraction the RAM
    as Python integers, which makes every game run. OCAtari fails on its own in a few
    states (RoadRunner; TimePilot without its HUD; Assault and Enduro with it).

    Examples
    --------
    >>> import envs
    >>> env = envs.AtariObjects("Pong")
    >>> obs, info = env.reset(seed=0)
    >>> env.type_names
    ('Ball', 'Enemy', 'EnemyScore', 'Player', 'PlayerScore')
    >>> obs                                   # the player's paddle, at the start alone
    array([[ 0.,  0.,  4., 15.,  0.,  0.,  3.]], dtype=float32)
    >>> for _ in range(60):
    ...     obs, reward, terminated, truncated, info = env.step(0)
    >>> [env.type_names[int(t)] for t in obs[:, -1]]
    ['Player', 'Ball', 'Enemy']
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 15}
    attribute_names = ("x", "y", "w", "h", "dx", "dy")

    def __init__(self, game, *, mode="ram", hud=False, player="auto", frameskip=None,
                 repeat_action_probability=None, full_action_space=None,
                 max_num_frames_per_episode=None, render_mode=None):
        _check_mode(mode)
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        ocatari_class = _ocatari()[0]
        self.game, env_id = _game_and_id(game, mode)
        self.type_names = _type_names(self.game, mode)
        self._type_ids = {name: i for i, name in enumerate(self.type_names)}
        self._player = self._player_type(player)
        self.hud, self.render_mode = bool(hud), render_mode
        ale = {"frameskip": frameskip, "repeat_action_probability": repeat_action_probability,
               "full_action_space": full_action_space,
               "max_num_frames_per_episode": max_num_frames_per_episode}
        self._ocatari = ocatari_class(
            env_id, mode=mode, hud=self.hud, obs_mode="ori", create_buffer_stacks=[],
            obs_type="ram", **{key: value for key, value in ale.items() if value is not None})
        self.action_space = self._ocatari.action_space
        self.action_names = tuple(self._ocatari.get_action_meanings())
        low = np.array([-_BOUND, -_BOUND, 0, 0, -_BOUND, -_BOUND, 0], dtype=np.float32)
        high = np.array([_BOUND] * 6 + [self.n_types - 1], dtype=np.float32)
        self.observation_space = spaces.Sequence(spaces.Box(low, high, dtype=np.float32),
                                                 stack=True)
        self.spec = copy.copy(gym.spec("AtariObjects-v0"))
        self.spec.kwargs = {"game": game, "mode": mode, "hud": hud, "player": player,
                            "render_mode": render_mode, **ale}
        self._reference = _SCREEN_CENTRE

    @property
    def n_types(self):
        """Number of object categories of the game (``len(type_names)``)."""
        return len(self.type_names)

    def _player_type(self, player):
        """The type id of the `player` category, or None."""
        if player == "auto":
            player = _PLAYERS.get(self.game, "Player")
            return self._type_ids.get(player)
        if player is None:
            return None
        if player not in self._type_ids:
            raise ValueError(f"player must be 'auto', None or one of {self.game}'s categories "
                             f"{self.type_names}, got {player!r}")
        return self._type_ids[player]

    def reset(self, *, seed=None, options=None):
        """Start a new game.

        Parameters
        ----------
        seed : int, optional
            Seeds the emulator (the game's start and its sticky actions).
        options : None
            Not used.

        Returns
        -------
        observation : ndarray of float32 of shape (n, 7)
        info : dict
            ALE's (``lives``, ``episode_frame_number``, ``frame_number``).
        """
        super().reset(seed=seed)
        _, info = self._ocatari.reset(seed=seed)
        self._reference = _SCREEN_CENTRE
        observation = self._observation()
        observation[:, 4:6] = 0.0   # OCAtari's first move of an object is from (0, 0)
        return observation, info

    def step(self, action):
        """Play `action` for `frameskip` frames.

        Returns
        -------
        observation : ndarray of float32 of shape (n, 7)
        reward : float
            The score's change.
        terminated : bool
            Whether the game is over.
        truncated : bool
            Whether ALE's frame limit cut the episode.
        info : dict
            ALE's.
        """
        # OCAtari returns the flags swapped: (obs, reward, truncated, terminated, info)
        _, reward, truncated, terminated, info = self._ocatari.step(action)
        return self._observation(), float(reward), bool(terminated), bool(truncated), info

    def _observation(self):
        """The rows ``[x, y, w, h, dx, dy, type]`` of the objects present."""
        objects = [o for o in self._ocatari.objects if o and (self.hud or not o.hud)]
        rows = np.zeros((len(objects), 7), dtype=np.float32)
        if not objects:
            return rows
        rows[:] = [(o.x + o.w / 2, o.y + o.h / 2, o.w, o.h, o.dx, o.dy,
                    self._type_ids[o.category])
                   for o in objects]
        if self._player is not None:
            players = np.flatnonzero(rows[:, 6] == self._player)
            if len(players):
                self._reference = tuple(rows[players[0], :2])
            rows[:, :2] -= self._reference
        np.clip(rows[:, :6], self.observation_space.feature_space.low[:6], _BOUND,
                out=rows[:, :6])
        return rows

    def render(self):
        """The screen as an RGB array of shape (210, 160, 3), with ``render_mode="rgb_array"``."""
        if self.render_mode is None:
            gym.logger.warn("render() called without render_mode; pass render_mode='rgb_array'")
            return None
        return self._ocatari.getScreenRGB()

    def close(self):
        self._ocatari.close()
