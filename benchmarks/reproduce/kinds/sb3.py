"""``sb3``: a tuned stable-baselines3 ``DQN`` or ``PPO`` run on the game, scored on the
reference worlds at evenly spaced points of training (the last at its end)."""
from dataclasses import dataclass, field

import numpy as np

import envs
from fqi import GridObservation

from .. import plots
from ..cache import ListOf
from ._base import GameSettings, UnitKind
from ._game import make_env, reference_seeds
from .dqn import sb3_cost, sb3_steps

__all__ = ["TunedBaseline", "with_set_encoder"]


@dataclass(frozen=True)
class TunedBaselineSettings(GameSettings):
    """``algo`` ("DQN" or "PPO"); ``observation``: "grid" (`fqi.GridObservation` counts
    with ``n_bins``) or "objects" (`envs.PaddedObjects` of ``max_objects`` rows through
    `fqi.SetEncoder`, with ``attention``); ``hyperparams``: the algorithm's keyword
    arguments in rl-zoo3's form (see `training.train_sb3`); ``step_scale``: the share of one
    FQI run's environment steps it gets; ``checkpoints``: evaluations during and after
    training."""

    algo: str = None
    observation: str = None
    hyperparams: dict = field(default_factory=dict)
    step_scale: float = 1.0
    checkpoints: int = 1
    n_bins: int = None
    max_objects: int = None
    attention: bool = False

    def __post_init__(self):
        if self.algo not in ("DQN", "PPO"):
            raise ValueError(f"algo must be 'DQN' or 'PPO', got {self.algo!r}")
        needs = {"grid": "n_bins", "objects": "max_objects"}
        if self.observation not in needs:
            raise ValueError(f"observation must be 'grid' or 'objects', got "
                             f"{self.observation!r}")
        if getattr(self, needs[self.observation]) is None:
            raise ValueError(f"observation {self.observation!r} needs "
                             f"{needs[self.observation]}")

    def wrap(self, env):
        """`env` observed as the model observes it."""
        if self.observation == "grid":
            return GridObservation(env, n_bins=self.n_bins)
        return envs.PaddedObjects(env, max_objects=self.max_objects)

    def model_hyperparams(self):
        """The hyperparameters, with the set encoder for object observations."""
        if self.observation == "grid":
            return self.hyperparams
        return with_set_encoder(self.hyperparams, self.attention)


def with_set_encoder(hyperparams, attention=False):
    """stable-baselines3 `hyperparams` whose policy reads padded objects through
    `fqi.SetEncoder` (with `attention`, and the encoder's other arguments that
    ``policy_kwargs["features_extractor_kwargs"]`` holds)."""
    from fqi import SetEncoder  # imports torch: only here

    given = hyperparams.get("policy_kwargs", {})
    policy_kwargs = {**given, "features_extractor_class": SetEncoder,
                     "features_extractor_kwargs": {**given.get("features_extractor_kwargs", {}),
                                                   "attention": attention}}
    return {**hyperparams, "policy_kwargs": policy_kwargs}


class TunedBaseline(UnitKind):
    """The reward curve of a stable-baselines3 run and its final policy's reward."""

    name = "sb3"
    Settings = TunedBaselineSettings
    budget_fields = ("iterations", "eval_steps", "dqn_steps")

    def run(self, unit, checkpoint=None):
        from ...training import EvalCallback, WrappedPolicy, train_sb3  # imports torch

        settings, budget = unit.settings, unit.budget
        steps = sb3_steps(unit, settings.step_scale)
        env = make_env(settings)
        wrapper = settings.wrap(env)  # pads or counts the evaluation's observations
        curve = EvalCallback(env, steps / settings.checkpoints,
                             seeds=reference_seeds(env, budget),
                             policy=lambda model: WrappedPolicy(model, wrapper), score="total",
                             scale=budget.reward_scale)
        model, train_seconds, _ = train_sb3(
            settings.algo, lambda: settings.wrap(make_env(settings)), steps,
            settings.model_hyperparams(), seed=unit.seed, callback=curve)
        return {"reward": curve.evaluations[-1][1], "curve": curve.evaluations,
                "total_timesteps": int(model.num_timesteps), "train_seconds": train_seconds,
                "eval_seconds": curve.eval_seconds}

    def cost(self, unit):
        settings = unit.settings
        return sb3_cost(unit, settings.step_scale,
                        slow=settings.observation == "objects" and settings.algo != "PPO")

    def record_shape(self, budget):
        return {"reward": float, "curve": ListOf(ListOf(float, 2))}

    def curve(self, stats, records):
        curves = np.array([r["result"]["curve"] for r in records], dtype=float)
        rewards = curves[:, :, 1]
        return curves[0, :, 0], rewards.mean(axis=0), rewards.std(axis=0)

    def plot(self, experiment, stats, runs, budget):
        return plots.reward_bars(experiment, stats, budget)
