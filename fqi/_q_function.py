"""The Q-function of an FQI iteration: one fitted clone of the regressor per action."""
import warnings
from collections import deque
from functools import partial

import numpy as np
from sklearn.base import clone

from boxtrees._threads import side_by_side, threads_for

from ._calls import _SMALL_BATCH, _regressor_calls

__all__ = []


class _QFunction:
    """``Q_n``: a regressor per action, fitted at iteration `iteration`.

    Parameters
    ----------
    models : list of regressors
        One per action, fitted.
    iteration : int
        The iteration that fitted them (named in errors).
    """

    def __init__(self, models, iteration):
        self.models, self.iteration = models, iteration

    @classmethod
    def fit(cls, regressor, data, targets, n_actions, rng, previous, iteration, n_jobs=1):
        """A clone of `regressor` per action, fitted on the transitions with that action;
        each clone's ``random_state`` parameters (nested ones too) drawn from `rng`. An action
        absent from the data keeps its `previous` model (with a warning), or is an error
        without one.

        The clones are fitted side by side in up to `n_jobs` threads, the calling one among
        them, each taking the next clone, the largest data sets first (a clone's own
        threads, a forest's ``n_jobs``, are its own business): one clone's serial parts and
        its last trees overlap the others' work instead of leaving cores idle.
        """
        models, fits = [], []
        for action in range(n_actions):
            mask = data.actions == action
            if not mask.any():
                if previous is None:
                    raise ValueError(f"no transition with action {action} in the data; "
                                     f"collect more samples per iteration")
                warnings.warn(f"no transition with action {action} in the data; keeping its "
                              f"previous Q-function", RuntimeWarning, stacklevel=4)
                models.append(previous.models[action])
                continue
            models.append(_seeded_clone(regressor, rng))
            fits.append((-mask.sum(), action, partial(_fit_into, models, action, data.states,
                                                      targets, mask)))
        queue = deque(fit for _, _, fit in sorted(fits, key=lambda fit: fit[:2]))
        side_by_side([partial(_run_all, queue)] * min(threads_for(n_jobs), max(len(fits), 1)),
                     "fqi-actions")
        return cls(models, iteration)

    def future(self, data, n_jobs=1, split=None, supported=None):
        """``max_a Q(s', a)`` for the next state of every transition of `data`, over the
        actions `supported` there (a mask of shape ``(len(data), n_actions)``; None: every
        action). `split` is `_DoubleQFunction`'s; unused here."""
        return _masked(self.values(data.next_states, n_jobs), supported).max(axis=1)

    def backups(self, data, targets, discounts, n_backups, split=None, supported=None):
        """`targets` after `n_backups` fitted-Q backups that keep these models' trees.

        Each backup sets every leaf's value to the mean target of the transitions of the
        data set (of the leaf's action) that reach it, and then every target to ``r +
        discount * max_a Q(s', a)``, ``Q(s', a)`` the mean over the trees of the values of
        the leaves ``s'`` reaches (a leaf no transition reaches is left out of that mean; a
        next state with no such leaf in any tree keeps the model's own prediction). With
        the structure fixed this is a kernel-based value iteration, a contraction: value
        travels one step per backup for the cost of two table lookups per tree.

        Parameters
        ----------
        data : _Transitions
        targets : ndarray of shape (len(data),)
            The first backup's targets.
        discounts : ndarray of shape (len(data),)
            ``gamma``, or 0 after a termination.
        n_backups : int
        split : None
            `_DoubleQFunction`'s; unused here.
        supported : ndarray of bool of shape (len(data), n_actions), default=None
            The actions the maximum is taken over at each next state (None: every one).

        Returns
        -------
        targets : ndarray of shape (len(data),)
        """
        rows = np.ones(len(data), dtype=bool)
        tables = self._leaf_tables(data, rows)
        for _ in range(n_backups):
            q = _leaf_values(tables, targets, data.actions, rows)
            targets = data.rewards + discounts * _masked(q, supported).max(axis=1)
        return targets

    def _leaf_tables(self, data, rows):
        """A `_LeafTable` per action: where the transitions of `rows` (a mask of `data`)
        with that action, and every next state of `data`, fall in that action's trees."""
        return [_LeafTable(model, data.states[rows & (data.actions == action)],
                           data.next_states)
                for action, model in enumerate(self.models)]

    def values(self, batch, n_jobs=1):
        """``Q(s, a)`` of every action for the observations of `batch`, shape ``(n,
        n_actions)``, predicted in up to `n_jobs` threads, the calling one among them (the
        actions split between them; a box forest then predicts on its share of the cores,
        see `boxtrees._threads.threads_for`) and checked to be one finite value per
        observation. A batch of fewer than `_calls._SMALL_BATCH` observations (an
        environment step's) is predicted in the calling thread alone, starting no thread
        (`_calls._regressor_calls`)."""
        n_threads = (min(threads_for(n_jobs), len(self.models)) if len(batch) >= _SMALL_BATCH
                     else 1)   # (an environment step's batch: handing it over costs more)
        edges = np.linspace(0, len(self.models), n_threads + 1).astype(int)
        predictions = [prediction for part in side_by_side(
            [partial(_predictions, self.models[a:b], batch) for a, b in zip(edges, edges[1:])],
            "fqi-actions") for prediction in part]
        q = np.empty((len(batch), len(self.models)))
        for action, prediction in enumerate(predictions):
            q[:, action] = _checked_prediction(
                prediction, len(batch), lambda: f"iteration {self.iteration}'s Q-function of "
                f"action {action} ({self.models[action]!r})")
        return q


class _ActionInputQFunction:
    """``Q_n`` as one regressor over each observation encoded with its action (FQI's
    ``action_input``): by default the observation followed by the action's one-hot columns
    (`_with_actions`), or the user's encoding. The actions share its splits on the
    observation, so their Q-values err together, where one regressor per action errs for
    each apart; an encoding that maps symmetric state-actions to one input also shares
    their data.

    Parameters
    ----------
    model : regressor
        Fitted on ``encode(states, actions)``.
    n_actions : int
        The number of actions.
    iteration : int
        The iteration that fitted it (named in errors).
    encode : callable or None
        ``encode(observations, actions)``: the regressor's input, one row per observation;
        None: `_with_actions`.
    """

    encode = None  # (and so in the saves of versions that had no other encoding)

    def __init__(self, model, n_actions, iteration, encode):
        self.model, self.n_actions, self.iteration = model, n_actions, iteration
        self.encode = encode

    @property
    def models(self):
        """The one regressor, in a list (as `_QFunction.models`)."""
        return [self.model]

    @classmethod
    def fit(cls, regressor, data, targets, n_actions, rng, previous, iteration, encode):
        """A clone of `regressor` (its ``random_state`` parameters drawn from `rng`) fitted
        on every transition, encoded; `previous` is unused (every action is in the input)."""
        model = _seeded_clone(regressor, rng)
        with _regressor_calls():
            model = model.fit(_encoded(encode, data.states, data.actions, n_actions), targets)
        return cls(model, n_actions, iteration, encode)

    def _every_action(self, batch):
        """Each observation of `batch` with each action in turn, encoded: ``n_actions`` rows
        per observation, observation by observation."""
        return _encoded(self.encode, batch[np.repeat(np.arange(len(batch)), self.n_actions)],
                        np.tile(np.arange(self.n_actions), len(batch)), self.n_actions)

    def values(self, batch, n_jobs=1):
        """``Q(s, a)`` of every action for the observations of `batch`, shape ``(n,
        n_actions)``, in one call of the regressor's ``predict`` (its own threads: `n_jobs`
        is unused here), checked as in `_QFunction.values`."""
        n = len(batch) * self.n_actions
        with _regressor_calls(n):
            prediction = self.model.predict(self._every_action(batch))
        q = _checked_prediction(prediction, n,
                                lambda: f"iteration {self.iteration}'s Q-function "
                                        f"({self.model!r})")
        return q.reshape(len(batch), self.n_actions)

    future = _QFunction.future  # max_a Q(s', a) through `values`, as for one per action

    def backups(self, data, targets, discounts, n_backups, split=None, supported=None):
        """`_QFunction.backups` on the one regressor: its leaves hold the mean targets of
        every transition that reaches them, whatever its action."""
        table = _LeafTable(self.model,
                           _encoded(self.encode, data.states, data.actions, self.n_actions),
                           self._every_action(data.next_states))
        for _ in range(n_backups):
            q = table.next_values(targets).reshape(len(data), self.n_actions)
            targets = data.rewards + discounts * _masked(q, supported).max(axis=1)
        return targets


def _encoded(encode, states, actions, n_actions):
    """The observations `states` encoded with their `actions` (of `n_actions`) by `encode`,
    or by `_with_actions` if it is None."""
    if encode is None:
        return _with_actions(states, actions, n_actions)
    return encode(states, actions)


def _with_actions(states, actions, n_actions):
    """The encoding of ``action_input=True``: the rows of the observation matrix `states`
    followed by the one-hot columns of `actions` (``n_actions`` columns, in the matrix's
    dtype)."""
    onehot = np.zeros((len(states), n_actions), dtype=states.dtype)
    onehot[np.arange(len(states)), actions] = 1
    return np.hstack([states, onehot])


def _fit_into(models, index, states, targets, mask):
    """Fit ``models[index]`` on the `states` and `targets` of `mask` (taken here: only the
    data sets being fitted exist at once) and put what its ``fit`` returns in its place."""
    with _regressor_calls():
        models[index] = models[index].fit(states[mask], targets[mask])


def _run_all(queue):
    """Call the callables of `queue` (a deque, which other threads may share) until it is
    empty."""
    while True:
        try:
            task = queue.popleft()
        except IndexError:
            return
        task()


def _predictions(models, batch):
    """Each of `models`' ``predict(batch)``, in a list."""
    with _regressor_calls(len(batch)):
        return [model.predict(batch) for model in models]


def _seeded_clone(regressor, rng):
    """A clone of `regressor` whose ``random_state`` parameters (nested ones too) are one
    seed drawn from `rng`."""
    model = clone(regressor)
    seed = int(rng.integers(2**31 - 1))
    model.set_params(**{key: seed for key in model.get_params()
                        if key == "random_state" or key.endswith("__random_state")})
    return model


class _DoubleQFunction:
    """Double FQI's ``Q_n`` ("Estimating the Maximum Expected Value in Continuous
    Reinforcement Learning Problems", AAAI 2017): two `_QFunction`, each fitted on its own
    half of the data set, that select and evaluate the next action for each other's half.

    A single Q-function's ``max_a Q(s', a)`` is biased upwards: the action that looks best
    is often the one whose fit erred upwards. Here a transition of half ``i`` bootstraps on
    ``Q^j(s', argmax_a Q^i(s', a))``, ``j`` the other half, whose errors at ``s'`` are
    independent of those that chose the action. Actions follow the mean of the two.

    Parameters
    ----------
    halves : list of two _QFunction
    """

    def __init__(self, halves):
        self.halves = halves

    @property
    def models(self):
        """The regressors of the first half, one per action, then those of the second."""
        return [model for half in self.halves for model in half.models]

    @property
    def iteration(self):
        return self.halves[0].iteration

    @classmethod
    def fit(cls, regressor, data, targets, n_actions, rng, previous, iteration, split,
            n_jobs=1):
        """`_QFunction.fit` on each half: the transitions of `split` (a mask of `data`),
        then the others; `previous` is the last `_DoubleQFunction`, or None."""
        return cls([_QFunction.fit(regressor, data[rows], targets[rows], n_actions, rng,
                                   None if previous is None else previous.halves[half],
                                   iteration, n_jobs)
                    for half, rows in enumerate((split, ~split))])

    def values(self, batch, n_jobs=1):
        """The mean of the two halves' ``Q(s, a)`` (see `_QFunction.values`)."""
        first, second = (half.values(batch, n_jobs) for half in self.halves)
        return (first + second) / 2

    def future(self, data, n_jobs=1, split=None, supported=None):
        """Each transition's bootstrap value: the action chosen by the Q-function of its
        half (`split`: the transitions of the first) among those `supported`, valued by
        the other's."""
        first, second = (_masked(half.values(data.next_states, n_jobs), supported)
                         for half in self.halves)
        return _crossed(first, second, split)

    def backups(self, data, targets, discounts, n_backups, split=None, supported=None):
        """`_QFunction.backups`, each half's leaves holding the mean targets of its own
        transitions, and the bootstrap values crossed as in `future`."""
        halves = [(half, rows, half._leaf_tables(data, rows))
                  for half, rows in zip(self.halves, (split, ~split))]
        for _ in range(n_backups):
            first, second = (_masked(_leaf_values(tables, targets, data.actions, rows),
                                     supported) for _, rows, tables in halves)
            targets = data.rewards + discounts * _crossed(first, second, split)
        return targets


def _masked(q, supported):
    """The Q-values `q` with those of the actions not `supported` (a mask of their shape)
    at -inf; `q` itself when `supported` is None."""
    return q if supported is None else np.where(supported, q, -np.inf)


def _crossed(first, second, split):
    """Double Q-learning's values: where `split`, ``second`` at ``first``'s best action;
    elsewhere ``first`` at ``second``'s best action."""
    rows = np.arange(len(first))
    return np.where(split, second[rows, first.argmax(axis=1)],
                    first[rows, second.argmax(axis=1)])


def _leaf_values(tables, targets, actions, rows):
    """``Q(s', a)`` of every next state and action, from the per-action `tables` whose
    leaves hold the mean of `targets` over the transitions of `rows` with that action."""
    q = np.empty((tables[0].n_next, len(tables)))
    for action, table in enumerate(tables):
        q[:, action] = table.next_values(targets[rows & (actions == action)])
    return q


def _checked_prediction(prediction, n, describe):
    """`prediction` for `n` observations, as floats of shape ``(n,)``, after checking there
    are `n` of them and all are finite; ``describe()`` names the model in the error."""
    prediction = np.asarray(prediction, dtype=np.float64)
    bad = ~np.isfinite(prediction)
    if prediction.size == n and not bad.any():
        return prediction.reshape(n)
    model = describe()
    if prediction.size != n:
        raise ValueError(f"{model} predicted an array of size {prediction.size} for "
                         f"{n} observations; a regressor must predict one value per "
                         f"observation")
    raise ValueError(f"{model} predicted non-finite Q-values (NaN or inf) for {bad.sum()} "
                     f"of {n} observations; a regressor must predict finite values")


class _LeafTable:
    """Where the transitions of one action, and every next state, fall in `model`'s trees.

    ``model.apply(X)`` must give each sample's leaf in each tree, shape ``(n, n_trees)``
    (or ``(n,)`` for a single tree), and ``model.predict`` the mean over the trees of the
    leaves' mean training target (`_check_leaf_means` checks a fitted model).
    """

    def __init__(self, model, states, next_states):
        next_leaves = _leaves(model, next_states)
        leaves = (_leaves(model, states) if len(states)  # none: an action not in the data
                  else np.empty((0, next_leaves.shape[1]), dtype=next_leaves.dtype))
        n_nodes = 1 + max(leaves.max(initial=0), next_leaves.max(initial=0))
        self._size = n_nodes * leaves.shape[1]
        index = np.int32 if self._size < 2**31 else np.intp  # half the memory when it can
        offsets = (np.arange(leaves.shape[1]) * n_nodes).astype(index)
        self._leaves = (leaves.astype(index) + offsets).ravel()  # one table for all trees
        self._next = next_leaves.astype(index) + offsets
        counts = np.bincount(self._leaves, minlength=self._size)
        self._reached = counts[self._next] > 0
        self._n_reached = self._reached.sum(axis=1)
        self._counts = np.maximum(counts, 1)
        self._alone = np.flatnonzero(self._n_reached == 0)  # reaches no leaf with data
        self._own = None
        if len(self._alone):
            with _regressor_calls(len(self._alone)):
                self._own = model.predict(next_states[self._alone])

    @property
    def n_next(self):
        """Number of next states."""
        return len(self._next)

    def next_values(self, targets):
        """``Q(s', a)`` for every next state, the leaves holding the mean of `targets` (one
        per transition of this action)."""
        n_trees = self._next.shape[1]
        sums = np.bincount(self._leaves, weights=np.repeat(targets, n_trees),
                           minlength=self._size)
        values = np.where(self._reached, (sums / self._counts)[self._next], 0.0)
        mean = values.sum(axis=1) / np.maximum(self._n_reached, 1)
        if self._own is not None:
            mean[self._alone] = self._own
        return mean


def _leaves(model, X):
    """``model.apply(X)`` as leaf ids of shape (n, n_trees)."""
    with _regressor_calls(len(X)):
        leaves = np.asarray(model.apply(X))
    if leaves.ndim == 1:
        leaves = leaves[:, None]
    if leaves.ndim != 2 or leaves.shape[0] != len(X) or not np.issubdtype(leaves.dtype,
                                                                           np.integer):
        raise ValueError(f"{model!r}.apply gave an array of shape {leaves.shape} and dtype "
                         f"{leaves.dtype} for {len(X)} samples; leaf_backups needs leaf ids "
                         f"of shape (n_samples, n_trees)")
    return leaves


def _check_leaf_means(model, X, y):
    """Check that `model`, fitted on ``(X, y)``, predicts the mean over its trees of its
    leaves' mean target (what `_QFunction.backups` relies on); ValueError if not."""
    table = _LeafTable(model, X, X)
    with _regressor_calls(len(X)):
        prediction = model.predict(X)
    if not np.allclose(table.next_values(y), prediction, rtol=1e-6, atol=1e-9):
        raise ValueError(f"leaf_backups needs a regressor that predicts the mean over its "
                         f"trees of the mean training target in each leaf (a forest without "
                         f"bootstrap, such as scikit-learn's ExtraTreesRegressor or "
                         f"boxtrees.BoxExtraTreesRegressor(bootstrap=False)); {model!r} "
                         f"predicts otherwise")
