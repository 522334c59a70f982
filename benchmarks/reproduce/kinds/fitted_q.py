"""``fqi``: an FQI run of the thesis's protocol on the game, its reward after every
iteration (Figs. 3.1-3.10)."""
import time

import numpy as np

from fqi import RandomPolicy, evaluate

from .. import plots
from ..stats import LAST_WINDOW, SettingStats, sd, se
from ..cache import ListOf
from ._base import UnitKind, _seconds
from ._game import AgentSettings, agent_cost, make_agent, make_env, reference_seeds

__all__ = ["FittedQ"]

_HISTORY = ("n_samples", "nodes_per_tree", "t_collect", "t_fit", "t_evaluate", "t_total")


class FittedQ(UnitKind):
    """Rewards per iteration (per 20,000 evaluation steps) and the random policy's; with a
    checkpoint, the pickled agent (its envs and random streams) after an iteration but the
    last, which a later run resumes to the result it would have had uninterrupted."""

    name = "fqi"
    Settings = AgentSettings
    budget_fields = ("iterations", "eval_steps", "max_trees", "max_tests")
    resumable = True

    def run(self, unit, checkpoint=None):
        budget = unit.budget
        start = time.perf_counter()
        saved = None if checkpoint is None else checkpoint.load()
        agent, earlier = ((saved["agent"], saved["seconds"]) if saved is not None
                          else (make_agent(unit.settings, budget, unit.seed, unit.samples), 0.0))

        def save(locals_, globals_):
            if agent.iteration < budget.iterations:
                checkpoint.save({"agent": agent,
                                 "seconds": earlier + time.perf_counter() - start})

        if agent.iteration < budget.iterations:
            agent.learn(n_iterations=budget.iterations - agent.iteration,
                        callback=None if checkpoint is None else save)
        env = make_env(unit.settings)
        random_reward = evaluate(RandomPolicy(env, seed=unit.seed), env,
                                 seeds=reference_seeds(env, budget)).total
        scale = budget.reward_scale
        return {"rewards": [r["reward"] * scale for r in agent.history],
                "random_reward": random_reward * scale,
                "history": [{k: r[k] for k in _HISTORY} for r in agent.history],
                "earlier_seconds": earlier}

    def cost(self, unit):
        return agent_cost(unit.settings, unit.budget.iterations, unit.samples)

    def record_shape(self, budget):
        return {"rewards": ListOf(float, budget.iterations), "random_reward": float}

    def summarise(self, label, runs):
        curves = np.array([[r["random_reward"], *r["rewards"]] for r in runs])
        window = curves[:, 1:][:, -LAST_WINDOW:]
        scores = window.mean(axis=1)
        changes = np.abs(np.diff(curves[:, 1:], axis=1))
        return SettingStats(
            label, self.name, len(runs), float(scores.mean()), sd(scores), se(window),
            curve_mean=curves.mean(axis=0), curve_sd=curves.std(axis=0),
            best=float(curves[:, 1:].max()),
            instability=float(changes.mean()) if changes.size else np.nan,
            mean_peak=float(curves[:, 1:].mean(axis=0).max()),
            spread=float(curves[:, 1:].std(axis=0).mean()) if len(runs) > 1 else np.nan,
            random_reward=float(curves[:, 0].mean()), seconds=_seconds(runs))

    def values(self, result):
        return [result["random_reward"], *result["rewards"]]  # step 0: the random policy

    def curve(self, stats, records):
        steps = np.arange(len(stats.curve_mean)) * records[0]["budget"]["samples"]
        return steps, stats.curve_mean, stats.curve_sd

    def plot(self, experiment, stats, runs, budget):
        return plots.reward_curves(experiment, stats, budget)

