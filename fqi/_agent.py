"""`FQI`: fitted Q-iteration with one scikit-learn regressor per action."""
import dataclasses
import os
import pickle
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from numbers import Integral

import joblib
import numpy as np
from joblib import effective_n_jobs
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from tqdm.auto import tqdm

from envs import WorldRules

from ._checks import (_check_bool, _check_int, _check_n_jobs, _check_real, _check_seed,
                      _check_steps)
from ._collect import _Collector, _Transitions
from ._evaluate import evaluate
from ._logger import CSVLogger
from ._observations import _observation_batch
from ._worlds import _world_rules

__all__ = ["FQI"]

_SAVE_FORMAT = 1
_SAVE_KEYS = frozenset({"format", "params", "rules", "q_functions_", "history",
                        "num_timesteps", "iteration", "rngs"})


class FQI:
    """Fitted Q-iteration (Ernst et al. 2005) in the data regimes of Blank (2015), 3.2.2.

    The Q-function is one regressor per action, each a fresh `sklearn.base.clone` of
    `regressor` fitted at every iteration; the agent only calls ``fit(X, y)`` and
    ``predict(X)``, with ``X`` a `boxtrees.ObjectSets` of observations (object sets), so
    any regressor that accepts object sets plugs in (`boxtrees.BoxExtraTreesRegressor`, a
    pipeline starting with `boxtrees.GridCounts`, ...).

    Iteration ``n`` of `learn`:

    1. *collect* (iteration 0, then every `resample_every` iterations):
       `samples_per_iteration` transitions from `n_worlds` training worlds played in
       lockstep, with the uniform random policy at iteration 0 and the epsilon-greedy
       policy of ``Q_{n-1}`` later. They replace the data set, or with `keep_data` are
       appended to it (oldest dropped beyond `max_samples`);
    2. *targets*: ``r`` at iteration 0, then ``r + gamma * max_a Q_{n-1}(s', a)`` for every
       transition in the data set (no bootstrap after a real termination; the 50-step time
       limit is a truncation, not a termination, and is bootstrapped through);
    3. *fit* ``Q_n``: one clone of `regressor` per action on the transitions with that
       action;
    4. *evaluate*: greedy play over `eval_steps` steps on the fixed reference worlds
       (`fqi.evaluate`), logged with the time of each phase.

    Parameters
    ----------
    regressor : scikit-learn regressor
        Template of the per-action Q-functions; must have ``fit`` and ``predict``, be
        clonable and take object sets (else a TypeError or ValueError at its first fit),
        and predict one finite value per observation (else a ValueError naming the action
        and the iteration). A ``random_state`` parameter (also nested,
        ``step__random_state``) is set from `seed` on each clone. For
        `boxtrees.BoxExtraTreesRegressor`, set ``n_jobs=-1`` to use every core and
        ``view_bounds=env view`` to draw tests in the view square (`fqi.make_box_forest`
        does both).
    env : str, gymnasium.Env, envs.BatchedObjectWorld or envs.WorldRules
        The ObjectWorld variant: an id such as ``"ObjectWorld-v0"`` or an env instance
        (wrappers allowed) whose rules (``env.unwrapped.rules``) build the batched rollout
        and evaluation worlds. The action space must be `gymnasium.spaces.Discrete`.
    gamma : float, default=0.5
        Discount factor in ``[0, 1)``. 0.5 scored best and most steadily in a measured
        comparison of 0.5, 0.8, 0.9 and 0.95 (README, section "fqi").
    epsilon : float, default=0.2
        Probability of a uniform random action while collecting (thesis: 0.2).
    samples_per_iteration : int, default=20_000
        Transitions collected per collection (thesis: 20,000).
    resample_every : int or None, default=1
        Collect new data every this many iterations: 1 is the thesis's "normal" regime,
        5 its "mixed" one; None collects only at iteration 0 (offline FQI, Ernst 2005).
    keep_data : bool, default=False
        Append new transitions to the earlier ones instead of replacing them, keeping the
        most recent `max_samples` (a cure for the forgetting the thesis blames for its
        crashes).
    max_samples : int, default=100_000
        Cap on the data set size when `keep_data` is True.
    n_worlds : int, default=400
        Training worlds played in lockstep while collecting.
    eval_steps : int, default=20_000
        Steps of the greedy evaluation after each iteration (a multiple of the episode
        length, 50); 0 skips the evaluation (``reward`` is then NaN).
    n_jobs : int, default=-1
        Threads predicting the per-action Q-functions concurrently (at most one per
        action; -1: one per core). The box forests release the GIL while predicting.
    log_path : str or path-like, default=None
        CSV file receiving one row per iteration (see `history` for the columns); its
        directory must exist and be writable (checked here, see `CSVLogger`).
    seed : int or None, default=None
        Drives the training worlds, the exploration and the regressors' random states: the
        same seed gives the same reward curve.
    verbose : int or bool, default=0
        1 (or True) prints one line per iteration.

    Attributes
    ----------
    q_functions_ : list of regressors
        The fitted ``Q_n``, one per action.
    history : list of dict
        One record per iteration: ``iteration``, ``reward`` (evaluation), ``n_samples``
        (data set size), ``new_samples``, ``num_timesteps``, ``collect_reward_per_step``,
        ``nodes_per_tree`` (mean over actions and trees; NaN without trees) and the seconds
        of each phase: ``t_collect``, ``t_targets``, ``t_fit``, ``t_evaluate``, ``t_total``.
    num_timesteps : int
        Environment steps collected so far (all worlds).
    iteration : int
        Iterations done so far.
    rules : envs.WorldRules
    n_actions : int

    Examples
    --------
    >>> from boxtrees import BoxExtraTreesRegressor
    >>> from fqi import FQI
    >>> forest = BoxExtraTreesRegressor(n_estimators=5, n_tests=50, view_bounds=10)
    >>> agent = FQI(forest, "ObjectWorld-v0", samples_per_iteration=2000, n_worlds=100,
    ...             eval_steps=1000, seed=0).learn(2)
    >>> [r["iteration"] for r in agent.history]
    [0, 1]
    """

    def __init__(self, regressor, env, gamma=0.5, epsilon=0.2, samples_per_iteration=20_000,
                 resample_every=1, keep_data=False, max_samples=100_000, n_worlds=400,
                 eval_steps=20_000, n_jobs=-1, log_path=None, seed=None, verbose=0):
        for method in ("fit", "predict"):
            if not callable(getattr(regressor, method, None)):
                raise TypeError(f"regressor must have fit and predict methods; "
                                f"{type(regressor).__name__} has no {method}")
        clone(regressor)  # a clear TypeError now rather than at the first fit
        self.regressor = regressor
        self.rules = _world_rules(env)
        self.n_actions = self.rules.n_actions
        self.gamma = _check_real("gamma", gamma, 0.0, 1.0, high_inclusive=False)
        self.epsilon = _check_real("epsilon", epsilon, 0.0, 1.0)
        self.samples_per_iteration = _check_int("samples_per_iteration", samples_per_iteration, 1)
        self.resample_every = (None if resample_every is None
                               else _check_int("resample_every", resample_every, 1))
        self.keep_data = _check_bool("keep_data", keep_data)
        self.max_samples = _check_int("max_samples", max_samples, 1)
        if self.keep_data and self.max_samples < self.samples_per_iteration:
            raise ValueError(f"max_samples ({self.max_samples}) must be at least "
                             f"samples_per_iteration ({self.samples_per_iteration})")
        self.n_worlds = _check_int("n_worlds", n_worlds, 1)
        self.eval_steps = _check_steps("eval_steps", eval_steps, self.rules.max_steps,
                                       allow_zero=True)
        self.n_jobs = _check_n_jobs(n_jobs)
        self.seed = _check_seed("seed", seed)
        if not isinstance(verbose, (Integral, np.bool_)):
            raise TypeError(f"verbose must be an int or a bool, got {verbose!r}")
        if verbose < 0:
            raise ValueError(f"verbose must be >= 0, got {verbose}")
        self.verbose = int(verbose)
        self.log_path = log_path
        self.logger = None if log_path is None else CSVLogger(log_path)
        world_seq, action_seq, fit_seq = np.random.SeedSequence(seed).spawn(3)
        self._world_rng = np.random.default_rng(world_seq)
        self._action_rng = np.random.default_rng(action_seq)
        self._fit_rng = np.random.default_rng(fit_seq)
        self._collector = None
        self._pool = None
        self._data = None
        self.q_functions_ = None
        self._q_iteration = None  # the iteration that fitted q_functions_
        self.history = []
        self.num_timesteps = 0
        self.iteration = 0

    # ------------------------------------------------------------------ training
    def learn(self, n_iterations, callback=None, progress_bar=False):
        """Run `n_iterations` FQI iterations (continuing from earlier calls).

        Parameters
        ----------
        n_iterations : int
        callback : callable or object, default=None
            Called after every iteration, either as ``callback(locals_, globals_)`` (the
            stable-baselines3 convention: ``locals_["self"]`` is the agent and
            ``locals_["record"]`` the iteration's record) or, for an object with an
            ``on_iteration`` method, as ``callback.on_iteration(agent, record)``. Returning
            False stops training (any other value, None included, continues).
        progress_bar : bool, default=False
            Show a tqdm bar over the iterations, with the last evaluation reward.

        Returns
        -------
        self : FQI
        """
        n_iterations = _check_int("n_iterations", n_iterations, 1)
        notify = _callback_function(callback)
        progress_bar = _check_bool("progress_bar", progress_bar)
        if self._collector is None:
            self._collector = _Collector(self.rules, self.n_worlds, self._world_rng)
        with tqdm(total=n_iterations, desc="FQI", disable=not progress_bar) as bar:
            for _ in range(n_iterations):
                record = self._iterate()
                bar.set_postfix(reward=f"{record['reward']:,.0f}")
                bar.update()
                if notify is not None and notify(locals(), globals()) is False:
                    break
        return self

    def _iterate(self):
        """One iteration: collect (when due), targets, fit, evaluate; returns its record."""
        start = time.perf_counter()
        new = 0
        collect_reward = np.nan
        if self._data is None or (self.resample_every is not None
                                  and self.iteration % self.resample_every == 0):
            batch = self._collector.collect(
                self.samples_per_iteration, self._behaviour,
                None if self.q_functions_ is None else self._q_values)
            self.num_timesteps += -(-self.samples_per_iteration // self.n_worlds) * self.n_worlds
            new, collect_reward = len(batch), float(batch.rewards.mean())
            if self.keep_data and self._data is not None:
                batch = _Transitions.concatenate([self._data, batch])[-self.max_samples:]
            self._data = batch
        data = self._data
        collected = time.perf_counter()

        targets = data.rewards.copy()
        if self.q_functions_ is not None:
            future = data.next_values  # known when the data was just collected with Q_{n-1}
            if future is None:
                future = self._q_values(data.next_states).max(axis=1)
            targets += self.gamma * np.where(data.terminated, 0.0, future)
        data.next_values = None  # stale once Q_n is fitted
        targeted = time.perf_counter()

        self.q_functions_ = [self._fit_action(a, data, targets) for a in range(self.n_actions)]
        self._q_iteration = self.iteration
        fitted = time.perf_counter()

        reward = evaluate(self, self.rules, self.eval_steps) if self.eval_steps else np.nan
        done = time.perf_counter()

        record = {
            "iteration": self.iteration, "reward": reward, "n_samples": len(data),
            "new_samples": new, "num_timesteps": self.num_timesteps,
            "collect_reward_per_step": collect_reward,
            "nodes_per_tree": _nodes_per_tree(self.q_functions_),
            "t_collect": collected - start, "t_targets": targeted - collected,
            "t_fit": fitted - targeted, "t_evaluate": done - fitted, "t_total": done - start,
        }
        self.history.append(record)
        self.iteration += 1
        if self.logger is not None:
            self.logger.write(record)
        if self.verbose:
            print(f"iteration {record['iteration']:3d}  reward {reward:>12,.0f}  "
                  f"samples {len(data):>7,d}  collect {record['t_collect']:5.2f}s  "
                  f"targets {record['t_targets']:5.2f}s  fit {record['t_fit']:5.2f}s  "
                  f"evaluate {record['t_evaluate']:5.2f}s")
        return record

    def _behaviour(self, obs, q):
        """Collection policy: uniform random before the first fit (``q`` is None), then
        epsilon-greedy on the Q-values ``q`` of the observations."""
        if q is None:
            return self._action_rng.integers(self.n_actions, size=len(obs))
        return self._epsilon_greedy(q)

    def _epsilon_greedy(self, q):
        n = len(q)
        explore = self._action_rng.random(n) < self.epsilon
        return np.where(explore, self._action_rng.integers(self.n_actions, size=n),
                        q.argmax(axis=1))

    def _fit_action(self, action, data, targets):
        """A clone of the regressor fitted on the transitions with `action`.

        A TypeError or ValueError of the agent's first fit is re-raised saying what the
        regressor was given (object sets) and how to wrap a feature-vector regressor. Only
        fitting tells whether a regressor takes object sets, so the constructor cannot.
        """
        mask = data.actions == action
        if not mask.any():
            if self.q_functions_ is None:
                raise ValueError(f"no transition with action {action} in the data; collect "
                                 f"more samples per iteration")
            warnings.warn(f"no transition with action {action} in the data; keeping its "
                          f"previous Q-function", RuntimeWarning, stacklevel=3)
            return self.q_functions_[action]
        model = clone(self.regressor)
        seed = int(self._fit_rng.integers(2**31 - 1))
        params = model.get_params()
        model.set_params(**{k: seed for k in params
                            if k == "random_state" or k.endswith("__random_state")})
        try:
            return model.fit(data.states[mask], targets[mask])
        except (TypeError, ValueError) as exc:
            if self.q_functions_ is not None or action > 0:
                raise  # the regressor has taken object sets before
            error = ValueError if isinstance(exc, ValueError) else TypeError
            raise error(
                f"{self.regressor!r} failed on its first fit, given object sets as a "
                f"boxtrees.ObjectSets ({type(exc).__name__}: {exc}). FQI gives every "
                f"regressor its observations as object sets (variable-size sets of "
                f"[dx, dy, type] rows), not as a feature matrix: use a regressor that takes "
                f"object sets, such as boxtrees.BoxExtraTreesRegressor (fqi.make_box_forest), "
                f"or wrap a feature-vector regressor in a pipeline starting with "
                f"boxtrees.GridCounts (fqi.make_grid_ridge)") from exc

    # ------------------------------------------------------------------ acting
    def q_values(self, observation):
        """Q-values of every action.

        Parameters
        ----------
        observation
            As for `predict`.

        Returns
        -------
        q : ndarray of shape (n_actions,) for one observation, (n, n_actions) for a batch
        """
        sets, single = _observation_batch(observation)
        q = self._q_values(sets)
        return q[0] if single else q

    def _q_values(self, sets):
        if self.q_functions_ is None:
            raise NotFittedError("this FQI agent has no Q-function yet; call learn() first")
        if self._pool is None:
            self._pool = ThreadPoolExecutor(min(effective_n_jobs(self.n_jobs), self.n_actions))
        predictions = self._pool.map(lambda model: model.predict(sets), self.q_functions_)
        q = np.empty((len(sets), self.n_actions))
        for action, prediction in enumerate(predictions):
            q[:, action] = self._checked_prediction(action, prediction, len(sets))
        return q

    def _checked_prediction(self, action, prediction, n):
        """`prediction` of the Q-function of `action` for `n` observations, as floats of
        shape ``(n,)``, after checking there are `n` of them and all are finite."""
        prediction = np.asarray(prediction, dtype=np.float64)
        bad = ~np.isfinite(prediction)
        if prediction.size == n and not bad.any():
            return prediction.reshape(n)
        model = (f"iteration {self._q_iteration}'s Q-function of action {action} "
                 f"({self.q_functions_[action]!r})")
        if prediction.size != n:
            raise ValueError(f"{model} predicted an array of size {prediction.size} for "
                             f"{n} observations; a regressor must predict one value per "
                             f"observation")
        raise ValueError(f"{model} predicted non-finite Q-values (NaN or inf) for {bad.sum()} "
                         f"of {n} observations; a regressor must predict finite values")

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        """Actions for one observation or a batch (the stable-baselines3 signature).

        Parameters
        ----------
        observation : array-like or batch
            One world's objects, an ``(n, 3)`` array of rows ``[dx, dy, type]``; a batch:
            an `envs.RaggedBatch` / `boxtrees.ObjectSets` (anything with ``data`` and
            ``offsets``), a list of ``(n_i, 3)`` arrays or an ``(batch, n, 3)`` array; or
            observations padded by `envs.PaddedObjects`: ``(max_objects, 4)`` or
            ``(batch, max_objects, 4)``.
        state, episode_start
            Unused (the policy is reactive); accepted for stable-baselines3.
        deterministic : bool, default=True
            Greedy actions; False draws epsilon-greedy ones.

        Returns
        -------
        actions : int, or ndarray of int of shape (batch,)
        state : None
        """
        sets, single = _observation_batch(observation)
        q = self._q_values(sets)
        actions = q.argmax(axis=1) if deterministic else self._epsilon_greedy(q)
        return (actions[0] if single else actions), None

    # ------------------------------------------------------------------ persistence
    def save(self, path):
        """Save the parameters, the fitted Q-functions, the history and the random
        streams with joblib (the transitions are not saved).

        Parameters
        ----------
        path : str or path-like
        """
        params = {name: getattr(self, name) for name in (
            "regressor", "gamma", "epsilon", "samples_per_iteration", "resample_every",
            "keep_data", "max_samples", "n_worlds", "eval_steps", "n_jobs", "seed", "verbose")}
        joblib.dump({
            "format": _SAVE_FORMAT, "params": params, "rules": dataclasses.asdict(self.rules),
            "q_functions_": self.q_functions_, "history": self.history,
            "num_timesteps": self.num_timesteps, "iteration": self.iteration,
            "rngs": (self._world_rng, self._action_rng, self._fit_rng),
        }, path)

    @classmethod
    def load(cls, path, env=None, log_path=None):
        """Load an agent saved by `save`.

        Loading unpickles the file, which can run arbitrary code: load only trusted files.

        Parameters
        ----------
        path : str or path-like
            A file written by `save`; ValueError for any other file (empty, truncated,
            damaged, not an FQI save, or a save of another format version), and
            FileNotFoundError for a missing one.
        env : str, gymnasium.Env or envs.WorldRules, default=None
            Play and train on this env instead of the saved rules (same number of actions).
        log_path : str or path-like, default=None
            CSV log for further `learn` calls.

        Returns
        -------
        agent : FQI
            Further `learn` calls continue the iteration count with freshly collected data.
        """
        state = _read_save(path)
        rules = WorldRules(**state["rules"])
        agent = cls(env=rules if env is None else env, log_path=log_path, **state["params"])
        if agent.n_actions != rules.n_actions:
            raise ValueError(f"env has {agent.n_actions} actions, the saved agent "
                             f"{rules.n_actions}")
        agent.q_functions_ = state["q_functions_"]
        agent.history = state["history"]
        agent.num_timesteps = state["num_timesteps"]
        agent.iteration = state["iteration"]
        agent._q_iteration = agent.iteration - 1
        agent._world_rng, agent._action_rng, agent._fit_rng = state["rngs"]
        return agent

    def __getstate__(self):
        state = self.__dict__.copy()
        state["_pool"] = None  # threads do not pickle; a new pool starts on demand
        return state

    def __repr__(self):
        return (f"FQI(regressor={self.regressor!r}, gamma={self.gamma}, "
                f"epsilon={self.epsilon}, samples_per_iteration={self.samples_per_iteration}, "
                f"resample_every={self.resample_every}, keep_data={self.keep_data}, "
                f"iteration={self.iteration})")


def _read_save(path):
    """The state that `FQI.save` wrote to `path`, or a ValueError saying why the file is
    not one (FileNotFoundError when it does not exist)."""
    path = os.fspath(path)
    with open(path, "rb") as f:
        head = f.read(1)
    if not head:
        raise ValueError(f"{path} is empty, not an agent saved by FQI.save")
    if head != pickle.PROTO:  # FQI.save writes an uncompressed joblib pickle
        raise ValueError(f"{path} is not an agent saved by FQI.save (not a joblib pickle)")
    try:
        state = joblib.load(path)
    except Exception as exc:  # unpickling damaged data can raise almost anything
        raise ValueError(f"{path} could not be read as an agent saved by FQI.save: it is "
                         f"truncated or damaged ({type(exc).__name__}: {exc})") from exc
    if not isinstance(state, dict) or "format" not in state:
        raise ValueError(f"{path} is a joblib pickle of a {type(state).__name__}, not an "
                         f"agent saved by FQI.save")
    if state["format"] != _SAVE_FORMAT:
        raise ValueError(f"{path} is an FQI save of format version {state['format']!r}; "
                         f"this version of fqi reads version {_SAVE_FORMAT}")
    missing = sorted(_SAVE_KEYS - state.keys())
    if missing:
        raise ValueError(f"{path} is not an agent saved by FQI.save: it lacks "
                         f"{', '.join(missing)}")
    return state


def _callback_function(callback):
    """`callback` as a function ``f(locals_, globals_) -> bool or None``."""
    if callback is None:
        return None
    if callable(getattr(callback, "on_iteration", None)):
        return lambda locals_, globals_: callback.on_iteration(locals_["self"], locals_["record"])
    if callable(callback):
        return callback
    raise TypeError(f"callback must be callable(locals_, globals_) or have an on_iteration "
                    f"method; got {type(callback).__name__}")


def _nodes_per_tree(models):
    """Mean node count per tree over the models' forests (looking inside pipelines); NaN if
    they have no trees."""
    counts = []
    for model in models:
        forest = model[-1] if hasattr(model, "steps") else model
        for tree in getattr(forest, "estimators_", []):
            counts.append(getattr(tree, "tree_", tree).node_count)
    return float(np.mean(counts)) if counts else np.nan
