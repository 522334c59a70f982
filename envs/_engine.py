"""The vectorised ObjectWorld engine: the game's rules, written once for many worlds.

`ObjectWorldEnv` is this engine over one world and `BatchedObjectWorld` over many, so the
two cannot disagree. All worlds step together, each at its own step of its episode (a world
reset alone, `_Engine.replaced`, starts again while the others go on). Each world draws from
its own generator only, so the transitions of a world never depend on how many worlds run
beside it.

Stream. A world's generator gives, at reset, one block of uniforms: the layout, then the move
noise of the whole episode (two per step); then the redraws of objects too close to the start,
and after them the next episode. The noise is read in chunks of `_NOISE_CHUNK` steps: reset
draws the first chunk with the layout, keeps the generator state where the second one starts
and skips the stream past the episode's noise; a later chunk is drawn, world by world, from
that kept state.
The draws are those of taking the whole block at once, in memory that does not grow with
``max_steps``.

Layout. Objects that never move (money, walls, grass, treasure coins, border walls) are
"static": ``n_static`` per world, in flat arrays sorted by world and then by cell of a coarse
grid, so that a step only looks at the cells around each agent. Enemies live in dense
``(n_worlds, n_enemies)`` arrays; a removed object is only marked dead.
"""
import copy
import math

import numpy as np

from ._rules import (
    _DIRECTIONS, _REWARD_ENEMY, _REWARD_MONEY, _REWARD_SWIPE_MANY, _REWARD_SWIPE_NONE,
    _REWARD_SWIPE_ONE, _REWARD_WALL, ARROW, ENEMY, GRASS, MONEY, MONEY_MARKER,
    TREASURE_MARKER, WALL,
)

_GRID_CELL = 4.0  # side of the cells that index static objects (a speed knob, not a rule)
_ARROW_DISTANCE = 0.9  # the arrow sits at this fraction of view_size from the agent
_NOISE_CHUNK = 256  # steps of move noise held at a time (a memory knob, not a rule)
_SKIP_BLOCK = 1 << 16  # uniforms per draw when a stream is skipped by drawing


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


def _layout_uniforms(rules):
    """Number of uniforms that lay out one world, before its move noise (see `_Engine.reset`)."""
    n_objects = rules.n_money + rules.n_walls + rules.n_grass + rules.n_enemies
    n_treasure = 2 + 2 * rules.n_treasure if rules.treasure else 0
    return 2 * n_objects + n_treasure


def _skip_uniforms(rng, n):
    """Advance `rng` past `n` uniforms exactly as ``rng.random(n)`` would, without holding them.

    A PCG64 (or PCG64DXSM) stream spends one step on each uniform, so it jumps with
    ``advance``; that also drops the 32-bit half a 32-bit integer draw may have buffered,
    which ``random`` keeps, so the half is restored. Other bit generators draw and discard
    the uniforms in blocks of `_SKIP_BLOCK`.
    """
    bit_generator = rng.bit_generator
    if isinstance(bit_generator, (np.random.PCG64, np.random.PCG64DXSM)):
        before = bit_generator.state
        bit_generator.advance(n)
        after = bit_generator.state
        after["has_uint32"], after["uinteger"] = before["has_uint32"], before["uinteger"]
        bit_generator.state = after
    else:
        for start in range(0, n, _SKIP_BLOCK):
            rng.random(min(_SKIP_BLOCK, n - start))


def _check_layout(objects, rules):
    """Validate explicit world objects: a float ``(k, 3)`` array of ``[x, y, type]`` rows."""
    try:
        objects = np.asarray(objects, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError("options['objects'] must be a numeric array of rows [x, y, type]") \
            from None
    objects = objects.reshape(-1, 3) if objects.size == 0 else objects
    if objects.ndim != 2 or objects.shape[1] != 3:
        raise ValueError(f"options['objects'] must have shape (k, 3), got {objects.shape}")
    if not np.isfinite(objects).all():
        raise ValueError("options['objects'] contains NaN or infinite values")
    if (np.abs(objects[:, :2]) > rules.size_w).any():
        raise ValueError(f"options['objects'] has positions outside [-{rules.size_w}, "
                         f"{rules.size_w}]^2")
    if not np.isin(objects[:, 2], [MONEY, WALL, GRASS, ENEMY]).all():
        raise ValueError("options['objects'] types must be MONEY, WALL, GRASS or ENEMY "
                         f"({MONEY}-{ENEMY})")
    return objects


def _near_path(rx, ry, sx, sy, radius):
    """Whether points ``(rx, ry)`` lie within `radius` of the segment from 0 to ``(sx, sy)``."""
    along = np.clip((rx * sx + ry * sy) / np.maximum(sx * sx + sy * sy, 1e-12), 0.0, 1.0)
    dx = rx - along * sx
    dy = ry - along * sy
    return dx * dx + dy * dy <= radius * radius


def _ragged_concat(n_worlds, parts):
    """Interleave ragged parts into one world-major ``(N, 3)`` float32 array plus offsets.

    Parameters
    ----------
    n_worlds : int
    parts : list of (world, dx, dy, types)
        Rows of one kind: ``world`` their non-decreasing world ids, ``dx, dy`` their
        agent-relative positions, ``types`` their type ids.
    """
    counts = [np.bincount(part[0], minlength=n_worlds) for part in parts]
    offsets = np.zeros(n_worlds + 1, dtype=np.intp)
    np.cumsum(sum(counts), out=offsets[1:])
    data = np.empty((offsets[-1], 3), dtype=np.float32)
    base = offsets[:-1].copy()
    for (world, dx, dy, types), count in zip(parts, counts):
        first = np.cumsum(count) - count  # index of each world's first row inside this part
        dest = base[world] + (np.arange(len(world)) - first[world])
        data[dest, 0] = dx
        data[dest, 1] = dy
        data[dest, 2] = types
        base += count
    return data, offsets


class _Engine:
    """The rules of `n_worlds` ObjectWorlds, stepped together with numpy.

    Parameters
    ----------
    rules : WorldRules
    n_worlds : int

    Attributes
    ----------
    t : ndarray of intp of shape (n_worlds,)
        Steps each world has taken since it was reset.
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
        self._border = _border_walls(size_w)
        self._n_random = rules.n_money + rules.n_walls + rules.n_grass
        self._random_types = np.repeat(np.array([MONEY, WALL, GRASS], dtype=np.int8),
                                       [rules.n_money, rules.n_walls, rules.n_grass])
        # A step reads the static objects in a window of grid cells around each agent:
        # whatever its path touches or its view holds afterwards lies within `reach`.
        self._grid = math.ceil(2 * size_w / _GRID_CELL)
        self._reach = max(rules.view_size, rules.contact_radius) + 1 + rules.move_noise
        if rules.view == "global":
            self._reach = 4 * size_w
        self._window = min(self._grid, math.ceil(2 * self._reach / _GRID_CELL) + 1)
        # Only objects this close (per coordinate) to the agent can lie on its path.
        self._path_reach = rules.contact_radius + 1 + rules.move_noise
        self._minimap = math.ceil(size_w / rules.view_size)  # minimap cells are view-sized
        self.t = np.zeros(n_worlds, dtype=np.intp)
        self.observation = None

    # ----------------------------------------------------------------------------------
    def reset(self, rngs, layout=None):
        """Draw every world afresh, world ``i`` from ``rngs[i]``.

        Each world takes one block of uniforms (object positions, treasure, the episode's
        move noise, of which only the first `_NOISE_CHUNK` steps are drawn now; see the
        module's docstring), then redraws the objects that fell within `start_clearance` of
        the centre (rejection keeps the density uniform outside it). The generators are kept
        for the later chunks of noise.

        Parameters
        ----------
        rngs : list of numpy.random.Generator
            One per world.
        layout : ndarray of shape (k, 3), optional
            Rows ``[x, y, type]`` (checked by `_check_layout`) that replace the random
            objects of every world; the border, the treasure and the noise are still drawn.
        """
        rules, n = self.rules, self.n_worlds
        size_w = rules.size_w
        first = min(rules.max_steps, _NOISE_CHUNK)
        u = np.stack([rng.random(_layout_uniforms(rules) + 2 * first) for rng in rngs])
        rest = 2 * (rules.max_steps - first)
        self._noise_states = None
        if rest:
            self._noise_states = [rng.bit_generator.state for rng in rngs]
            for rng in rngs:
                _skip_uniforms(rng, rest)
        self._rngs = rngs
        n_objects = self._n_random + rules.n_enemies
        used = 2 * n_objects
        if layout is None:
            objects = (2 * size_w) * u[:, :used].reshape(n, n_objects, 2) - size_w
            clearance2 = rules.start_clearance ** 2
            near = (objects * objects).sum(axis=2) < clearance2
            for i in np.flatnonzero(near.any(axis=1)):
                while near[i].any():
                    redraw = rngs[i].random((near[i].sum(), 2))
                    objects[i, near[i]] = (2 * size_w) * redraw - size_w
                    near[i] = (objects[i] * objects[i]).sum(axis=1) < clearance2
            random_types = self._random_types
            enemies = objects[:, self._n_random:]
            objects = objects[:, :self._n_random]
        else:
            is_enemy = layout[:, 2] == ENEMY
            random_types = layout[~is_enemy, 2].astype(np.int8)
            enemies = np.broadcast_to(layout[is_enemy, :2], (n, is_enemy.sum(), 2))
            objects = np.broadcast_to(layout[~is_enemy, :2], (n, len(random_types), 2))
        coins = np.empty((n, 0, 2))
        self._treasure = np.zeros((n, 2))
        if rules.treasure:
            side = (4 * u[:, used]).astype(np.intp)
            inset = size_w - rules.treasure_margin
            self._treasure = inset * _DIRECTIONS[side]
            # x along the top and bottom sides, y along the others
            self._treasure[np.arange(n), side % 2] = inset * (2 * u[:, used + 1] - 1)
            radius, angle = u[:, used + 2:used + 2 + 2 * rules.n_treasure].reshape(n, 2, -1) \
                .transpose(1, 0, 2)
            radius = rules.treasure_radius * np.sqrt(radius)
            angle = 2 * np.pi * angle
            coins = self._treasure[:, None] + np.stack(
                [radius * np.cos(angle), radius * np.sin(angle)], axis=2)
            used += 2 + 2 * rules.n_treasure
        self._noise = rules.move_noise * (2 * u[:, used:].reshape(n, first, 2) - 1)
        self._noise_start = np.zeros(n, dtype=np.intp)  # each world's step of its _noise[i, 0]

        self._ex = enemies[..., 0].copy()
        self._ey = enemies[..., 1].copy()
        self._enemy_alive = np.ones(self._ex.shape, dtype=bool)
        self.agent = np.zeros((n, 2))
        self.t = np.zeros(n, dtype=np.intp)

        # Static objects, sorted world by world and then by grid cell.
        statics = np.concatenate([np.broadcast_to(self._border, (n,) + self._border.shape),
                                  objects, coins], axis=1)
        static_types = np.concatenate([np.full(len(self._border), WALL, dtype=np.int8),
                                       random_types,
                                       np.full(coins.shape[1], MONEY, dtype=np.int8)])
        self._n_static = len(static_types)
        cells = self._cell_index(statics[..., 0], statics[..., 1], _GRID_CELL, self._grid)
        order = np.argsort(cells.astype(np.int16), axis=1, kind="stable")  # radix sort
        self._types = static_types[order].ravel()
        order = (order + self._n_static * np.arange(n)[:, None]).ravel()
        cells = cells.ravel()[order]
        self._x = statics[..., 0].ravel()[order]
        self._y = statics[..., 1].ravel()[order]
        self._alive = np.ones(len(self._types), dtype=bool)
        # Flat start of every (world, cell), plus the end of the last one.
        n_cells = self._grid ** 2
        self._cell_start = np.zeros(n * n_cells + 1, dtype=np.intp)
        np.cumsum(np.bincount(cells + n_cells * (order // self._n_static),
                              minlength=n * n_cells), out=self._cell_start[1:])
        if rules.view == "minimap":
            m = self._minimap
            self._minimap_cell = self._cell_index(self._x, self._y, 2 * rules.view_size, m)
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
            Valid action ids (checked by the caller), for worlds that have not reached
            ``max_steps``.

        Returns
        -------
        rewards : ndarray of float64 of shape (n_worlds,)
        truncated : ndarray of bool of shape (n_worlds,)
            Whether each world's episode reached ``max_steps``.
        """
        rules, n = self.rules, self.n_worlds
        radius = rules.contact_radius
        stale = np.flatnonzero(self.t - self._noise_start == self._noise.shape[1])
        if len(stale):
            self._draw_noise(stale)
        moves = actions < 4
        direction = _DIRECTIONS[actions & 3]
        noise = self._noise[np.arange(n), self.t - self._noise_start]
        delta = np.where(moves[:, None], direction + noise, 0.0)
        dx, dy = delta[:, 0], delta[:, 1]
        ax, ay = self.agent[:, 0], self.agent[:, 1]

        # Static objects on the path: a wall cancels the move, otherwise money is collected.
        index, world = self._candidates()
        rx = self._x[index] - ax[world]
        ry = self._y[index] - ay[world]
        reach = self._path_reach
        close = np.flatnonzero((np.abs(rx) <= reach) & (np.abs(ry) <= reach)
                               & self._alive[index] & moves[world])
        cw = world[close]
        hit = close[_near_path(rx[close], ry[close], dx[cw], dy[cw], radius)]
        types = self._types[index[hit]]
        blocked = np.bincount(world[hit[types == WALL]], minlength=n) > 0
        collected = hit[(types == MONEY) & ~blocked[world[hit]]]
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
        erx = self._ex - ax[:, None]
        ery = self._ey - ay[:, None]
        touched = self._enemy_alive & walked[:, None]
        touched &= _near_path(erx, ery, dx[:, None], dy[:, None], radius)
        self._enemy_alive &= ~touched
        rewards += _REWARD_ENEMY * np.count_nonzero(touched, axis=1)
        if rules.sword:
            rewards += self._swipe(~moves, direction, erx, ery)
        self.agent = np.where(walked[:, None], self.agent + delta, self.agent)
        ax, ay = self.agent[:, 0], self.agent[:, 1]

        # Enemies inside the view chase the agent; the ones that reach it hurt.
        erx = ax[:, None] - self._ex
        ery = ay[:, None] - self._ey
        dist = np.sqrt(erx * erx + ery * ery)
        view = rules.view_size
        chasing = self._enemy_alive & (np.abs(erx) <= view) & (np.abs(ery) <= view)
        stride = np.minimum(rules.enemy_speed, dist) / np.maximum(dist, 1e-12) * chasing
        self._ex += stride * erx
        self._ey += stride * ery
        dist *= 1.0 - stride
        touched = self._enemy_alive & (dist <= radius)
        self._enemy_alive &= ~touched
        rewards += _REWARD_ENEMY * np.count_nonzero(touched, axis=1)

        if rules.view == "minimap":
            self._visit()
        self.t += 1
        self.observation = self._observe(index, world)
        return rewards, self.t >= rules.max_steps

    def take(self, worlds):
        """A new engine whose world ``j`` is a copy of world ``worlds[j]``, mid-episode.

        For look-ahead search. A copy holds the world's objects, enemies, agent, step count and
        move noise, the chunks not drawn yet included: under the same actions it goes through
        exactly the transitions the original would. Stepping a copy changes neither this
        engine nor its generators (a copy shares them only to draw later chunks, which
        `_draw_noise` does without moving them).

        Parameters
        ----------
        worlds : ndarray of int of shape (k,)
            Worlds of this engine, repeats allowed (valid ids, checked by the caller).

        Returns
        -------
        _Engine
        """
        worlds = np.asarray(worlds, dtype=np.intp)
        return _gather([self], np.zeros(len(worlds), dtype=np.intp), worlds)

    def replaced(self, worlds, other):
        """A new engine: this one with world ``worlds[j]`` replaced by world ``j`` of `other`.

        Every world is copied as by `take`, with its step count, so a world reset on its own
        (`other` freshly reset) starts its episode while the others go on with theirs.

        Parameters
        ----------
        worlds : ndarray of int of shape (k,)
            Distinct worlds of this engine (valid ids, checked by the caller).
        other : _Engine
            An engine of ``k`` worlds of the same rules, whose worlds hold as many objects of
            each type as this engine's (checked by the caller).

        Returns
        -------
        _Engine
        """
        source = np.zeros(self.n_worlds, dtype=np.intp)
        index = np.arange(self.n_worlds)
        source[worlds] = 1
        index[worlds] = np.arange(len(worlds))
        return _gather([self, other], source, index)

    # ----------------------------------------------------------------------------------
    def _draw_noise(self, worlds):
        """Draw the move noise of the next `_NOISE_CHUNK` steps of `worlds` where each
        stream keeps it.

        Each generator is set to the kept state, draws, and is put back where it was, so its
        own position (the next episode's start) does not move. A world's last chunk may be
        shorter than ``_noise.shape[1]``; the rest of its row is never read.
        """
        rules = self.rules
        for i in worlds:
            count = min(_NOISE_CHUNK, rules.max_steps - self.t[i])
            rng = self._rngs[i]
            bit_generator = rng.bit_generator
            position = bit_generator.state
            bit_generator.state = self._noise_states[i]
            u = rng.random(2 * count)
            self._noise_states[i] = bit_generator.state
            bit_generator.state = position
            self._noise[i, :count] = rules.move_noise * (2 * u.reshape(count, 2) - 1)
        self._noise_start[worlds] = self.t[worlds]

    def _swipe(self, swiping, direction, erx, ery):
        """Rewards of the swipes; a swipe that hits exactly one enemy kills it."""
        size = self.rules.swipe_size
        dx, dy = direction[:, None, 0], direction[:, None, 1]
        along = erx * dx + ery * dy
        across = erx * dy - ery * dx
        inside = self._enemy_alive & swiping[:, None]
        inside &= (along > 0) & (along <= size) & (np.abs(across) <= size / 2)
        n_hit = np.count_nonzero(inside, axis=1)
        self._enemy_alive &= ~(inside & (n_hit == 1)[:, None])
        rewards = np.select([n_hit == 0, n_hit == 1], [_REWARD_SWIPE_NONE, _REWARD_SWIPE_ONE],
                            _REWARD_SWIPE_MANY)
        return np.where(swiping, rewards, 0.0)

    def _cell_index(self, x, y, cell, n_cells):
        """Row-major index of the `cell`-sized grid cell holding each position."""
        size_w = self.rules.size_w
        # Positions lie inside the world, so truncation is the floor.
        i = np.minimum(((x + size_w) * (1 / cell)).astype(np.intp), n_cells - 1)
        j = np.minimum(((y + size_w) * (1 / cell)).astype(np.intp), n_cells - 1)
        return j * n_cells + i

    def _candidates(self):
        """Static objects (dead ones too) in the window of cells around each agent.

        The window is `_window` cells high and wide; its cells in one grid row are
        consecutive in the sorted order, so the window is one slice per row.

        Returns their flat indices and world ids, world after world.
        """
        g, w = self._grid, self._window
        corner = (self.agent - self._reach + self.rules.size_w) // _GRID_CELL
        corner = np.clip(corner.astype(np.intp), 0, g - w)
        first_cell = ((corner[:, 1, None] + np.arange(w)) * g + corner[:, 0, None]
                      + (g * g) * np.arange(self.n_worlds)[:, None]).ravel()
        first = self._cell_start[first_cell]
        count = self._cell_start[first_cell + w] - first
        end = np.cumsum(count)
        index = np.repeat(first - (end - count), count) + np.arange(end[-1])
        return index, index // self._n_static

    def _observe(self, index, world):
        """The agents' observations, given the static candidates `index` of `world`."""
        rules = self.rules
        ax, ay = self.agent[:, 0], self.agent[:, 1]
        rx = self._x[index] - ax[world]
        ry = self._y[index] - ay[world]
        erx = self._ex - ax[:, None]
        ery = self._ey - ay[:, None]
        seen = self._alive[index]
        enemy_seen = self._enemy_alive
        if rules.view != "global":
            view = rules.view_size
            seen &= (np.abs(rx) <= view) & (np.abs(ry) <= view)
            enemy_seen = enemy_seen & (np.abs(erx) <= view) & (np.abs(ery) <= view)
        enemy_world, enemy = np.nonzero(enemy_seen)
        seen = np.flatnonzero(seen)
        parts = [
            (world[seen], rx[seen], ry[seen], self._types[index[seen]]),
            (enemy_world, erx[enemy_world, enemy], ery[enemy_world, enemy], ENEMY),
        ]
        if rules.view in ("minimap", "arrow"):
            marker_world, xy, types = self._markers()
            xy -= self.agent[marker_world]
            if rules.view == "minimap":  # the whole world shrunk into the view
                xy *= rules.view_size / (2 * rules.size_w)
            parts.append((marker_world, xy[:, 0], xy[:, 1], types))
        return _ragged_concat(self.n_worlds, parts)

    def _markers(self):
        """The treasure views' marker objects in world coordinates, world after world.

        Minimap: a `MONEY_MARKER` at the centre of each unvisited cell holding money, then a
        `TREASURE_MARKER` at the centre of the treasure's cell until it is visited (centres of
        the cells' parts inside the world). Arrow: one `ARROW` at ``0.9 * view_size`` from
        the agent toward the treasure's centre.
        """
        rules = self.rules
        if rules.view == "arrow":
            to_goal = self._treasure - self.agent
            dist = np.hypot(to_goal[:, 0], to_goal[:, 1])[:, None]
            arrow = np.divide(_ARROW_DISTANCE * rules.view_size * to_goal, dist,
                              out=np.zeros_like(to_goal), where=dist > 0)
            return np.arange(self.n_worlds), self.agent + arrow, ARROW
        m = self._minimap
        goal_cell = self._cell_index(self._treasure[:, 0], self._treasure[:, 1],
                                     2 * rules.view_size, m)
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
        cell = self._cell_index(self.agent[:, 0], self.agent[:, 1],
                                2 * self.rules.view_size, self._minimap)
        self._visited[np.arange(self.n_worlds), cell] = True

    def world_objects(self, i):
        """Objects of world `i` in world coordinates, rows ``[x, y, type]`` (for rendering).

        The live objects, then the markers of the treasure views.
        """
        own = slice(i * self._n_static, (i + 1) * self._n_static)
        alive = self._alive[own]
        enemies = self._enemy_alive[i]
        rows = [np.column_stack([self._x[own][alive], self._y[own][alive],
                                 self._types[own][alive]]),
                np.column_stack([self._ex[i, enemies], self._ey[i, enemies],
                                 np.full(enemies.sum(), ENEMY)])]
        if self.rules.view in ("minimap", "arrow"):
            world, xy, types = self._markers()
            mine = world == i
            rows.append(np.column_stack([xy[mine], np.broadcast_to(types, world.shape)[mine]]))
        return np.concatenate(rows)


def _joined(parts):
    """`parts` concatenated along their first axis (the only part itself, not copied)."""
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


def _gather(engines, source, worlds):
    """A new engine whose world ``j`` is a copy of world ``worlds[j]`` of
    ``engines[source[j]]``, mid-episode (see `_Engine.take`).

    The engines have the same rules and their worlds as many objects of each type; what only
    depends on the rules is shared with the first engine.
    """
    first = engines[0]
    s, n_cells = first._n_static, first._grid ** 2
    index = np.cumsum([0] + [engine.n_worlds for engine in engines])[source] + worlds
    k = len(index)  # index: into the worlds of all the engines, engine after engine
    new = copy.copy(first)
    new.n_worlds = k
    names = ["_x", "_y", "_types", "_alive"]
    names += ["_minimap_cell"] if first.rules.view == "minimap" else []
    for name in names:  # flat, world after world
        flat = _joined([getattr(engine, name) for engine in engines])
        setattr(new, name, flat.reshape(-1, s)[index].ravel())
    own_start = _joined([  # each world's cell starts, counted from its first object
        engine._cell_start[:-1].reshape(engine.n_worlds, n_cells)
        - s * np.arange(engine.n_worlds)[:, None] for engine in engines])
    new._cell_start = np.append((own_start[index] + s * np.arange(k)[:, None]).ravel(), k * s)
    names = ["_ex", "_ey", "_enemy_alive", "agent", "_treasure", "_noise", "_noise_start", "t"]
    names += ["_cell_money", "_visited"] if first.rules.view == "minimap" else []
    for name in names:  # one row per world
        setattr(new, name, _joined([getattr(engine, name) for engine in engines])[index])
    rngs = [rng for engine in engines for rng in engine._rngs]
    new._rngs = [rngs[i] for i in index]
    if first._noise_states is not None:  # _draw_noise replaces these dicts, never edits them
        states = [state for engine in engines for state in engine._noise_states]
        new._noise_states = [states[i] for i in index]
    data = _joined([engine.observation[0] for engine in engines])
    shifts = np.cumsum([0] + [len(engine.observation[0]) for engine in engines])
    offsets = np.append(_joined([engine.observation[1][:-1] + shift
                                 for engine, shift in zip(engines, shifts)]), len(data))
    sizes = np.diff(offsets)[index]
    new_offsets = np.zeros(k + 1, dtype=np.intp)
    np.cumsum(sizes, out=new_offsets[1:])
    rows = np.repeat(offsets[index] - new_offsets[:-1], sizes) + np.arange(new_offsets[-1])
    new.observation = (data[rows], new_offsets)
    return new
