"""The ObjectWorld game of the thesis as gymnasium environments, single and batched.

Importing this package registers

- ``ObjectWorld-v0``: four moves (up, right, down, left);
- ``ObjectWorldSword-v0``: plus four sword swipes;
- ``ObjectWorldTreasure-v0``: plus a 20-coin treasure stack near the border, observed
  through ``view="local" | "global" | "minimap" | "arrow"``.

Every rule constant is a keyword argument (see `WorldRules`), e.g.
``gymnasium.make("ObjectWorldTreasure-v0", view="arrow", enemy_speed=0)``;
``gymnasium.make_vec(id, num_envs=400)`` builds a `BatchedObjectWorld`. The envs truncate
their episodes themselves after ``max_steps`` steps; the ids register the default,
``max_episode_steps=50``, so ``gymnasium.spec(id)`` reports it and the `TimeLimit` that
``gymnasium.make`` adds truncates on the same step (see `ObjectWorldEnv` for other lengths).

Real games as object sets, with optional packages imported on first use:
`AtariObjects` (any game of OCAtari, also registered as ``AtariObjects-v0``; the extra
``atari``) and `HighwayObjects` (a wrapper of any highway-env env; the extra ``highway``).
"""
from gymnasium.envs.registration import register

from ._rules import (
    ACTION_NAMES, ARROW, ENEMY, GRASS, MONEY, MONEY_MARKER, REFERENCE_SEED_START,
    TREASURE_MARKER, TYPE_NAMES, VIEWS, WALL, WorldRules, reference_worlds,
)
from ._render import TYPE_COLOURS
from .batched import BatchedObjectWorld, RaggedBatch
from .object_world import ObjectWorldEnv
from .planner import LookaheadPlanner
from .policies import GreedyPolicy
from .symmetry import in_move_frame, move_frame
from .wrappers import PaddedObjects, strip_padding

__all__ = [
    "ObjectWorldEnv", "BatchedObjectWorld", "RaggedBatch", "WorldRules", "PaddedObjects",
    "strip_padding", "GreedyPolicy", "reference_worlds", "REFERENCE_SEED_START",
    "LookaheadPlanner", "move_frame", "in_move_frame",
    "MONEY", "WALL", "GRASS", "ENEMY", "MONEY_MARKER", "TREASURE_MARKER", "ARROW",
    "TYPE_NAMES", "TYPE_COLOURS", "ACTION_NAMES", "VIEWS",
    "AtariObjects", "atari_games", "HighwayObjects",
]
# name -> module of the adapters of real games, whose packages are imported on first use
_LAZY = {"AtariObjects": "atari", "atari_games": "atari", "HighwayObjects": "highway"}

_SPEC = {"entry_point": "envs.object_world:ObjectWorldEnv",
         "vector_entry_point": "envs.batched:_make_vec",
         "max_episode_steps": WorldRules.max_steps}
register(id="ObjectWorld-v0", **_SPEC)
register(id="ObjectWorldSword-v0", kwargs={"sword": True}, **_SPEC)
register(id="ObjectWorldTreasure-v0", kwargs={"treasure": True}, **_SPEC)
register(id="AtariObjects-v0", entry_point="envs.atari:AtariObjects")


def __getattr__(name):
    if name in _LAZY:
        from importlib import import_module

        return getattr(import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
