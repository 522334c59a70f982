"""What the kinds that learn on the game share: its envs, its reference worlds, the
regressors of a setting and the FQI agent of the thesis's protocol."""
from dataclasses import dataclass

import gymnasium as gym

import envs
from fqi import FQI, make_box_forest, make_grid_ridge

from ._base import GameSettings

__all__ = ["GAMMA", "ForestSettings", "AgentSettings", "make_env", "reference_seeds",
           "regressor", "make_agent", "forest_cost", "actions_cost", "agent_cost"]

# Discount factor of every FQI and DQN run (the thesis does not state one; 0.5 scored best
# in the measured comparison of docs/fqi.md, "Discount factor"). Pinned here so a changed
# library default cannot silently change cached results.
GAMMA = 0.5
THESIS_EPSILON = 0.2  # the thesis's exploration, the same throughout (after a random round)
_MODELS = ("box", "grid")


@dataclass(frozen=True)
class ForestSettings(GameSettings):
    """A regressor of the thesis: a box forest (``model="box"``: ``test_type``,
    ``test_width``, ``n_estimators``, ``n_tests``, ``min_samples_split``; ``test_region``,
    the half-side of the agent-centred square its tests are drawn in, None: the whole view;
    or ``type_regions``, ``(type id, half-side)`` pairs: such squares for some types only)
    or grid counts with a ridge (``model="grid"``: ``n_bins``, ``alpha``)."""

    model: str = None
    test_type: str = None
    test_width: float = 1.0
    n_estimators: int = None
    n_tests: int = None
    min_samples_split: int = None
    test_region: float = None
    type_regions: tuple = None
    n_bins: int = None
    alpha: float = 1.0

    def __post_init__(self):
        needs = {"box": ("test_type", "n_estimators", "n_tests", "min_samples_split"),
                 "grid": ("n_bins",)}
        if self.model not in needs:
            raise ValueError(f"model must be one of {_MODELS}, got {self.model!r}")
        missing = [name for name in needs[self.model] if getattr(self, name) is None]
        if missing:
            raise ValueError(f"a {self.model} model needs {', '.join(missing)}")
        if self.test_region is not None and not (self.model == "box" and self.test_region > 0):
            raise ValueError(f"test_region must be a box model's positive half-side, got "
                             f"{self.test_region!r}")
        if self.type_regions is not None and not (
                self.model == "box" and self.test_region is None
                and all(r > 0 for _, r in self.type_regions)):
            raise ValueError(f"type_regions must be a box model's (type id, positive "
                             f"half-side) pairs, without test_region; got "
                             f"{self.type_regions!r}")


@dataclass(frozen=True)
class AgentSettings(ForestSettings):
    """An FQI agent of the thesis's protocol with its regressor: ``gamma``, collections
    every ``resample_every`` iterations, ``keep_data`` up to ``max_samples`` transitions
    (default: one iteration's), and with ``move_frame`` one regressor of every move seen in
    its own frame (`envs.in_move_frame`) instead of one per move. Exploration falls linearly
    over the run from the thesis's epsilon to ``final_epsilon`` (by default it stays)."""

    gamma: float = GAMMA
    resample_every: int = 1
    keep_data: bool = False
    max_samples: int = None
    move_frame: bool = False
    final_epsilon: float = THESIS_EPSILON


def make_env(settings, **kwargs):
    """The setting's game (`kwargs`: more arguments of ``gymnasium.make``)."""
    return gym.make(settings.env_id, **settings.env_kwargs(), **kwargs)


def reference_seeds(env, budget):
    """The thesis's evaluation on the game's reference worlds: one episode of ``max_steps``
    per world, ``budget.eval_steps`` steps in all."""
    return envs.reference_worlds(budget.eval_steps // env.unwrapped.rules.max_steps)


def regressor(settings, env, budget, seed):
    """The setting's regressor, with the budget's caps on M and K."""
    if settings.model == "grid":
        return make_grid_ridge(env, n_bins=settings.n_bins, alpha=settings.alpha)
    view_bounds = None          # the whole view
    if settings.test_region is not None:
        view_bounds = (-settings.test_region, settings.test_region) * 2
    elif settings.type_regions is not None:     # the other types: the whole view
        view_bounds = {int(t): float(r) for t, r in settings.type_regions}
    return make_box_forest(
        env, test_type=settings.test_type, test_width=settings.test_width,
        n_estimators=_capped(settings.n_estimators, budget.max_trees),
        n_tests=_capped(settings.n_tests, budget.max_tests),
        min_samples_split=settings.min_samples_split, n_jobs=-1, random_state=seed,
        view_bounds=view_bounds)


def _capped(value, cap):
    return value if cap is None else min(value, cap)


def make_agent(settings, budget, seed, samples):
    """The FQI agent of a registry setting on the game, with the thesis's protocol: up to
    400 training worlds in lockstep (the game's batched engine, through its vector entry
    point), epsilon 0.2 (or falling linearly to ``settings.final_epsilon`` over the run),
    greedy ties to the first action, the actions' Q-functions predicted side by side
    (``n_jobs=-1``), evaluated on the reference worlds after every iteration; learn it with
    ``learn(n_iterations=...)``.

    Parameters
    ----------
    settings : AgentSettings
    budget : reproduce.budgets.Budget
        Its caps on trees and tests, and its evaluation steps.
    seed : int
    samples : int
        Samples per iteration.

    Returns
    -------
    agent : fqi.FQI
    """
    env = make_env(settings)
    if settings.move_frame and env.action_space.n != 4:
        env.close()
        raise ValueError(f"move_frame needs the game of four moves; {settings.env_id} with "
                         f"{settings.rules} has {env.action_space.n} actions")
    return FQI(regressor(settings, env, budget, seed), env, gamma=settings.gamma,
               samples_per_iteration=samples, resample_every=settings.resample_every,
               keep_data=settings.keep_data,
               max_samples=max(settings.max_samples or samples, samples),
               exploration_initial_eps=THESIS_EPSILON,
               exploration_final_eps=settings.final_epsilon, exploration_fraction=1.0,
               action_input=envs.in_move_frame if settings.move_frame else False,
               tie_break="first", n_envs=min(400, samples), n_jobs=-1,
               eval_seeds=reference_seeds(env, budget), seed=seed)


def forest_cost(settings):
    """A regressor's cost relative to the thesis's standard forest (M=15, K=300)."""
    if settings.model != "box":
        return 3.0
    return settings.n_estimators / 15 * (settings.n_tests / 300) ** 0.5


def actions_cost(settings):
    """The sword game's 8 actions cost twice the 4 of the others (four times, planning)."""
    return 2.0 if settings.env_id == "ObjectWorldSword-v0" else 1.0


def agent_cost(settings, iterations, samples):
    """Rough seconds of `iterations` FQI iterations of `samples` on 2 free cores (measured
    at the quick budget)."""
    return (0.3 * iterations * samples / 1000 * forest_cost(settings) * actions_cost(settings)
            * (3.0 if settings.keep_data else 1.0)
            * (9.0 if settings.view == "global" else 1.0))  # ~360 objects, not ~40
