"""``dqn``: stable-baselines3 DQN on the game's grid counts, as many environment steps as
one FQI run, scored once at the end like FQI."""
from dataclasses import dataclass

from fqi import GridObservation

from ...zoo_hyperparams import SMALL_TASK_DQN
from .. import plots
from ._base import GameSettings, UnitKind
from ._game import GAMMA, make_env, reference_seeds

__all__ = ["GridDQN", "sb3_steps", "sb3_cost"]


@dataclass(frozen=True)
class GridDQNSettings(GameSettings):
    """``n_bins``: grid cells per axis of the observation (`fqi.GridObservation`)."""

    n_bins: int = 10


def sb3_steps(unit, step_scale=1.0):
    """A neural baseline's environment steps: the budget's, else one FQI run's, times
    `step_scale`."""
    budget = unit.budget
    return round((budget.dqn_steps or budget.iterations * unit.samples) * step_scale)


def sb3_cost(unit, step_scale=1.0, slow=False):
    """Rough seconds of a neural baseline: its steps, four times dearer for DQN's updates
    through the set encoder (`slow`)."""
    budget = unit.budget
    return (2.5e-3 * (budget.dqn_steps or budget.iterations * unit.samples) * step_scale
            * (4.0 if slow else 1.0))


class GridDQN(UnitKind):
    """DQN (`zoo_hyperparams.SMALL_TASK_DQN`, the game's discount factor) on 10 x 10 grid
    counts, its final policy's reward on the reference worlds."""

    name = "dqn"
    Settings = GridDQNSettings
    budget_fields = ("iterations", "eval_steps", "dqn_steps")

    def run(self, unit, checkpoint=None):
        from ...training import EvalCallback, WrappedPolicy, train_sb3  # imports torch

        settings, budget = unit.settings, unit.budget
        steps = sb3_steps(unit)
        env = make_env(settings)
        grid = GridObservation(env, n_bins=settings.n_bins)  # counts the evaluation's sets
        final = EvalCallback(env, steps, seeds=reference_seeds(env, budget),
                             policy=lambda model: WrappedPolicy(model, grid), score="total",
                             scale=budget.reward_scale)
        _, train_seconds, _ = train_sb3(
            "DQN", lambda: GridObservation(make_env(settings), n_bins=settings.n_bins), steps,
            {**SMALL_TASK_DQN, "gamma": GAMMA}, seed=unit.seed, callback=final)
        return {"reward": final.evaluations[-1][1], "total_timesteps": steps,
                "train_seconds": train_seconds, "eval_seconds": final.eval_seconds}

    def cost(self, unit):
        return sb3_cost(unit)

    def plot(self, experiment, stats, runs, budget):
        return plots.reward_bars(experiment, stats, budget)
