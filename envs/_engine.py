"""The vectorised ObjectWorld engine: the game's rules, written once for many worlds.

`ObjectWorldEnv` is this engine over one world and `BatchedObjectWorld` over many, so the
two cannot disagree. All worlds advance in lockstep. Each world is drawn at reset from its own
generator, including the move noise of the whole episode, so `step` makes no random calls
and the transitions of a world never depend on how many worlds run beside it.

Layout. Objects that never move (money, walls, grass, treasure coins, border walls) are
"static": ``n_static`` per world, in flat arrays sorted by world and then by cell of a coarse
grid, so that a step only looks at the cells around each agent. Enemies live in dense
``(n_worlds, n_enemies)`` arrays; a removed object is only marked dead.
"""
import math

import numpy as np

from ._rules import (
    _DIRECTIONS, _REWARD_ENEMY, _REWARD_MONEY, _REWARD_SWIPE_MANY, _REWARD_SWIPE_NONE,
    _REWARD_SWIPE_ONE, _REWARD_WALL, ARROW, ENEMY, GRASS, MONEY, MONEY_MARKER,
    TREASURE_MARKER, WALL,
)

_GRID_CELL = 4.0  # side of the cells that index static objects (a speed knob, not a rule)
_ARROW_DISTANCE = 0.9  # the arrow sits at this fraction of view_size from the agent


def _border_walls(size_w):
    """Wall positions lining the square's border, at most 1 unit apart, corners included."""
    side = np.linspace(-size_w, size_w, math.ceil(2 * size_w) + 1)
    inner = side[1:-1]
    return np.concatenate([
        np.column_stack([side, np.full_like(side, -size_w)]),
        np.column_stack([side, np.full_like(side, size_w)]),
        np.column_stack([np.full_like(inner, -size_w), inner]),
        np.column_stack([np.full_like(inner, size_w), inner]),
    ])


def _draw_world(rules, rng):
    """Draw one world from `rng`: random object positions, treasure coins and move noise.

    Returns
    -------
    objects : ndarray of shape (n_money + n_walls + n_grass + n_enemies, 2)
        Uniform in the world square, none within `start_clearance` of the centre.
    coins : ndarray of shape (n_treasure or 0, 2)
    centre : ndarray of shape (2,)
        The treasure's centre (zeros without treasure).
    noise : ndarray of shape (max_steps, 2)
        The move noise of each step of the episode.
    """
    size_w = rules.size_w
    n_objects = rules.n_money + rules.n_walls + rules.n_grass + rules.n_enemies
    objects = rng.uniform(-size_w, size_w, size=(n_objects, 2))
    too_close = np.hypot(objects[:, 0], objects[:, 1]) < rules.start_clearance
    while too_close.any():  # rejection keeps the density uniform outside the clearance
        objects[too_close] = rng.uniform(-size_w, size_w, size=(int(too_close.sum()), 2))
        too_close = np.hypot(objects[:, 0], objects[:, 1]) < rules.start_clearance
    centre = np.zeros(2)
    coins = np.empty((0, 2))
    if rules.treasure:
        side = rng.integers(4)
        along = rng.uniform(-size_w + rules.treasure_margin, size_w - rules.treasure_margin)
        centre = (size_w - rules.treasure_margin) * _DIRECTIONS[side]
        centre[side % 2] = along  # x along the top and bottom sides, y along the others
        radius, angle = rng.uniform(size=(2, rules.n_treasure))
        radius = rules.treasure_radius * np.sqrt(radius)
        angle = 2 * np.pi * angle
        coins = centre + np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])
    noise = rng.uniform(-rules.move_noise, rules.move_noise, size=(rules.max_steps, 2))
    return objects, coins, centre, noise


def _near_path(rel, seg, radius):
    """Whether points `rel` lie within `radius` of the segment from 0 to `seg` (broadcasting)."""
    rx, ry = rel[..., 0], rel[..., 1]
    sx, sy = seg[..., 0], seg[..., 1]
    along = np.clip((rx * sx + ry * sy) / np.maximum(sx * sx + sy * sy, 1e-12), 0.0, 1.0)
    dx = rx - along * sx
    dy = ry - along * sy
    return dx * dx + dy * dy <= radius * radius


def _ragged_concat(n_rows, parts):
    """Interleave ragged parts into one world-major ``(N, 3)`` float32 array plus offsets.

    Parameters
    ----------
    n_rows : int
        Number of worlds.
    parts : list of (world, xy, types)
        Rows of one kind: ``world`` their (non-decreasing) world ids, ``xy`` their
        agent-relative positions, ``types`` their type ids.
    """
    counts = [np.bincount(world, minlength=n_rows) for world, _, _ in parts]
    offsets = np.zeros(n_rows + 1, dtype=np.intp)
    np.cumsum(sum(counts), out=offsets[1:])
    data = np.empty((offsets[-1], 3), dtype=np.float32)
    base = offsets[:-1].copy()
    for (world, xy, types), count in zip(parts, counts):
        first = np.cumsum(count) - count  # index of each world's first row inside this part
        dest = base[world] + (np.arange(len(world)) - first[world])
        data[dest, :2] = xy
        data[dest, 2] = types
        base += count
    return data, offsets


class _Engine:
    """The rules of `n_worlds` ObjectWorlds, stepped in lockstep with numpy.

    Parameters
    ----------
    rules : WorldRules
    n_worlds : int

    Attributes
    ----------
    t : int
        Steps taken since the last reset.
    observation : tuple of (ndarray, ndarray)
        The current observations as rows ``[dx, dy, type]`` (float32, world after world) and
        offsets: world ``i`` sees ``data[offsets[i]:offsets[i + 1]]``.
    agent : ndarray of shape (n_worlds, 2)
        The agents' positions.
    """

    def __init__(self, rules, n_worlds):
        self.rules = rules
        self.n_worlds = n_worlds
        size_w = rules.size_w
        border = _border_walls(size_w)
        self._border = border
        n_coins = rules.n_treasure if rules.treasure else 0
        self._static_types = np.repeat(
            np.array([WALL, MONEY, WALL, GRASS, MONEY], dtype=np.int8),
            [len(border), rules.n_money, rules.n_walls, rules.n_grass, n_coins])
        self._n_static = len(self._static_types)
        self._n_random_static = rules.n_money + rules.n_walls + rules.n_grass
        # Grid of cells indexing the static objects, and the window of cells a step reads:
        # everything touched by a path or seen from its end lies within `reach` of its start.
        self._grid = math.ceil(2 * size_w / _GRID_CELL)
        reach = max(rules.view_size, rules.contact_radius) + 1 + rules.move_noise
        if rules.view == "global":
            reach = 4 * size_w
        self._window = min(self._grid, math.ceil(2 * reach / _GRID_CELL) + 1)
        self._reach = reach
        # Minimap cells are view-sized.
        self._minimap = math.ceil(size_w / rules.view_size)
        self.t = 0
        self.observation = None

    # ----------------------------------------------------------------------------------
    def reset(self, rngs):
        """Draw every world afresh, world ``i`` from ``rngs[i]``."""
        rules, n = self.rules, self.n_worlds
        draws = [_draw_world(rules, rng) for rng in rngs]
        objects = np.stack([d[0] for d in draws])
        n_rand = self._n_random_static
        statics = np.concatenate([
            np.broadcast_to(self._border, (n,) + self._border.shape),
            objects[:, :n_rand],
            np.stack([d[1] for d in draws]),
        ], axis=1)
        self._enemies = np.ascontiguousarray(objects[:, n_rand:])
        self._enemy_alive = np.ones(self._enemies.shape[:2], dtype=bool)
        self._treasure = np.stack([d[2] for d in draws])
        self._noise = np.stack([d[3] for d in draws])
        self.agent = np.zeros((n, 2))
        self.t = 0

        cells = self._cell_index(statics, _GRID_CELL, self._grid)
        order = np.argsort(cells, axis=1, kind="stable")
        cells = np.take_along_axis(cells, order, axis=1)
        self._pos = np.take_along_axis(statics, order[..., None], axis=1).reshape(-1, 2)
        self._types = self._static_types[order].ravel()
        self._alive = np.ones(len(self._types), dtype=bool)
        n_cells = self._grid ** 2
        counts = np.bincount((cells + n_cells * np.arange(n)[:, None]).ravel(),
                             minlength=n * n_cells).reshape(n, n_cells)
        self._cell_count = counts
        self._cell_start = (np.cumsum(counts, axis=1) - counts
                            + self._n_static * np.arange(n)[:, None])
        if rules.view == "minimap":
            m = self._minimap
            self._minimap_cell = self._cell_index(
                self._pos.reshape(n, -1, 2), 2 * rules.view_size, m).ravel()
            world = np.repeat(np.arange(n), self._n_static)
            self._cell_money = np.bincount(
                (world * m * m + self._minimap_cell)[self._types == MONEY],
                minlength=n * m * m).reshape(n, m * m)
            self._visited = np.zeros((n, m * m), dtype=bool)
            self._visit()
        self.observation = self._observe(*self._candidates())

    def step(self, actions):
        """Advance every world by one step.

        Parameters
        ----------
        actions : ndarray of int of shape (n_worlds,)
            Valid action ids (checked by the caller).

        Returns
        -------
        rewards : ndarray of float64 of shape (n_worlds,)
        truncated : bool
            Whether the episodes (all in lockstep) reached ``max_steps``.
        """
        rules, n = self.rules, self.n_worlds
        moves = actions < 4
        direction = _DIRECTIONS[actions & 3]
        delta = np.where(moves[:, None], direction + self._noise[:, self.t], 0.0)
        old = self.agent

        # Static objects on the path: a wall cancels the move, otherwise money is collected.
        index, world = self._candidates()
        types = self._types[index]
        hit = _near_path(self._pos[index] - old[world], delta[world], rules.contact_radius)
        hit &= moves[world]
        blocked = np.bincount(world[hit & (types == WALL)], minlength=n) > 0
        collected = hit & ~blocked[world] & (types == MONEY)
        self._alive[index[collected]] = False
        rewards = _REWARD_WALL * blocked
        rewards += _REWARD_MONEY * np.bincount(world[collected], minlength=n)
        if rules.view == "minimap":
            m2 = self._minimap ** 2
            self._cell_money -= np.bincount(
                world[collected] * m2 + self._minimap_cell[index[collected]],
                minlength=n * m2).reshape(n, m2)

        # Enemies on the path, then the swipes.
        walked = moves & ~blocked
        rel = self._enemies - old[:, None]
        touched = self._enemy_alive & walked[:, None]
        touched &= _near_path(rel, delta[:, None], rules.contact_radius)
        self._enemy_alive &= ~touched
        rewards += _REWARD_ENEMY * touched.sum(axis=1)
        if rules.sword:
            rewards += self._swipe(~moves, direction, rel)
        self.agent = np.where(walked[:, None], old + delta, old)

        # Enemies inside the view chase the agent; the ones that reach it hurt.
        rel = self.agent[:, None] - self._enemies
        dist = np.hypot(rel[..., 0], rel[..., 1])
        chasing = self._enemy_alive & (np.abs(rel).max(axis=2) <= rules.view_size) & (dist > 0)
        stride = np.divide(np.minimum(rules.enemy_speed, dist), dist,
                           out=np.zeros_like(dist), where=chasing)
        self._enemies += stride[..., None] * rel
        rel = self.agent[:, None] - self._enemies
        touched = self._enemy_alive & ((rel * rel).sum(axis=2) <= rules.contact_radius ** 2)
        self._enemy_alive &= ~touched
        rewards += _REWARD_ENEMY * touched.sum(axis=1)

        if rules.view == "minimap":
            self._visit()
        self.t += 1
        self.observation = self._observe(index, world)
        return rewards, self.t >= rules.max_steps

    # ----------------------------------------------------------------------------------
    def _swipe(self, swiping, direction, rel):
        """Rewards of the swipes; a swipe that hits exactly one enemy kills it."""
        size = self.rules.swipe_size
        dx, dy = direction[:, None, 0], direction[:, None, 1]
        along = rel[..., 0] * dx + rel[..., 1] * dy
        across = rel[..., 0] * dy - rel[..., 1] * dx
        inside = self._enemy_alive & swiping[:, None]
        inside &= (along > 0) & (along <= size) & (np.abs(across) <= size / 2)
        n_hit = inside.sum(axis=1)
        self._enemy_alive &= ~(inside & (n_hit == 1)[:, None])
        rewards = np.select([n_hit == 0, n_hit == 1], [_REWARD_SWIPE_NONE, _REWARD_SWIPE_ONE],
                            _REWARD_SWIPE_MANY)
        return np.where(swiping, rewards, 0.0)

    def _cell_index(self, pos, cell, n_cells):
        """Row-major index of the `cell`-sized grid cell holding each position."""
        ij = np.clip(((pos + self.rules.size_w) // cell).astype(np.intp), 0, n_cells - 1)
        return ij[..., 1] * n_cells + ij[..., 0]

    def _candidates(self):
        """Live static objects in the window of cells around each agent.

        Returns their flat indices and world ids, world after world.
        """
        g, w = self._grid, self._window
        corner = (self.agent - self._reach + self.rules.size_w) // _GRID_CELL
        corner = np.clip(corner.astype(np.intp), 0, g - w)
        offsets = np.arange(w)
        cells = ((corner[:, 1, None, None] + offsets[:, None]) * g
                 + corner[:, 0, None, None] + offsets).reshape(self.n_worlds, -1)
        count = np.take_along_axis(self._cell_count, cells, axis=1).ravel()
        start = np.take_along_axis(self._cell_start, cells, axis=1).ravel()
        end = np.cumsum(count)
        index = np.repeat(start - (end - count), count) + np.arange(end[-1])
        index = index[self._alive[index]]
        return index, index // self._n_static

    def _observe(self, index, world):
        """The agents' observations, given live static candidates `index` of `world`."""
        rules = self.rules
        rel = self._pos[index] - self.agent[world]
        erel = self._enemies - self.agent[:, None]
        seen = self._alive[index]
        enemy_seen = self._enemy_alive.copy()
        if rules.view != "global":
            seen &= np.abs(rel).max(axis=1) <= rules.view_size
            enemy_seen &= np.abs(erel).max(axis=2) <= rules.view_size
        enemy_world, enemy = np.nonzero(enemy_seen)
        parts = [
            (world[seen], rel[seen], self._types[index[seen]]),
            (enemy_world, erel[enemy_world, enemy], ENEMY),
        ]
        if rules.view in ("minimap", "arrow"):
            marker_world, xy, types = self._markers()
            xy -= self.agent[marker_world]
            if rules.view == "minimap":  # the whole world shrunk into the view
                xy *= rules.view_size / (2 * rules.size_w)
            parts.append((marker_world, xy, types))
        return _ragged_concat(self.n_worlds, parts)

    def _markers(self):
        """The treasure views' marker objects in world coordinates, world after world.

        Minimap: a `MONEY_MARKER` at the centre of each unvisited cell holding money, then a
        `TREASURE_MARKER` at the centre of the treasure's cell until it is visited (centres of
        the cells' parts inside the world). Arrow:
        one `ARROW` at ``0.9 * view_size`` from the agent toward the treasure's centre.
        """
        rules = self.rules
        if rules.view == "arrow":
            to_goal = self._treasure - self.agent
            dist = np.hypot(to_goal[:, 0], to_goal[:, 1])[:, None]
            arrow = np.divide(_ARROW_DISTANCE * rules.view_size * to_goal, dist,
                              out=np.zeros_like(to_goal), where=dist > 0)
            return np.arange(self.n_worlds), self.agent + arrow, ARROW
        m = self._minimap
        goal_cell = self._cell_index(self._treasure, 2 * rules.view_size, m)
        shown = np.column_stack([
            (self._cell_money > 0) & ~self._visited,
            ~np.take_along_axis(self._visited, goal_cell[:, None], axis=1),
        ])
        cell = np.concatenate([np.broadcast_to(np.arange(m * m), shown[:, :-1].shape),
                               goal_cell[:, None]], axis=1)
        world, k = np.nonzero(shown)
        cell = cell[world, k]
        low = np.column_stack([cell % m, cell // m]) * (2 * rules.view_size) - rules.size_w
        centre = (low + np.minimum(low + 2 * rules.view_size, rules.size_w)) / 2
        types = np.where(k < m * m, MONEY_MARKER, TREASURE_MARKER)
        return world, centre, types

    def _visit(self):
        """Mark the minimap cells holding the agents as visited."""
        cell = self._cell_index(self.agent, 2 * self.rules.view_size, self._minimap)
        self._visited[np.arange(self.n_worlds), cell] = True

    def world_objects(self, i):
        """Objects of world `i` in world coordinates, rows ``[x, y, type]`` (for rendering).

        The live objects, then the markers of the treasure views.
        """
        n_static = self._n_static
        own = slice(i * n_static, (i + 1) * n_static)
        alive = self._alive[own]
        rows = [np.column_stack([self._pos[own][alive], self._types[own][alive]]),
                np.column_stack([self._enemies[i][self._enemy_alive[i]],
                                 np.full(self._enemy_alive[i].sum(), ENEMY)])]
        if self.rules.view in ("minimap", "arrow"):
            world, xy, types = self._markers()
            mine = world == i
            rows.append(np.column_stack([xy[mine], np.broadcast_to(types, world.shape)[mine]]))
        return np.concatenate(rows)
