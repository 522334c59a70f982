"""``policy``: the score of a reference policy that does not learn (the planner's ceiling,
the scripted heuristic, random play) on the reference worlds, played as the learners."""
from dataclasses import dataclass

import gymnasium as gym

import envs
from fqi import RandomPolicy, evaluate

from ..budgets import EVAL_REFERENCE_STEPS
from .. import plots
from ._base import GameSettings, UnitKind
from ._game import actions_cost, make_env, reference_seeds

__all__ = ["ReferencePolicy"]

_POLICIES = ("planner", "greedy", "random")


@dataclass(frozen=True)
class ReferencePolicySettings(GameSettings):
    """``policy``: "planner" (`envs.LookaheadPlanner` with ``depth`` and ``width``: the
    ceiling, it plays with the simulator), "greedy" (`envs.GreedyPolicy`, scripted) or
    "random" (uniform, action seed: the unit's)."""

    policy: str = None
    depth: int = None
    width: int = None

    def __post_init__(self):
        if self.policy not in _POLICIES:
            raise ValueError(f"policy must be one of {_POLICIES}, got {self.policy!r}")


class ReferencePolicy(UnitKind):
    """A reference policy's reward, the player's name and each episode's return."""

    name = "policy"
    Settings = ReferencePolicySettings
    budget_fields = ("eval_steps",)
    one_seed = True

    def run(self, unit, checkpoint=None):
        settings, budget = unit.settings, unit.budget
        env = make_env(settings)
        reference = reference_seeds(env, budget)
        env.close()
        worlds = gym.make_vec(settings.env_id, num_envs=len(reference),
                              **settings.env_kwargs())
        if settings.policy == "planner":
            planner = envs.LookaheadPlanner(**{k: getattr(settings, k) for k in ("depth", "width")
                                               if getattr(settings, k) is not None})
            policy = _PlannerPolicy(planner, worlds)
        elif settings.policy == "greedy":
            policy = envs.GreedyPolicy(worlds)
        else:
            policy = RandomPolicy(worlds, seed=unit.seed)
        result = evaluate(policy, worlds, seeds=reference)
        worlds.close()
        player = repr(planner) if settings.policy == "planner" else type(policy).__name__
        return {"reward": result.total * budget.reward_scale, "player": player,
                "episode_returns": result.returns.tolist()}

    def cost(self, unit):
        """The planner: about a minute per 20,000 steps with 4 actions."""
        if unit.settings.policy != "planner":
            return 1.0
        return (60.0 * actions_cost(unit.settings) ** 2 * unit.budget.eval_steps
                / EVAL_REFERENCE_STEPS)

    def plot(self, experiment, stats, runs, budget):
        return plots.reward_bars(experiment, stats, budget)


class _PlannerPolicy:
    """`envs.LookaheadPlanner` behind ``predict``: it plans from the state of `worlds`
    (the vector env being evaluated), not from the observations."""

    def __init__(self, planner, worlds):
        self.planner, self.worlds = planner, worlds

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return self.planner.act(self.worlds), None
