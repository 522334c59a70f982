"""A look-ahead planner with the simulator in hand: the ceiling of the game, not a learner.

`LookaheadPlanner` plays a world whose whole state it copies: it sees every object, not the
agent's view, and it simulates the world's own future, move noise included. Each world's
generator draws the move noise of the whole episode up front (see `envs._engine`), and a copy
made with `_Engine.take` replays exactly that noise, so a simulated action sequence earns
exactly the rewards it would earn in the real world: the search is exact, not an estimate
over noise the agent cannot know (so the ceiling is that of a player who knows the noise
too). It plans, it does not learn; its scores are the reference a learner's score is read
against, as a fraction of the best play found.

Search. A beam search over action sequences, replanned at every step: copies of the world
take every action, the `width` best sequences (reward so far plus the value of where they
end) are extended by every action again, `depth` times; the first action of the best
sequence is played. All candidates of many worlds step at once on one vectorised engine.

Value of a search node. A route plan: at the root, a beam search over the orders in which to
collect the world's targets (every coin, and with the sword every enemy, worth the +300 of
a swipe that hits it alone) finds the most valuable route that fits in the steps left. The
steps of a leg are counted on the agent's lattice of unit moves: the fewest moves after
which the path touches the coin, or a swipe's square holds the enemy, plus the swipe
(walls, the enemies' chase and the noise are left to the exact search). A node is worth the
targets of the root's route it can still collect, in order from where it stands, each
weighed by ``discount ** steps`` until the episode ends.
"""
from numbers import Real

import numpy as np

from ._rules import _REWARD_MONEY, _REWARD_SWIPE_ONE, MONEY, _check_int
from .batched import BatchedObjectWorld, _unwrapped_world

__all__ = ["LookaheadPlanner"]

_MAX_NODES = 16384  # search nodes held at a time; worlds are planned in groups that fit
_ROUTE_RATE = 20.0  # reward per step that ranks partial routes of different values
_ROUTE_SEED = 0  # seeds the keys that hash sets of visited targets (fixed: deterministic)
_TIE_BREAK = 1e-3  # reward per unit of distance to the next target (far below any reward)
_EPS = 1e-9  # keeps a leg that ends exactly at the contact distance from costing a step more


def _coin_legs(px, py, cx, cy, radius):
    """Unit moves from ``(px, py)`` until the path touches the coin at ``(cx, cy)``.

    The agent moves along one axis last; the moves along the other one leave it at the floor
    or the ceiling of that offset, and those along the last axis stop as soon as the coin
    lies within `radius` of the path. Returns the number of moves and where they end (the
    fewest of the four ways; broadcast over the inputs).
    """
    dx, dy = cx - px, cy - py
    ax, ay = np.abs(dx), np.abs(dy)
    best = None
    for last_is_x in (True, False):
        last, other = (ax, ay) if last_is_x else (ay, ax)
        for n_other in (np.floor(other), np.ceil(other)):
            miss = other - n_other
            reach = np.sqrt(np.maximum(radius * radius - miss * miss, 0.0))
            n_last = np.maximum(np.ceil(last - reach - _EPS), 0.0)
            n = np.where(np.abs(miss) <= radius, n_last + n_other, np.inf)
            nx, ny = (n_last, n_other) if last_is_x else (n_other, n_last)
            if best is None:
                best, bx, by = n, nx, ny
            else:
                better = n < best
                best = np.where(better, n, best)
                bx = np.where(better, nx, bx)
                by = np.where(better, ny, by)
    return best, px + np.sign(dx) * bx, py + np.sign(dy) * by


def _foe_legs(px, py, ex, ey, size):
    """Unit moves from ``(px, py)`` until the enemy at ``(ex, ey)`` fills a swipe's square, plus
    the swipe: the enemy must lie ``(0, size]`` ahead along one axis and within ``size / 2``
    across. Returns the number of steps and where the moves end.
    """
    dx, dy = ex - px, ey - py
    ax, ay = np.abs(dx), np.abs(dy)
    ahead_x = np.maximum(np.ceil(ax - size - _EPS), 0.0)
    ahead_y = np.maximum(np.ceil(ay - size - _EPS), 0.0)
    across_x = np.maximum(np.ceil(ax - size / 2 - _EPS), 0.0)
    across_y = np.maximum(np.ceil(ay - size / 2 - _EPS), 0.0)
    swipe_x = np.where(ax > 0, ahead_x + across_y, np.inf)  # swiping left or right
    swipe_y = np.where(ay > 0, ahead_y + across_x, np.inf)
    use_x = swipe_x <= swipe_y
    nx = np.where(use_x, ahead_x, across_x)
    ny = np.where(use_x, across_y, ahead_y)
    return np.minimum(swipe_x, swipe_y) + 1, px + np.sign(dx) * nx, py + np.sign(dy) * ny


def _plan_routes(x, y, value, n_coins, valid, start, budget, rules, width):
    """The most valuable order in which each world can take its targets within `budget` steps.

    Beam search over routes: every partial route is extended by every target it has not
    taken whose leg still fits; of the routes that took the same set and end at the same
    target only the fastest is kept, then the `width` best of each world (value minus
    `_ROUTE_RATE` per step).

    Parameters
    ----------
    x, y, value : ndarray of shape (n_worlds, n_targets)
        The targets: the first `n_coins` columns coins, the others enemies.
    n_coins : int
    valid : ndarray of bool of shape (n_worlds, n_targets)
        Targets still there.
    start : ndarray of shape (n_worlds, 2)
    budget : ndarray of int of shape (n_worlds,)
        Each world's steps left.
    rules : WorldRules
    width : int

    Returns
    -------
    routes : ndarray of intp of shape (n_worlds, length)
        Each world's best route (most value, then fewest steps): target columns, padded
        with -1.
    """
    n_worlds, n_targets = x.shape
    keys = np.random.default_rng(_ROUTE_SEED).integers(1 << 62, size=n_targets, dtype=np.int64)
    world = np.arange(n_worlds)  # the world of each partial route
    px, py = start[:, 0], start[:, 1]
    taken = ~valid
    taken_key = np.zeros(n_worlds, dtype=np.int64)
    steps = np.zeros(n_worlds)
    got = np.zeros(n_worlds)
    route = np.zeros((n_worlds, 0), dtype=np.intp)
    best = np.full((n_worlds, max(n_targets, 1)), -1, dtype=np.intp)
    best_got = np.zeros(n_worlds)
    best_steps = np.zeros(n_worlds)
    while True:
        legs = [_coin_legs(px[:, None], py[:, None], x[world, :n_coins], y[world, :n_coins],
                           rules.contact_radius)]
        if n_targets > n_coins:
            legs.append(_foe_legs(px[:, None], py[:, None], x[world, n_coins:],
                                  y[world, n_coins:], rules.swipe_size))
        leg, end_x, end_y = (np.concatenate(part, axis=1) for part in zip(*legs))
        arrival = steps[:, None] + leg
        parent, target = np.nonzero(~taken & (arrival <= budget[world][:, None]))
        if len(parent) == 0:
            break
        w = world[parent]
        s = arrival[parent, target]
        k = taken_key[parent] ^ keys[target]
        order = np.lexsort((s, target, k, w))
        parent, target, w, s, k = parent[order], target[order], w[order], s[order], k[order]
        fastest = np.ones(len(w), dtype=bool)
        fastest[1:] = (w[1:] != w[:-1]) | (k[1:] != k[:-1]) | (target[1:] != target[:-1])
        parent, target, w, s, k = (a[fastest] for a in (parent, target, w, s, k))
        v = got[parent] + value[w, target]
        order = np.lexsort((s, -(v - _ROUTE_RATE * s), w))
        rank = np.arange(len(order)) - np.searchsorted(w[order], w[order])
        order = order[rank < width]
        parent, target, w, s, k, v = (a[order] for a in (parent, target, w, s, k, v))
        route = np.column_stack([route[parent], target])
        taken = taken[parent]
        taken[np.arange(len(parent)), target] = True
        px, py = end_x[parent, target], end_y[parent, target]
        world, steps, taken_key, got = w, s, k, v
        # Every partial route is a route: keep each world's best so far.
        order = np.lexsort((steps, -got, world))
        head = order[np.r_[True, world[order][1:] != world[order][:-1]]]
        hw = world[head]
        better = (got[head] > best_got[hw]) | ((got[head] == best_got[hw])
                                               & (steps[head] < best_steps[hw]))
        head, hw = head[better], hw[better]
        best[hw, :route.shape[1]] = route[head]
        best_got[hw], best_steps[hw] = got[head], steps[head]
    length = max(1, int((best >= 0).sum(axis=1).max()))
    return best[:, :length]


class _Targets:
    """The targets and route of each root world of a search, and the value of search nodes.

    Parameters
    ----------
    root : _Engine
        The worlds to plan, as they stand.
    route_width : int
    discount : float
    """

    def __init__(self, root, route_width, discount):
        rules = root.rules
        n, s = root.n_worlds, root._n_static
        self.rules, self.discount = rules, discount
        # Every world has the same static types (in its own order), so as many coins.
        types = root._types.reshape(n, s)
        self.coin_index = np.nonzero(types == MONEY)[1].reshape(n, -1)
        self.n_coins = self.coin_index.shape[1]
        x = np.take_along_axis(root._x.reshape(n, s), self.coin_index, axis=1)
        y = np.take_along_axis(root._y.reshape(n, s), self.coin_index, axis=1)
        valid = np.take_along_axis(root._alive.reshape(n, s), self.coin_index, axis=1)
        value = np.full(x.shape, _REWARD_MONEY)
        if rules.sword:
            x, y = np.hstack([x, root._ex]), np.hstack([y, root._ey])
            valid = np.hstack([valid, root._enemy_alive])
            value = np.hstack([value, np.full(root._ex.shape, _REWARD_SWIPE_ONE)])
        self.x, self.y, self.value = x, y, value
        self.route = _plan_routes(x, y, value, self.n_coins, valid, root.agent,
                                  rules.max_steps - root.t, rules, route_width)

    def node_values(self, plan, group, steps_left):
        """The value of the nodes `plan` (copies of root worlds `group`): the discounted value
        of the root route's targets each can still take, in order, within `steps_left`.
        """
        rules, n = self.rules, plan.n_worlds
        if self.x.shape[1] == 0:  # nothing to collect
            return np.zeros(n)
        node = np.arange(n)[:, None]
        # Every target of the node's copy, columns as in the root's: coins never move, the
        # enemies are where the copy has them.
        there = plan._alive.reshape(n, plan._n_static)[node, self.coin_index[group]]
        x, y = self.x[group], self.y[group]
        if rules.sword:
            there = np.hstack([there, plan._enemy_alive])
            x = np.hstack([x[:, :self.n_coins], plan._ex])
            y = np.hstack([y[:, :self.n_coins], plan._ey])
        route = self.route[group]
        on_route = route >= 0
        column = np.where(on_route, route, 0)
        is_coin = column < self.n_coins
        there = on_route & np.take_along_axis(there, column, axis=1)
        tx = np.take_along_axis(x, column, axis=1)
        ty = np.take_along_axis(y, column, axis=1)
        worth = np.take_along_axis(self.value[group], column, axis=1)
        px, py = plan.agent[:, 0], plan.agent[:, 1]
        # Ties in whole steps go to the node nearer its next target as the crow flies: of two
        # ways that seem as long, the one that goes around an obstacle has got past it.
        ahead = np.argmax(there, axis=1)
        gap = np.hypot(tx[node[:, 0], ahead] - px, ty[node[:, 0], ahead] - py)
        steps = np.zeros(n)
        total = np.where(there.any(axis=1), -_TIE_BREAK * gap, 0.0)
        for k in range(route.shape[1]):
            leg, end_x, end_y = _coin_legs(px, py, tx[:, k], ty[:, k], rules.contact_radius)
            if rules.sword:
                foe_leg = _foe_legs(px, py, tx[:, k], ty[:, k], rules.swipe_size)
                leg, end_x, end_y = (np.where(is_coin[:, k], a, b)
                                     for a, b in zip((leg, end_x, end_y), foe_leg))
            go = there[:, k]
            steps = np.where(go, steps + leg, steps)
            total += np.where(go & (steps <= steps_left),
                              worth[:, k] * self.discount ** steps, 0.0)
            px, py = np.where(go, end_x, px), np.where(go, end_y, py)
        return total


class LookaheadPlanner:
    """Beam search over action sequences on exact copies of the world: an upper reference.

    Not a learner: it needs the environment itself, copies the world's whole state (every
    object and the pre-drawn move noise, see the module's docstring) and simulates it, so
    its score is what planning with a perfect model achieves, the ceiling that learners are
    read against. It replans at every step: the `width` best action sequences are extended
    by every action `depth` times on copies of the world, ranked by their reward plus the
    value of where they end (a route plan over the world's coins, and with the sword its
    enemies), and the first action of the best one is played. It is deterministic.

    Parameters
    ----------
    depth : int, default=5
        Actions per searched sequence (fewer near the end of the episode).
    width : int, default=16
        Sequences kept per world after each level of the search (the beam).
    route_width : int, default=50
        Partial routes kept per world by the route plan that values the search's nodes.
    discount : float, default=0.95
        A route target reached ``k`` steps after a node counts ``discount ** k`` of its
        reward, in ``(0, 1]``: near targets first.

    Raises
    ------
    TypeError
        If a parameter is not of its type (`depth`, `width` and `route_width` ints,
        `discount` a number).
    ValueError
        If it is out of range.

    Attributes
    ----------
    simulated_steps : int
        World steps simulated by the search so far (its compute; ``act`` adds to it).

    Notes
    -----
    Interface: `act` returns the action for the env's current state, reading the state
    from the env (an `ObjectWorldEnv` or a `BatchedObjectWorld`, possibly wrapped);
    `play` resets the env and plays a whole episode. A step simulates at most
    ``n_actions * (1 + width * (depth - 1))`` world steps per world. Any rules work,
    treasure included; the views do not matter, the planner sees the whole world.

    Examples
    --------
    >>> import envs
    >>> env = envs.ObjectWorldEnv()
    >>> planner = envs.LookaheadPlanner(depth=2, width=4)
    >>> obs, info = env.reset(seed=0)
    >>> action = planner.act(env)  # from the env's state, not from obs
    >>> obs, reward, terminated, truncated, info = env.step(action)
    >>> actions, rewards = planner.play(env, seed=0)  # reset, then a whole episode
    >>> actions.shape, rewards.shape, int(actions[0]) == action
    ((50,), (50,), True)
    """

    def __init__(self, depth=5, width=16, route_width=50, discount=0.95):
        self.depth = _check_int("depth", depth, 1)
        self.width = _check_int("width", width, 1)
        self.route_width = _check_int("route_width", route_width, 1)
        if not isinstance(discount, Real) or isinstance(discount, bool):
            raise TypeError(f"discount must be a number, got {discount!r}")
        if not 0.0 < discount <= 1.0:
            raise ValueError(f"discount must lie in (0, 1], got {discount!r}")
        self.discount = float(discount)
        self.simulated_steps = 0

    def __repr__(self):
        return (f"LookaheadPlanner(depth={self.depth}, width={self.width}, "
                f"route_width={self.route_width}, discount={self.discount})")

    def act(self, env):
        """The planned action of every world of `env` in its current state.

        Parameters
        ----------
        env : ObjectWorldEnv or BatchedObjectWorld
            Possibly wrapped; reset and not yet truncated. Only read, never stepped.

        Returns
        -------
        action : int, or ndarray of intp of shape (num_envs,) for a BatchedObjectWorld

        Raises
        ------
        TypeError
            If `env` is not an ObjectWorld env.
        RuntimeError
            If it was not reset, or the episode of one of its worlds is over.
        """
        base, engine = self._unwrap(env)
        n_actions = engine.rules.n_actions
        steps_left = engine.rules.max_steps - engine.t
        actions = np.empty(engine.n_worlds, dtype=np.intp)
        for left in np.unique(steps_left):  # worlds reset on their own are at other steps
            same = np.flatnonzero(steps_left == left)
            horizon = min(self.depth, int(left))
            kept = min(self.width, n_actions ** (horizon - 1))
            group = max(1, _MAX_NODES // (kept * n_actions))
            for start in range(0, len(same), group):
                worlds = same[start:start + group]
                actions[worlds] = self._search(engine, worlds, horizon)
        return actions if isinstance(base, BatchedObjectWorld) else int(actions[0])

    def play(self, env, seed=None):
        """Reset `env` with `seed` and play one whole episode with `act`.

        Parameters
        ----------
        env : ObjectWorldEnv or BatchedObjectWorld
            Possibly wrapped.
        seed : None, int or sequence of int, default=None
            Passed to ``env.reset`` (a sequence: one per world of a `BatchedObjectWorld`).

        Returns
        -------
        actions : ndarray of intp of shape (max_steps,) or (max_steps, num_envs)
        rewards : ndarray of float64 of the same shape

        Raises
        ------
        TypeError
            If `env` is not an ObjectWorld env.
        """
        base = self._unwrap(env, reset=False)[0]
        env.reset(seed=seed)
        actions, rewards = [], []
        for _ in range(base.rules.max_steps):
            action = self.act(env)
            rewards.append(env.step(action)[1])
            actions.append(action)
        return np.array(actions, dtype=np.intp), np.array(rewards, dtype=np.float64)

    @staticmethod
    def _unwrap(env, reset=True):
        """`env` unwrapped and its engine, checked to be reset and mid-episode if `reset`."""
        base = _unwrapped_world(env, "the planner")
        engine = base._engine
        if reset and engine.observation is None:
            raise RuntimeError("call env.reset() before planning")
        if reset and (engine.t >= engine.rules.max_steps).any():
            raise RuntimeError(f"the episode is over (truncated after {engine.rules.max_steps} "
                               "steps); call env.reset()")
        return base, engine

    def _search(self, engine, worlds, horizon):
        """The first action of the best sequence found for each of `worlds` of `engine`."""
        rules = engine.rules
        n_actions, n = rules.n_actions, len(worlds)
        plan = engine.take(worlds)
        targets = _Targets(plan, self.route_width, self.discount)
        group = np.arange(n)  # the root world of each node
        reward = np.zeros(n)  # along each node's actions
        first = np.zeros(n, dtype=np.intp)
        kept = group
        for level in range(horizon):
            parent = np.repeat(kept, n_actions)
            action = np.tile(np.arange(n_actions), len(kept))
            plan = plan.take(parent)
            reward = reward[parent] + plan.step(action)[0]
            first = action if level == 0 else first[parent]
            group = group[parent]
            self.simulated_steps += len(parent)
            score = reward + targets.node_values(plan, group, rules.max_steps - plan.t)
            per_world = len(group) // n  # nodes are grouped world after world
            kept = np.arange(len(group))
            if level < horizon - 1 and per_world > self.width:
                best = np.argsort(-score.reshape(n, per_world), axis=1, kind="stable")
                kept = (best[:, :self.width] + per_world * np.arange(n)[:, None]).ravel()
        best = score.reshape(n, -1).argmax(axis=1)
        return first.reshape(n, -1)[np.arange(n), best]
