"""`FQI`: fitted Q-iteration with one scikit-learn regressor per action, on any gymnasium env."""
from __future__ import annotations

import inspect
import os
import time
from collections.abc import Callable, Sequence
from contextlib import contextmanager
from typing import Any, Self

import numpy as np
from gymnasium import spaces
from gymnasium.vector import VectorEnv
from sklearn.base import clone, is_classifier
from sklearn.exceptions import NotFittedError
from tqdm.auto import tqdm

from ._behaviour import _default_classifier, _Support
from ._callbacks import _as_callback
from ._calls import _regressor_calls
from ._checks import (_check_bool, _check_choice, _check_int, _check_n_jobs, _check_real,
                      _check_seed, _check_verbose)
from ._collect import _Collector, _Transitions
from ._datasets import _dataset_transitions
from ._envs import (_check_env, _close_built, _evaluation_vector, _make_vector, _n_actions,
                    _tried)
from ._evaluate import _DEFAULT_EPISODES as _EVAL_EPISODES
from ._evaluate import _eval_seeds, evaluate
from ._logger import CSVLogger, _KeyValueLogger
from ._observations import _ObjectRows, _observation_format
from ._q_function import (_ActionInputQFunction, _check_leaf_means, _checked_prediction,
                          _DoubleQFunction, _encoded, _masked, _QFunction)
from ._saving import _read_save, _write_save
from ._typing import Callback, Dataset, EnvLike, Logger, Observation, Regressor

__all__ = ["FQI"]

_DEFAULT_ENVS = 16
_TIE_BREAKS = ("random", "first")
_TIE_TOLERANCE = 1e-6  # relative: Q-values closer than this to the best tie with it
_MAX_HOLD = 10_000  # steps: the cap on the duration of a held exploratory action
# What `save` leaves out (SB3 saves its __dict__ minus such a list): the envs, which hold
# simulators, the transitions, the threads and the logs.
_UNSAVED = frozenset({"_env", "_eval_env", "_collector", "_held", "_data", "_next_supported",
                      "_csv_log", "_logger"})
# What a save holds beyond the constructor parameters.
_LEARNED = ("_q", "history", "num_timesteps", "iteration", "observation_space",
            "action_space")


class FQI:
    """Fitted Q-iteration on any gymnasium env with discrete actions: a growing batch of
    transitions, several fitted-Q backups per collection round, and the data regimes of the
    thesis (section 3.2.2).

    The Q-function is one regressor per action (or one over observations and actions:
    `action_input`), each a fresh `sklearn.base.clone` of `regressor` fitted at every
    iteration; the agent only calls ``fit(X, y)`` and ``predict(X)``. ``X`` follows the
    env's observation space: for a ``Box``, a 2D float matrix with one flattened
    observation per row, so any scikit-learn regressor plugs in;
    for ``Sequence(Box(shape=(d + 1,)))`` (sets of ``[f_1, ..., f_d, type]`` objects), one
    `boxtrees.ObjectSets` (``data`` + ``offsets``) per batch, which
    `boxtrees.BoxExtraTreesRegressor` or a pipeline starting with `boxtrees.GridCounts` take.

    `learn` runs collection rounds, each followed by `resample_every` iterations (fitted-Q
    backups on the data kept so far: the backups, not the collections, carry value over a
    horizon of about ``1 / (1 - gamma)`` steps). Iteration ``n``:

    1. *collect* (iteration 0, then every `resample_every` iterations):
       `samples_per_iteration` transitions from the `n_envs` envs of a gymnasium vector env,
       with the uniform random policy at iteration 0 and the epsilon-greedy policy of
       ``Q_{n-1}`` later, epsilon falling as in stable-baselines3's DQN (with
       `exploration_zeta`, each random action is held for a random number of steps). With
       `keep_data` they are appended to the data set (oldest dropped beyond `max_samples`),
       else they replace it;
    2. *targets*: ``r`` at iteration 0, then ``r + gamma * max_a Q_{n-1}(s', a)`` for every
       transition in the data set (no bootstrap after a termination; a truncation, such as
       a time limit, is bootstrapped through with the true final observation), then
       `leaf_backups` more backups on ``Q_{n-1}``'s trees with only their leaf values
       recomputed;
    3. *fit* ``Q_n``: one clone of `regressor` per action on the transitions with that
       action;
    4. *evaluate*: greedy play, one episode per seed of `eval_seeds` (`fqi.evaluate`),
       logged with the time of each phase.

    Parameters
    ----------
    regressor : scikit-learn regressor
        Template of the per-action Q-functions; must have ``fit`` and ``predict``, be
        clonable, and predict one finite value per observation (checked here by fitting a
        clone on the env's first observations, and after every fit). A ``random_state``
        parameter (also nested, ``step__random_state``) is set from `seed` on each clone.
        For `boxtrees.BoxExtraTreesRegressor`, `fqi.make_box_forest` reads the view square
        from the observation space and uses every core.
    env : str, gymnasium.Env, gymnasium.vector.VectorEnv or callable
        The environment; its action space must be ``Discrete`` (numbered from 0) and its
        observation space a ``Box`` or ``Sequence(Box(shape=(d + 1,)))``. A registered id is made
        with ``gymnasium.make_vec(id, num_envs=n_envs)``, which uses the id's
        ``vector_entry_point`` (a batched engine) when it has one and a ``SyncVectorEnv``
        otherwise; an env made by ``gymnasium.make`` is rebuilt the same way from its spec;
        any other env is copied `n_envs` times (``copy.deepcopy``); a callable is called
        once per env; a vector env is used as it is. The env is tried once here (a reset
        and a step): an env that raises gives a RuntimeError naming the call.
    gamma : float, default=0.99
        Discount factor in ``[0, 1)``, stable-baselines3's default. The thesis's game scored
        best with 0.5 (``docs/fqi.md``, "Discount factor").
    samples_per_iteration : int, default=2_500
        Transitions collected per collection round (the thesis: 20,000).
    resample_every : int or None, default=5
        Iterations (fitted-Q backups) per collection round: 1 is the thesis's "normal"
        regime, 5 its "mixed" one; None collects only at iteration 0 (offline FQI, as first
        formulated; see also `learn_offline`).
    keep_data : bool, default=True
        Append new transitions to the earlier ones (a growing batch, as a replay buffer),
        keeping the most recent `max_samples`; False replaces them (the thesis's regimes).
    max_samples : int, default=100_000
        Cap on the data set size when `keep_data` is True (stable-baselines3's
        ``buffer_size``).
    exploration_fraction : float, default=0.1
        Share of `learn`'s ``total_timesteps`` over which the probability of a random action
        falls from `exploration_initial_eps` to `exploration_final_eps` (stable-baselines3's
        DQN schedule; with ``n_iterations``, the share of the iterations).
    exploration_initial_eps, exploration_final_eps : float, default=1.0, 0.05
        Probability of a uniform random action while collecting, at the start and at the end
        of the schedule (the thesis: 0.2 throughout). The first round plays uniformly at
        random whatever they are: there is no Q-function yet.
    exploration_zeta : float or None, default=None
        None: each random action lasts one step (epsilon-greedy). A number ``mu > 1``:
        temporally-extended epsilon-greedy ("ez-greedy", "Temporally-Extended
        epsilon-Greedy Exploration", ICLR 2021): an env that is not holding an action
        starts, with the probability of a random action, to hold a uniformly drawn action
        for ``n`` steps, ``n`` drawn from the zeta
        distribution of exponent ``mu`` (``P(n) ~ n**-mu``: mostly short, sometimes long;
        capped at 10,000 steps; a hold may run on into the env's next episode), and acts
        greedily otherwise; the first round holds random actions the same way. Random play
        that repeats its actions travels far (its displacement grows with the hold
        durations), where one-step random play dithers in place: the remedy for a sparse
        reward far from the start (Atari's Freeway: ``docs/games.md``; MountainCar-v0, with
        1.5 and epsilon kept up over half the steps: ``docs/fqi.md``). 2 is the paper's
        choice. `predict` with ``deterministic=False`` stays one-step epsilon-greedy.
    tie_break : {"random", "first"}, default="random"
        How the collection's greedy action is chosen among tied ones (Q-values within a
        relative ``1e-6`` of the best): "random" draws one uniformly, "first" takes the
        lowest action (the thesis's, numpy's ``argmax``). A forest's Q-function is
        piecewise constant, so actions it cannot yet tell apart tie, or differ only by
        rounding; "first" then always collects the same action there, which on a task with
        one reward everywhere until the goal (Acrobot-v1: -1 per step) never reaches the
        goal (``docs/fqi.md``). `predict` stays deterministic: the lowest tied action.
    leaf_backups : int, default=0
        Fitted-Q backups before each fit that keep ``Q_{n-1}``'s trees and recompute only
        their leaves' values, as means of the current targets (the frozen-structure
        Extra-Trees of "Tree-Based Batch Mode Reinforcement Learning", 2005): value travels
        ``leaf_backups + 1`` steps per fit instead of one, each extra backup for about the
        cost of a prediction. Needs a forest with ``apply`` that predicts the mean of its
        trees' leaf means, checked here: scikit-learn's ``ExtraTreesRegressor``, or
        `boxtrees.BoxExtraTreesRegressor` with ``bootstrap=False`` (a bootstrap sample
        weighs the leaf means). Memory: one leaf id per transition and tree, and per next
        state, tree and action.
    double : bool, default=False
        Double FQI ("Estimating the Maximum Expected Value in Continuous Reinforcement
        Learning Problems", AAAI 2017): each iteration splits
        the data set at random into two halves and fits a Q-function on each (twice the
        regressors, each on half the data); a transition of one half bootstraps on the
        other half's value of the action its own half's Q-function rates best, which
        removes the upward bias of ``max_a Q(s', a)`` over fitting errors. Actions follow
        the mean of the two. With `leaf_backups` each half's leaves hold the means of its
        own half's targets.
    action_input : bool or callable, default=False
        Fit one regressor on every transition, its input the observation encoded with its
        action, instead of one regressor per action on that action's transitions (as
        MushroomRL's FQI with a state-action regressor). True: the observation followed by
        the action's one-hot columns (``X`` has ``n_features + n_actions`` columns;
        feature-vector, ``Box``, observations only). A callable ``encode(observations,
        actions)``: the regressor's input is what it returns for a batch of observations
        (as the regressor takes them: an array, or a `boxtrees.ObjectSets`) and their
        actions, one row or set per observation; an env symmetric under a group of
        transformations that permutes its actions can turn each observation so that its
        action points one way, and the actions then share one model and all the data
        (``envs.in_move_frame`` does so for the thesis's game). The actions share the regressor's
        splits, so their Q-values err together where separate regressors err apart (the
        likely reason it plays better on Acrobot-v1, not measured apart: ``docs/fqi.md``).
        Not with `double`. A callable must pickle (a module-level function) for `save`.
    support_threshold : float or None, default=0.3
        The offline constraint: backups and greedy actions limited to the actions the data
        support ("never below the data"). `learn_offline` fits a behaviour model, a
        classifier of the data set's actions given its states (`support_classifier`),
        which gives each action's share at a state; an action is supported there when its
        share is at least `support_threshold` times the largest (BCQ's relative threshold,
        "Benchmarking Batch Deep Reinforcement Learning Algorithms", 2019). The backups'
        ``max_a Q(s', a)`` and the greedy action (`predict`, and the greedy action of a
        later `learn`'s collection) then range over the supported actions only: fitted
        Q-iteration no longer bootstraps on values its regressor extrapolates to actions
        the data never take at a state. 0 or None: every action (FQI as it was; None fits
        no behaviour model, and ``FQI.load(path, support_threshold=None)`` lifts a saved
        agent's constraint). In ``[0, 1]``; 1 keeps the data's most frequent action alone.
        A `learn` after `learn_offline` refits the behaviour model on the grown data set
        after each collection round; an agent that never learned offline is unconstrained.
    support_classifier : scikit-learn classifier, default=None
        Template of the behaviour model (with ``fit`` and ``predict_proba``, fitted on the
        states and the actions, with its ``random_state`` parameters set from `seed`).
        None: 30 Extra-Trees, scikit-learn's ``ExtraTreesClassifier(min_samples_leaf=5)``
        for ``Box`` observations, ``boxtrees.BoxExtraTreesClassifier(min_samples_split=100)``
        drawing its tests in the view for object sets (smoothed so: a data set's next
        state is most often one of its states, and a classifier that isolates it gives
        its own action alone).
    n_envs : int, default=None
        Envs played side by side while collecting; None: the vector env's own number, or
        16 for any other env form.
    eval_episodes : int, default=None
        Greedy evaluation episodes after each iteration (`fqi.evaluate`, played side by side
        in a vector env of one env per episode): ``len(eval_seeds)`` when those are given,
        else 10 when `eval_env` is given, else none: as stable-baselines3's ``learn``,
        FQI evaluates nothing unless asked (there, with an ``EvalCallback``), and
        ``history``'s ``train_return`` follows the training episodes meanwhile. Each
        evaluation plays whole episodes with a prediction per step: on CartPole-v1, 10
        episodes after every iteration took 80% of `learn`'s time with a 30-tree forest.
        0 evaluates nothing (``reward`` is then NaN), whatever `eval_seeds`.
    eval_seeds : sequence of int, default=None
        Reset seed of each evaluation episode, fixed for the whole run. Default
        ``2**40, 2**40 + 1, ...``: training draws its reset seeds below ``2**40``, so those
        episodes are never trained on.
    eval_env : str, gymnasium.Env, gymnasium.vector.VectorEnv or callable, default=None
        Env to evaluate on (same observation and action spaces); default: built from `env`
        like the training env, one env per episode (a vector env `env` is rebuilt from its
        spec; one without a spec needs `eval_env` or ``eval_episodes=0``).
    n_jobs : int, default=1
        Threads fitting, and predicting, the per-action Q-functions concurrently (at most
        one per action; -1: one per core); 1 fits and predicts them one after the other.
        Threads help a regressor whose fit and prediction release the GIL; one with
        threads of its own (a forest's ``n_jobs``) keeps them, and its serial parts and
        last trees then overlap another action's fit (the thesis's 4 forests fit about 1.5%
        faster on 2 cores with ``n_jobs=-1``; the same forests). A box forest
        (`fqi.make_box_forest`) predicting in one of them uses its share of the cores, not
        every core: on 2 cores, the thesis's 4 forests of 30 trees predict 400 game states
        at a time about 15% faster with ``n_jobs=-1`` than with 1 (their own threads
        alone), and 1 state 3 to 4 times slower (handing work to a thread costs more than
        the work).
    log_path : str or path-like, default=None
        CSV file receiving one row per iteration (see `history` for the columns); its
        directory must exist and be writable (checked here, see `CSVLogger`).
    seed : int or None, default=None
        Drives the training resets, the exploration and the regressors' random states: on
        an env that is deterministic given its reset seeds, the same seed gives the same
        reward curve.
    verbose : int or bool, default=0
        1 (or True) prints one line per iteration.

    Attributes
    ----------
    exploration_rate : float
        The current probability of a random action (of the next collection).
    q_functions_ : list of regressors
        The fitted ``Q_n``: one per action (two per action with `double`, one in all with
        `action_input`).
    history : list of dict
        One record per iteration: ``iteration``, ``reward`` (total return of the evaluation
        episodes), ``mean_return`` (per episode), ``train_return`` (mean return of the last
        100 training episodes that ended, played with the exploration: stable-baselines3's
        ``rollout/ep_rew_mean``; NaN before one ends), ``n_samples`` (data set size),
        ``new_samples``, ``num_timesteps``, ``collect_reward_per_step``, ``nodes_per_tree``
        (mean over actions and trees; NaN without trees) and the seconds of each phase:
        ``t_collect``, ``t_targets``, ``t_fit``, ``t_evaluate``, ``t_total``.
    num_timesteps : int
        Environment steps collected so far (transitions, over all envs; the reset steps of
        gymnasium's next-step autoreset are not transitions and not counted).
    iteration : int
        Iterations done so far.
    observation_space : gymnasium.spaces.Space
        Of one env.
    action_space : gymnasium.spaces.Discrete
        Of one env.
    n_actions : int
        Number of actions (``action_space.n``): one Q-function each.
    support_model_ : classifier or None
        The behaviour model that `learn_offline` fitted (`support_threshold`), None
        without one.
    logger : object
        The key-value logger of stable-baselines3 callbacks; see `FQI.logger`.

    Examples
    --------
    >>> from sklearn.ensemble import ExtraTreesRegressor
    >>> from fqi import FQI
    >>> agent = FQI(ExtraTreesRegressor(n_estimators=10, random_state=0), "CartPole-v1",
    ...             samples_per_iteration=500, resample_every=2, n_envs=1, eval_episodes=2,
    ...             seed=0)
    >>> agent = agent.learn(total_timesteps=1000)
    >>> agent.num_timesteps, [r["iteration"] for r in agent.history]
    (1000, [0, 1, 2, 3])
    >>> agent.predict(agent.observation_space.sample())[0] in (0, 1)
    True
    """

    exploration_rate: float
    history: list[dict[str, Any]]
    num_timesteps: int
    iteration: int
    observation_space: spaces.Space
    action_space: spaces.Discrete
    n_actions: int
    _collector: _Collector | None
    _held: np.ndarray | None
    _logger: Logger | None

    def __init__(self, regressor: Regressor, env: EnvLike, gamma: float = 0.99,
                 samples_per_iteration: int = 2_500, resample_every: int | None = 5,
                 keep_data: bool = True, max_samples: int = 100_000,
                 exploration_fraction: float = 0.1, exploration_initial_eps: float = 1.0,
                 exploration_final_eps: float = 0.05,
                 exploration_zeta: float | None = None, tie_break: str = "random",
                 leaf_backups: int = 0, double: bool = False,
                 action_input: bool | Callable[[Any, np.ndarray], Any] = False,
                 support_threshold: float | None = 0.3,
                 support_classifier: Any = None,
                 n_envs: int | None = None,
                 eval_episodes: int | None = None, eval_seeds: Sequence[int] | None = None,
                 eval_env: EnvLike | None = None, n_jobs: int = 1,
                 log_path: str | os.PathLike[str] | None = None, seed: int | None = None,
                 verbose: int | bool = 0) -> None:
        self._set_params({name: value for name, value in locals().items() if name != "self"})
        # (the behaviour model's stream apart: with the constraint on, the Q-functions draw
        # the seeds they draw without it)
        world_seq, action_seq, fit_seq, support_seq = np.random.SeedSequence(
            self.seed).spawn(4)
        self._world_rng = np.random.default_rng(world_seq)
        self._action_rng = np.random.default_rng(action_seq)
        self._fit_rng = np.random.default_rng(fit_seq)
        self._support_rng = np.random.default_rng(support_seq)
        # None until set_env (below) sets them: afterwards always the env's spaces
        self.observation_space = self.action_space = None  # type: ignore[assignment]
        self.exploration_rate = self.exploration_initial_eps
        # the last iteration's _QFunction (_DoubleQFunction if double, _ActionInputQFunction
        # if action_input)
        self._q = None
        # the behaviour model of the offline data (a _Support; support_threshold), and the
        # actions it supports at the data set's next states
        self._support = self._next_supported = None
        self.history = []
        self.num_timesteps = 0
        self.iteration = 0
        self._logger = None
        self.set_env(env)

    @classmethod
    def _param_names(cls):
        return [name for name in inspect.signature(cls.__init__).parameters if name != "self"]

    def _set_params(self, params):
        """Check the constructor parameters (all but the envs, see `set_env`) and set them
        as attributes of the same names."""
        regressor = params["regressor"]
        for method in ("fit", "predict"):
            if not callable(getattr(regressor, method, None)):
                raise TypeError(f"regressor must have fit and predict methods; "
                                f"{type(regressor).__name__} has no {method}")
        clone(regressor)  # a clear TypeError now rather than at the first fit
        if is_classifier(regressor):
            raise TypeError(f"regressor must be a regressor: FQI fits it on real-valued "
                            f"targets (Q-values), and {type(regressor).__name__} is a "
                            f"classifier; use its regressor counterpart (ExtraTreesRegressor "
                            f"for ExtraTreesClassifier, say)")
        self.regressor = regressor
        self.env, self.eval_env = params["env"], params["eval_env"]
        if self.eval_env is not None:
            _check_env(self.eval_env, "eval_env")
        self.gamma = _check_real("gamma", params["gamma"], 0.0, 1.0, high_inclusive=False)
        self.exploration_fraction = _check_real("exploration_fraction",
                                                params["exploration_fraction"], 0.0, 1.0)
        self.exploration_initial_eps = _check_real("exploration_initial_eps",
                                                   params["exploration_initial_eps"], 0.0, 1.0)
        self.exploration_final_eps = _check_real("exploration_final_eps",
                                                 params["exploration_final_eps"], 0.0, 1.0)
        zeta = params["exploration_zeta"]
        if zeta is not None:
            zeta = _check_real("exploration_zeta", zeta, 1.0, np.inf)
            if zeta == 1.0:
                raise ValueError("exploration_zeta must be greater than 1 (the zeta "
                                 "distribution's exponent), or None, got 1.0")
        self.exploration_zeta = zeta
        self.tie_break = _check_choice("tie_break", params["tie_break"], _TIE_BREAKS)
        self.leaf_backups = _check_int("leaf_backups", params["leaf_backups"], 0)
        if self.leaf_backups and not callable(getattr(regressor, "apply", None)):
            raise TypeError(f"leaf_backups needs a regressor with an apply method (the leaf of "
                            f"each sample in each tree, as scikit-learn's forests have); "
                            f"{type(regressor).__name__} has none")
        self.double = _check_bool("double", params["double"])
        action_input = params["action_input"]
        if not callable(action_input) and not isinstance(action_input, (bool, np.bool_)):
            raise TypeError(f"action_input must be a bool or a callable encode(observations, "
                            f"actions), got {action_input!r}")
        self.action_input = action_input if callable(action_input) else bool(action_input)
        if self.double and self.action_input:
            raise ValueError("double and action_input cannot be combined: Double FQI fits "
                             "a regressor per action on each half of the data")
        threshold = params["support_threshold"]
        self.support_threshold = (None if threshold is None
                                  else _check_real("support_threshold", threshold, 0.0, 1.0))
        classifier = params["support_classifier"]
        if classifier is not None:
            for method in ("fit", "predict_proba"):
                if not callable(getattr(classifier, method, None)):
                    raise TypeError(f"support_classifier must be a classifier with fit and "
                                    f"predict_proba methods; {type(classifier).__name__} has "
                                    f"no {method}")
            clone(classifier)
        self.support_classifier = classifier
        self.samples_per_iteration = _check_int("samples_per_iteration",
                                                params["samples_per_iteration"], 1)
        resample_every = params["resample_every"]
        self.resample_every = (None if resample_every is None
                               else _check_int("resample_every", resample_every, 1))
        self.keep_data = _check_bool("keep_data", params["keep_data"])
        self.max_samples = _check_int("max_samples", params["max_samples"], 1)
        if self.keep_data and self.max_samples < self.samples_per_iteration:
            raise ValueError(f"max_samples ({self.max_samples}) must be at least "
                             f"samples_per_iteration ({self.samples_per_iteration})")
        n_envs = params["n_envs"]
        self.n_envs = None if n_envs is None else _check_int("n_envs", n_envs, 1)
        self.eval_episodes, self.eval_seeds = params["eval_episodes"], params["eval_seeds"]
        self._eval_seeds = _eval_seeds(self.eval_episodes, self.eval_seeds, "eval_episodes",
                                       "eval_seeds",
                                       default=0 if self.eval_env is None else _EVAL_EPISODES)
        self.n_jobs = _check_n_jobs(params["n_jobs"])
        self.seed = _check_seed("seed", params["seed"])
        self.verbose = _check_verbose(params["verbose"])
        self.log_path = params["log_path"]
        self._csv_log = None if self.log_path is None else CSVLogger(self.log_path)

    # ------------------------------------------------------------------ envs
    def set_env(self, env: EnvLike, eval_env: EnvLike | None = None) -> None:
        """Play on `env` from now on (its spaces must be the agent's, once it has some).

        Builds the training vector env and the evaluation one (from `eval_env`, else from
        the constructor's `eval_env`, else from `env`), then tries the env (a reset and a
        step) and the regressor (fitted on those observations). Collection starts new
        episodes, on an empty data set (the transitions of the previous env are dropped).
        The previous envs are left as they are (as stable-baselines3 does); a call that fails
        closes the vector envs it built.

        Parameters
        ----------
        env, eval_env
            As in the constructor.
        """
        _check_env(env)
        if eval_env is None:
            eval_env = self.eval_env
        else:
            _check_env(eval_env, "eval_env")
        vector = _make_vector(env, self.n_envs or _DEFAULT_ENVS)
        eval_vector = None
        try:
            if isinstance(env, VectorEnv) and self.n_envs not in (None, vector.num_envs):
                raise ValueError(f"n_envs={self.n_envs} but the vector env has "
                                 f"{vector.num_envs} envs; leave n_envs out (None) for a "
                                 f"vector env")
            observation_space = vector.single_observation_space
            action_space = vector.single_action_space
            n_actions = _n_actions(action_space)
            observations = _observation_format(observation_space)
            self._check_action_input(observations, observation_space)
            if self.observation_space is not None and (observation_space, action_space) != (
                    self.observation_space, self.action_space):
                raise ValueError(f"env has the spaces {observation_space} and {action_space}; "
                                 f"the agent was made for {self.observation_space} and "
                                 f"{self.action_space}")
            eval_vector = _evaluation_vector(env, eval_env, vector,
                                             (observation_space, action_space),
                                             len(self._eval_seeds))
            first = _tried(vector, observations)
            self._check_regressor(observations, first, n_actions)
        except BaseException:
            _close_built(vector, env)
            _close_built(eval_vector, eval_env)
            raise
        self.env, self.eval_env = env, eval_env
        self._env, self._eval_env = vector, eval_vector
        self.observation_space, self.action_space = observation_space, action_space
        self.n_actions, self._observations = n_actions, observations
        self._collector = self._held = None
        self._data = self._next_supported = None

    def _check_action_input(self, observations, observation_space):
        """ValueError if `action_input` is asked of observations that are not feature
        vectors (`observations`: the format of `observation_space`)."""
        if self.action_input is True and isinstance(observations, _ObjectRows):
            raise ValueError(f"action_input=True needs feature-vector (Box) observations, not "
                             f"{observation_space}: the action is appended to each "
                             f"observation's features; pass a callable encode(observations, "
                             f"actions) for other observations")

    def _encoding(self):
        """`action_input`'s encoding for `_ActionInputQFunction`: the callable, or None for
        the one-hot columns."""
        return self.action_input if callable(self.action_input) else None

    def _check_regressor(self, observations, batch, n_actions):
        """Fit a clone of the regressor on `batch` (zero targets; distinct ones with
        `leaf_backups`, whose leaf means are checked too; with `action_input`, each
        observation with an action of the `n_actions` appended) and check its predictions,
        so that a regressor that cannot take these observations fails now."""
        if self.action_input:
            encoded = _encoded(self._encoding(), batch, np.arange(len(batch)) % n_actions,
                               n_actions)
            length = len(encoded) if hasattr(encoded, "__len__") else None
            if length != len(batch):
                raise ValueError(f"action_input={self.action_input!r} must return one input "
                                 f"per observation; for {len(batch)} observations it "
                                 f"returned a {type(encoded).__name__} of length {length}")
            batch = encoded
        model = clone(self.regressor)
        # distinct targets when the leaves' means are checked (leaf_backups), else zeros
        y = np.arange(len(batch), dtype=float) * self.leaf_backups
        try:
            with _regressor_calls():
                model.fit(batch, y)
            with _regressor_calls(len(y)):
                prediction = model.predict(batch)
        except (TypeError, ValueError) as exc:
            hint = ""
            if isinstance(observations, _ObjectRows):
                hint = ("; use a regressor that takes object sets, such as "
                        "boxtrees.BoxExtraTreesRegressor (fqi.make_box_forest), or wrap a "
                        "feature-vector regressor in a pipeline starting with "
                        "boxtrees.GridCounts (fqi.make_grid_ridge)")
            error = ValueError if isinstance(exc, ValueError) else TypeError
            raise error(f"{self.regressor!r} failed to fit and predict the env's "
                        f"observations, which FQI gives it as {observations.what} "
                        f"({type(exc).__name__}: {exc}){hint}") from exc
        _checked_prediction(prediction, len(batch),
                            lambda: f"{self.regressor!r}, fitted on the env's first "
                                    f"observations,")
        if self.leaf_backups:
            _check_leaf_means(model, batch, y)

    def get_env(self) -> VectorEnv | None:
        """The training vector env (None for an agent loaded without an env)."""
        return self._env

    def get_vec_normalize_env(self) -> None:
        """None: FQI normalizes no observations (stable-baselines3's callbacks ask)."""
        return None

    @property
    def logger(self) -> Logger:
        """The key-value logger that stable-baselines3 callbacks write to
        (``self.logger.record`` in a callback). Each iteration records its `history`
        record in it, every key prefixed with ``fqi/``, and dumps it at `num_timesteps`.
        By default it keeps the values in memory until that dump and writes them nowhere;
        `set_logger` gives it a stable-baselines3 ``Logger`` to write to.
        """
        if self._logger is None:
            self._logger = _KeyValueLogger()
        return self._logger

    def set_logger(self, logger: Logger) -> None:
        """Log to `logger` from now on, as stable-baselines3's ``set_logger``.

        Parameters
        ----------
        logger : stable_baselines3.common.logger.Logger
            Or any object with its ``record(key, value)`` and ``dump(step)`` methods; for
            example ``stable_baselines3.common.logger.configure(folder, ["stdout", "csv",
            "tensorboard"])``. Not saved or pickled with the agent.
        """
        for method in ("record", "dump"):
            if not callable(getattr(logger, method, None)):
                raise TypeError(f"logger must have record and dump methods, as a "
                                f"stable-baselines3 Logger; {type(logger).__name__} has no "
                                f"{method}")
        self._logger = logger

    # ------------------------------------------------------------------ training
    def learn(self, total_timesteps: int | None = None, callback: Callback | None = None,
              progress_bar: bool = False, *, n_iterations: int | None = None) -> Self:
        """Train for `total_timesteps` more environment steps, or `n_iterations` more
        iterations (continuing from earlier calls).

        Parameters
        ----------
        total_timesteps : int, default=None
            Environment steps to collect, in rounds of `samples_per_iteration` (the last one
            shorter), each followed by its `resample_every` iterations. A round keeps exactly
            its number of transitions; `num_timesteps` counts every env step, so it grows by
            exactly `total_timesteps` with one env, and by up to ``n_envs - 1`` more with
            several (they step together: the last step of a round may go past its count).
            Each call runs the exploration schedule over its own steps, as
            stable-baselines3's ``learn`` does by default (``reset_num_timesteps=True``):
            a call continuing training starts again from `exploration_initial_eps`.
        callback : callable, BaseCallback or list, default=None
            Called after every iteration. A stable-baselines3 ``BaseCallback`` or
            ``CallbackList`` is taken as it is, with the agent as its ``model``:
            ``init_callback`` and ``on_training_start(locals_, globals_)`` before the first
            iteration, ``update_locals`` and ``on_step()`` after each (``self.locals["record"]``
            is the iteration's record), ``on_training_end()`` at the end. A plain
            ``callback(locals_, globals_)`` is called after each iteration
            (``locals_["self"]`` is the agent, ``locals_["record"]`` the record). A list
            calls each in turn. A False return stops training (None continues).
        progress_bar : bool, default=False
            Show a tqdm bar over the steps (or iterations), with the last evaluation reward.
        n_iterations : int, default=None
            Instead of `total_timesteps`: this many iterations, collecting every
            `resample_every` of them (the thesis's protocol; the only way with
            ``resample_every=None``).

        Returns
        -------
        self : FQI
        """
        if (total_timesteps is None) == (n_iterations is None):
            raise TypeError("learn takes total_timesteps or n_iterations (one of them)")
        if total_timesteps is not None:
            total_timesteps = _check_int("total_timesteps", total_timesteps, 1)
            if self.resample_every is None:
                raise ValueError("resample_every=None collects once: learn(n_iterations=...) "
                                 "sets how many iterations run on that data")
        else:
            n_iterations = _check_int("n_iterations", n_iterations, 1)
        if self._env is None:
            raise ValueError("this agent has no env (it was loaded without one): pass env to "
                             "FQI.load or call set_env(env)")
        if self._collector is None:
            self._collector = _Collector(self._env, self._observations, self._world_rng)
            # per env: the exploratory action held (exploration_zeta) and its steps left
            self._held = np.zeros((2, self._env.num_envs), dtype=np.int64)
        return self._train(callback, progress_bar, total_timesteps, n_iterations)

    def learn_offline(self, dataset: Dataset, n_iterations: int,
                      callback: Callback | None = None, progress_bar: bool = False) -> Self:
        """Fitted Q-iteration on a fixed data set, without playing the env: FQI as first
        formulated, and as offline reinforcement learning works.

        The data set replaces the agent's transitions; unless `support_threshold` is None,
        the behaviour model is fitted on it (once per call), and the backups and the greedy
        policy keep to the actions it supports. `n_iterations` backups follow, each
        logged and evaluated as in `learn` (``eval_episodes=0`` plays nothing). A later
        `learn` goes on online: with `keep_data`, its transitions join the data set.

        Parameters
        ----------
        dataset : mapping, minari.MinariDataset, d3rlpy.dataset.MDPDataset or object
            A mapping of one entry per transition: ``observations`` and
            ``next_observations`` (an array of the observation space's shape per row, or
            for object sets a list of ``(n_i, d + 1)`` arrays or a `boxtrees.ObjectSets`),
            ``actions`` (ints), ``rewards``, ``terminations`` (no bootstrap after one;
            D4RL's name ``terminals`` too) and optionally ``truncations`` (bootstrapped
            through, as online; or ``timeouts``); flags are bools or numbers 0 and 1. Or a
            Minari dataset (its episodes; its spaces must be the agent's). Or d3rlpy's
            data: a d3rlpy 2 ``MDPDataset`` (its ``episodes``, each one row per step, with
            ``observations``, ``actions``, ``rewards`` and ``terminated``), or any object
            with d3rlpy's arrays as attributes, ``observations``, ``actions``, ``rewards``,
            ``terminals`` and optionally ``timeouts``: one row per step, each episode's
            rows in order and ended by a row flagged terminal (a transition with no
            bootstrap) or timeout (only the previous row's next observation), the next
            observation of a row the next row's. A missing or misaligned field is a
            ValueError naming it.
        n_iterations : int
        callback, progress_bar
            As in `learn`.

        Returns
        -------
        self : FQI

        Examples
        --------
        >>> import numpy as np
        >>> from sklearn.ensemble import ExtraTreesRegressor
        >>> from fqi import FQI
        >>> rng = np.random.default_rng(0)
        >>> x = rng.uniform(-2.4, 2.4, size=(500, 4)).astype(np.float32)
        >>> data = {"observations": x, "actions": rng.integers(0, 2, 500),
        ...         "rewards": np.ones(500), "next_observations": x,
        ...         "terminations": np.abs(x[:, 0]) > 2}
        >>> agent = FQI(ExtraTreesRegressor(n_estimators=5, random_state=0), "CartPole-v1",
        ...             eval_episodes=0, seed=0).learn_offline(data, n_iterations=3)
        >>> len(agent.history), agent.num_timesteps
        (3, 0)
        """
        n_iterations = _check_int("n_iterations", n_iterations, 1)
        if self._eval_seeds and self._eval_env is None:
            raise ValueError("this agent has no env to evaluate on (it was loaded without "
                             "one): pass env to FQI.load, call set_env(env), or load it with "
                             "eval_episodes=0")
        self._data = _dataset_transitions(dataset, self._observations, self.observation_space,
                                          self.action_space)
        self._support = self._next_supported = None
        if self.support_threshold is not None:
            self._fit_support()
        return self._train(callback, progress_bar, None, n_iterations, collect=False)

    def _train(self, callback, progress_bar, total_timesteps, n_iterations, collect=True):
        """The iterations of `learn` (collecting when due, if `collect`) and `learn_offline`,
        with the callbacks and the progress bar."""
        callback = _as_callback(callback)
        progress_bar = _check_bool("progress_bar", progress_bar)
        callback.init_callback(self)
        callback.on_training_start(locals(), globals())
        start_steps, done = self.num_timesteps, 0
        with tqdm(total=total_timesteps or n_iterations, desc="FQI",
                  unit="steps" if total_timesteps else "it", disable=not progress_bar) as bar:
            while True:
                if n_iterations is not None:
                    if done == n_iterations:
                        break
                    progress, budget = done / n_iterations, self.samples_per_iteration
                else:
                    steps = self.num_timesteps - start_steps
                    if self._collects() and steps >= total_timesteps:
                        break
                    progress = steps / total_timesteps
                    budget = min(self.samples_per_iteration, total_timesteps - steps)
                self.exploration_rate = self._exploration(progress)
                before = self.num_timesteps
                record = self._iterate(budget if collect else 0)
                done += 1
                bar.set_postfix(**_bar_figures(record))
                # (the last step of several envs may go past total_timesteps: not the bar)
                bar.update(min(self.num_timesteps - before, bar.total - bar.n)
                           if total_timesteps else 1)
                callback.update_locals(locals())
                if callback.on_step() is False:
                    break
        callback.on_training_end()
        return self

    def _exploration(self, progress):
        """The probability of a random action once `progress` (0 to 1) of training is done:
        linear from the initial to the final value over `exploration_fraction`."""
        if progress >= self.exploration_fraction:
            return self.exploration_final_eps
        return self.exploration_initial_eps + (
            self.exploration_final_eps - self.exploration_initial_eps
        ) * progress / self.exploration_fraction

    def _iterate(self, n_samples):
        """One iteration, in phases: collect `n_samples` (when due; none offline), targets,
        fit, evaluate; then its record, logged. Returns the record."""
        times = {}
        with _timed(times, "t_collect"):
            new, collect_reward = self._collect(n_samples)
        # Double FQI's halves, drawn anew each iteration (only then: other runs' draws stay)
        split = self._fit_rng.random(len(self._data)) < 0.5 if self.double else None
        with _timed(times, "t_targets"):
            targets = self._targets(self._data, split)
        with _timed(times, "t_fit"):
            args = (self.regressor, self._data, targets, self.n_actions, self._fit_rng,
                    self._q, self.iteration)
            self._q = (_DoubleQFunction.fit(*args, split, self.n_jobs) if self.double
                       else _ActionInputQFunction.fit(*args, self._encoding())
                       if self.action_input
                       else _QFunction.fit(*args, self.n_jobs))
        with _timed(times, "t_evaluate"):
            result = (evaluate(self, self._eval_env, seeds=self._eval_seeds)
                      if self._eval_seeds else None)
        record = {
            "iteration": self.iteration, "reward": np.nan if result is None else result.total,
            "mean_return": np.nan if result is None else result.mean,
            "train_return": (np.nan if self._collector is None
                             else self._collector.mean_episode_return()),
            "n_samples": len(self._data), "new_samples": new,
            "num_timesteps": self.num_timesteps, "collect_reward_per_step": collect_reward,
            "nodes_per_tree": _nodes_per_tree(self.q_functions_), **times,
            "t_total": sum(times.values()),
        }
        self._log(record)
        self.iteration += 1
        return record

    def _collect(self, n_samples):
        """Collect `n_samples` transitions into the data set if this iteration collects;
        returns how many were added and their mean reward (0 and NaN if none)."""
        if not (n_samples and self._collects()):
            return 0, np.nan
        try:
            batch, n_steps = self._collector.collect(
                n_samples, self._behaviour, None if self._q is None else self._acting_values)
        except Exception as exc:
            exc.add_note(f"(while FQI collected the transitions of iteration "
                         f"{self.iteration} on {self._env})")
            raise
        self.num_timesteps += n_steps
        new = (len(batch), float(batch.rewards.mean()))
        if self.keep_data and self._data is not None:
            batch = _Transitions.concatenate([self._data, batch], self._observations.concatenate)
            batch = batch[-self.max_samples:]
        self._data = batch
        if self._support is not None and self.support_threshold is not None:
            self._fit_support()  # after learn_offline: the grown data set's support
        return new

    def _fit_support(self):
        """Fit the behaviour model on the data set, and find the actions it supports at
        the data's next states (see `support_threshold`)."""
        classifier = self.support_classifier
        if classifier is None:
            classifier = _default_classifier(self.observation_space)
        self._support = _Support.fit(classifier, self._data, self.n_actions,
                                     self._support_rng)
        self._next_supported = self._supported(self._data.next_states)

    def _targets(self, data, split):
        """``r`` before any fit, then ``r + gamma * max_a Q_{n-1}(s', a)`` (no bootstrap
        after a termination; Double FQI's crossed value, halves `split`; the maximum over
        the actions supported at ``s'`` under `support_threshold`), then `leaf_backups`
        backups on ``Q_{n-1}``'s trees."""
        targets = data.rewards.copy()
        if self._q is not None:
            supported = self._next_supported
            # known when the data was just collected with Q_{n-1} (over the support of its
            # collection, refitted since); not Double FQI's values
            future = None if self.double or supported is not None else data.next_values
            if future is None:
                future = self._q.future(data, self.n_jobs, split, supported)
            discounts = np.where(data.terminated, 0.0, self.gamma)
            targets += discounts * future
            if self.leaf_backups:
                targets = self._q.backups(data, targets, discounts, self.leaf_backups, split,
                                          supported)
        data.next_values = None  # stale once Q_n is fitted
        return targets

    def _log(self, record):
        """Keep the iteration's `record` in `history` and write it to the CSV log, the
        key-value logger and (verbose) the console."""
        self.history.append(record)
        if self._csv_log is not None:
            self._csv_log.write(record)
        for key, value in record.items():
            self.logger.record(f"fqi/{key}", value)
        self.logger.dump(step=self.num_timesteps)
        if self.verbose:
            print(f"iteration {record['iteration']:3d}  reward {record['reward']:>12,.0f}  "
                  f"samples {record['n_samples']:>7,d}  collect {record['t_collect']:5.2f}s  "
                  f"targets {record['t_targets']:5.2f}s  fit {record['t_fit']:5.2f}s  "
                  f"evaluate {record['t_evaluate']:5.2f}s")

    def _collects(self):
        """Whether the next iteration collects transitions."""
        return self._data is None or (self.resample_every is not None
                                      and self.iteration % self.resample_every == 0)

    def _behaviour(self, obs, q, envs):
        """Collection policy for the observations `obs` of the envs `envs` (indices):
        uniform random before the first fit (``q`` is None), then epsilon-greedy on the
        Q-values ``q`` of the observations; with `exploration_zeta`, random actions held."""
        if self.exploration_zeta is not None:
            return self._held_epsilon_greedy(q, envs)
        if q is None:
            return self._action_rng.integers(self.n_actions, size=len(envs))
        return self._epsilon_greedy(q)

    def _held_epsilon_greedy(self, q, envs):
        """Temporally-extended epsilon-greedy actions of the envs `envs` (see
        `exploration_zeta`); random play (probability 1) before the first fit."""
        held, left = self._held
        rng = self._action_rng
        epsilon = 1.0 if q is None else self.exploration_rate
        start = envs[(left[envs] == 0) & (rng.random(len(envs)) < epsilon)]
        held[start] = rng.integers(self.n_actions, size=len(start))
        left[start] = np.minimum(rng.zipf(self.exploration_zeta, size=len(start)), _MAX_HOLD)
        holding = left[envs] > 0
        actions = held[envs] if q is None else np.where(holding, held[envs], self._greedy(q))
        left[envs[holding]] -= 1
        return actions

    def _epsilon_greedy(self, q):
        n = len(q)
        explore = self._action_rng.random(n) < self.exploration_rate
        return np.where(explore, self._action_rng.integers(self.n_actions, size=n),
                        self._greedy(q))

    def _greedy(self, q):
        """The greedy actions of Q-values ``q``, ties broken as `tie_break` says."""
        if self.tie_break == "first":
            return q.argmax(axis=1)
        best = q.max(axis=1, keepdims=True)
        tied = q >= best - _TIE_TOLERANCE * np.abs(best)
        return ((1.0 + self._action_rng.random(q.shape)) * tied).argmax(axis=1)

    # ------------------------------------------------------------------ acting
    def q_values(self, observation: Observation) -> np.ndarray:
        """Q-values of every action.

        Parameters
        ----------
        observation
            As for `predict`.

        Returns
        -------
        q : ndarray of shape (n_actions,) for one observation, (n, n_actions) for a batch
        """
        batch, single = self._observations.as_input(observation)
        q = self._q_values(batch)
        return q[0] if single else q

    def _q_values(self, batch):
        if self._q is None:
            raise NotFittedError("this FQI agent has no Q-function yet; call learn() first")
        return self._q.values(batch, self.n_jobs)

    def _supported(self, batch):
        """The actions supported at the observations of `batch` (`support_threshold`), a
        mask of shape ``(n, n_actions)``; None when every action is."""
        if self._support is None or not self.support_threshold:
            return None
        return self._support.supported(batch, self.support_threshold)

    def _acting_values(self, batch):
        """The Q-values the greedy policy picks from: those of unsupported actions at
        -inf."""
        return _masked(self._q_values(batch), self._supported(batch))

    @property
    def support_model_(self) -> Any:
        """The behaviour model fitted on the offline data (see `support_threshold`), None
        without one."""
        return None if self._support is None else self._support.model

    @property
    def q_functions_(self) -> list[Regressor] | None:
        """The fitted ``Q_n``, one regressor per action (None before the first iteration);
        with `double`, the first half's then the second half's: ``2 * n_actions``; with
        `action_input`, the one regressor."""
        return None if self._q is None else self._q.models

    def predict(self, observation: Observation, state: object = None,
                episode_start: object = None, deterministic: bool = True
                ) -> tuple[np.integer | np.ndarray, None]:
        """Actions for one observation or a batch (the stable-baselines3 signature).

        Parameters
        ----------
        observation : array-like or batch
            For a ``Box`` space: one observation of its shape, or a batch
            ``(batch, *shape)``. For object sets: one ``(n, d + 1)`` array of rows
            ``[f_1, ..., f_d, type]``; a batch: anything with ``data`` and ``offsets`` (a
            `boxtrees.ObjectSets`, a batched engine's observations), a list of ``(n_i, d +
            1)`` arrays or a ``(batch, n, d + 1)`` array; or padded rows ``[f_1, ..., f_d,
            type, valid]`` (``envs.PaddedObjects``): ``(max_objects, d + 2)`` or ``(batch,
            max_objects, d + 2)``.
        state, episode_start
            Unused (the policy is reactive); accepted for stable-baselines3.
        deterministic : bool, default=True
            Greedy actions (among the actions the data support, after `learn_offline`:
            `support_threshold`); False draws epsilon-greedy ones (with
            `exploration_rate`).

        Returns
        -------
        actions : numpy int, or ndarray of int of shape (batch,)
        state : None
        """
        batch, single = self._observations.as_input(observation)
        q = self._acting_values(batch)
        actions = q.argmax(axis=1) if deterministic else self._epsilon_greedy(q)
        return (actions[0] if single else actions), None

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | os.PathLike[str]) -> None:
        """Save the agent with joblib: its attributes (every constructor parameter, the
        fitted Q-functions, the history, the spaces and the random streams), less the envs,
        the transitions, the threads and the open log. An env given by its id is saved as
        the id; any other env is not saved.

        Parameters
        ----------
        path : str or path-like
        """
        state = {k: v for k, v in self.__dict__.items() if k not in _UNSAVED}
        for name in ("env", "eval_env"):
            if not isinstance(state[name], str):
                state[name] = None
        _write_save(state, path)

    @classmethod
    def load(cls, path: str | os.PathLike[str], env: EnvLike | None = None,
             **params: Any) -> Self:
        """Load an agent saved by `save`.

        Loading unpickles the file, which can run arbitrary code: load only trusted files.

        Parameters
        ----------
        path : str or path-like
            A file written by `save`; ValueError for any other file (empty, truncated,
            damaged, not an FQI save, or a save of another format version), and
            FileNotFoundError for a missing one.
        env : str, gymnasium.Env, gymnasium.vector.VectorEnv or callable, default=None
            Play and train on this env (same spaces as the saved agent). Default: the saved
            id, if the agent was made from one; otherwise the agent has no env: it predicts,
            and learns after `set_env`.
        **params
            Constructor parameters to change (``log_path``, ``n_jobs``, ``eval_seeds``...),
            checked as by the constructor; the others keep their saved values (a saved
            ``log_path`` too: further iterations append to that CSV; pass
            ``log_path=None`` to log nowhere). ``double`` and ``action_input`` change
            only on an agent that has no Q-function yet (ValueError otherwise).

        Returns
        -------
        agent : FQI
            Further `learn` calls continue the iteration count with freshly collected data.
        """
        names = cls._param_names()
        unknown = sorted(set(params) - set(names))
        if unknown:
            raise TypeError(f"FQI.load got unknown parameters {unknown}; the constructor "
                            f"parameters are {names}")
        state = _read_save(path, required=[*names, *_LEARNED])
        agent = cls.__new__(cls)
        agent.__dict__.update({k: v for k, v in state.items() if k not in names})
        agent._set_params({**{name: state[name] for name in names}, **params})
        for name in ("double", "action_input"):
            if agent._q is not None and getattr(agent, name) != state[name]:
                raise ValueError(f"{name} cannot change once the agent has a Q-function: "
                                 f"{path} holds one made with {name}={state[name]}")
        agent._check_action_input(agent._observations, agent.observation_space)
        agent._env = agent._eval_env = agent._collector = agent._held = None
        agent._data = agent._next_supported = agent._logger = None
        env = agent.env if env is None else env
        if env is not None:
            agent.set_env(env)
        return agent

    def __getstate__(self) -> dict[str, Any]:
        """The agent's attributes for pickle: with its envs (an env that does not pickle
        makes the agent unpicklable) and random streams, so an unpickled agent learns on
        exactly as this one would; less the transitions when the next
        iteration replaces them, and less the `logger` (a copy starts with the default one).
        A ``log_path`` travels: a copy appends to its CSV."""
        state = self.__dict__.copy()
        state["_logger"] = None  # SB3's loggers hold open files
        if self._collects() and not self.keep_data:
            state["_data"] = state["_next_supported"] = None
        return state

    def __repr__(self) -> str:
        return (f"FQI(regressor={self.regressor!r}, gamma={self.gamma}, "
                f"samples_per_iteration={self.samples_per_iteration}, "
                f"resample_every={self.resample_every}, keep_data={self.keep_data}, "
                f"iteration={self.iteration})")


@contextmanager
def _timed(times, name):
    """Record the seconds the block takes as ``times[name]``."""
    start = time.perf_counter()
    yield
    times[name] = time.perf_counter() - start


def _bar_figures(record):
    """The figures the progress bar shows of an iteration's `record`: the evaluation's
    total reward when there was one, else the training episodes' mean return."""
    if np.isnan(record["reward"]):
        return {"train_return": f"{record['train_return']:,.1f}"}
    return {"reward": f"{record['reward']:,.0f}"}


def _nodes_per_tree(models):
    """Mean node count per tree over the models' forests (looking inside pipelines); NaN if
    they have no trees."""
    counts = []
    for model in models:
        forest = model[-1] if hasattr(model, "steps") else model
        for tree in getattr(forest, "estimators_", []):
            counts.append(getattr(tree, "tree_", tree).node_count)
    return float(np.mean(counts)) if counts else np.nan
