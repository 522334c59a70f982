"""Pure-numpy drawing of ObjectWorld frames into RGB arrays (no plotting dependency)."""
from functools import lru_cache

import numpy as np

from ._rules import ARROW, ENEMY, GRASS, MONEY, MONEY_MARKER, TREASURE_MARKER, WALL

_BACKGROUND = (245, 240, 226)
_VIEW_COLOUR = (40, 60, 140)
_AGENT = ((20, 20, 20), "disc", 0.55)  # the agent's sprite: colour, shape, radius
# RGB colour of each object type, as drawn (and as the benchmark figures show it).
TYPE_COLOURS = {
    MONEY: (226, 178, 18),
    WALL: (100, 100, 106),
    GRASS: (76, 168, 72),
    ENEMY: (212, 44, 44),
    MONEY_MARKER: (212, 44, 44),
    TREASURE_MARKER: (40, 90, 220),
    ARROW: (140, 60, 200),
}
# The sprite of each type: colour (from TYPE_COLOURS), shape, radius in world units.
_STYLE = {
    kind: (TYPE_COLOURS[kind], shape, radius)
    for kind, shape, radius in [
        (MONEY, "disc", 0.45), (WALL, "square", 0.5), (GRASS, "triangle", 0.45),
        (ENEMY, "diamond", 0.55), (MONEY_MARKER, "ring", 0.9),
        (TREASURE_MARKER, "diamond", 0.9), (ARROW, "plus", 0.7),
    ]
}
_DRAW_ORDER = (GRASS, WALL, MONEY, ENEMY, MONEY_MARKER, TREASURE_MARKER, ARROW)
_WORLD_SCALE = 8.0  # pixels per unit when drawing the whole world
_LOCAL_PIXELS = 504  # side of the local-view frame


@lru_cache(maxsize=64)
def _mask(shape, half):
    """Boolean sprite of a shape in a ``(2 * half + 1)^2`` pixel square."""
    v, u = np.mgrid[half:-half - 1:-1, -half:half + 1] / max(half, 1)
    r2 = u * u + v * v
    masks = {
        "disc": r2 <= 1.0,
        "square": (np.abs(u) <= 0.9) & (np.abs(v) <= 0.9),
        "triangle": (v >= -0.8) & (v <= 0.9 - 1.9 * np.abs(u)),
        "diamond": np.abs(u) + np.abs(v) <= 1.0,
        "ring": (r2 <= 1.0) & (r2 >= 0.45),
        "plus": (np.minimum(np.abs(u), np.abs(v)) <= 0.3) & (r2 <= 1.0),
    }
    return masks[shape]


class _Canvas:
    """An RGB image showing the square ``[lo, hi]^2`` of the plane, y pointing up."""

    def __init__(self, lo, hi, scale):
        self.lo, self.hi, self.scale = lo, hi, scale
        side = int(round((hi - lo) * scale))
        self.image = np.empty((side, side, 3), dtype=np.uint8)
        self.image[:] = _BACKGROUND

    def _pixel(self, x, y):
        return int(round((self.hi - y) * self.scale)), int(round((x - self.lo) * self.scale))

    def sprite(self, x, y, colour, shape, radius):
        row, col = self._pixel(x, y)
        half = max(1, int(round(radius * self.scale)))
        mask = _mask(shape, half)
        size = self.image.shape[0]
        top, left = row - half, col - half
        r0, c0 = max(top, 0), max(left, 0)
        r1, c1 = min(top + mask.shape[0], size), min(left + mask.shape[1], size)
        if r0 < r1 and c0 < c1:
            self.image[r0:r1, c0:c1][mask[r0 - top:r1 - top, c0 - left:c1 - left]] = colour

    def square_outline(self, x, y, half, colour, width=2):
        r0, c0 = self._pixel(x - half, y + half)
        r1, c1 = self._pixel(x + half, y - half)
        size = self.image.shape[0]
        edges = (((r0, r0 + width), (c0, c1 + 1)), ((r1 - width + 1, r1 + 1), (c0, c1 + 1)),
                 ((r0, r1 + 1), (c0, c0 + width)), ((r0, r1 + 1), (c1 - width + 1, c1 + 1)))
        for rows, cols in edges:
            ra, rb = np.clip(rows, 0, size)
            ca, cb = np.clip(cols, 0, size)
            self.image[ra:rb, ca:cb] = colour

    def objects(self, rows, shift=(0.0, 0.0)):
        types = rows[:, 2].astype(int)
        for kind in _DRAW_ORDER:
            colour, shape, radius = _STYLE[kind]
            for x, y in rows[types == kind, :2] + np.asarray(shift):
                self.sprite(x, y, colour, shape, radius)


def render_world(objects, agent, rules):
    """The whole world: its objects (world coordinates), the agent and its view square.

    Parameters
    ----------
    objects : ndarray of shape (n, 3)
        Rows ``[x, y, type]`` in world coordinates.
    agent : ndarray of shape (2,)
    rules : WorldRules

    Returns
    -------
    frame : ndarray of uint8 of shape (side, side, 3)
    """
    extent = rules.size_w + 1.0
    canvas = _Canvas(-extent, extent, _WORLD_SCALE)
    canvas.objects(objects)
    canvas.square_outline(agent[0], agent[1], rules.view_size, _VIEW_COLOUR)
    canvas.sprite(agent[0], agent[1], *_AGENT)
    return canvas.image


def render_local(observation, rules):
    """What the agent observes: its ``(n, 3)`` observation around it, and the view square."""
    extent = rules.obs_bound + 1.0
    canvas = _Canvas(-extent, extent, _LOCAL_PIXELS / (2 * extent))
    canvas.objects(observation)
    canvas.square_outline(0.0, 0.0, rules.view_size, _VIEW_COLOUR)
    canvas.sprite(0.0, 0.0, *_AGENT)
    return canvas.image
