"""What every unit kind provides, the registry of kinds, and the settings they share."""
import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..stats import SettingStats, sd, se

__all__ = ["UnitKind", "KINDS", "GameSettings", "fmt"]

KINDS = {}  # name -> the UnitKind instance (filled as the kinds' modules are imported)


@dataclass(frozen=True)
class GameSettings:
    """Parameters every unit on the game has: which game, seen how, under which rules.

    Parameters
    ----------
    env_id : str
        A registered id of `envs`.
    view : str, default=None
        The game's ``view`` argument ("local", "global", ...), if the setting changes it.
    rules : dict, default={}
        Constants of `envs.WorldRules` the setting changes (the ablations').
    """

    env_id: str
    view: str = None
    rules: dict = field(default_factory=dict)

    def env_kwargs(self):
        """The game's arguments the setting changes."""
        return {**({"view": self.view} if self.view is not None else {}), **self.rules}


class UnitKind:
    """One kind of unit: how a unit runs, what it costs and records, and how a setting's
    runs are summarised, drawn and tabled.

    A subclass names itself (`name`), declares its `Settings` (a frozen dataclass of its
    parameters, ``kind`` excluded: unknown or missing ones fail when the registry is
    imported) and `budget_fields`, and implements `run`, `cost`, `record_shape`,
    `summarise` and `plot`; it is registered in `KINDS` by being defined. Defaults serve
    kinds that score one reward per run.

    Attributes
    ----------
    name : str
        The ``kind`` of a registry setting.
    Settings : type
        Its parameters, typed.
    budget_fields : tuple of str
        The `Budget` fields a unit's result depends on (part of its cache key).
    one_seed : bool
        One run per setting unless the experiment says otherwise (one data set, one
        forest, one deterministic score), where the others get the budget's seeds.
    resumable : bool
        `run` takes a `cache.Checkpoint` and resumes from it.
    """

    name = None
    Settings = GameSettings
    budget_fields = ()
    one_seed = False
    resumable = False

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.name is not None:
            if cls.name in KINDS:
                raise ValueError(f"unit kind {cls.name!r} defined twice")
            KINDS[cls.name] = cls()

    def settings(self, params):
        """The typed settings of a unit's parameters (``params["kind"]`` aside).

        Raises
        ------
        ValueError
            If a parameter is unknown to the kind, a required one is missing or one has a
            value the kind does not take.
        """
        values = {key: value for key, value in params.items() if key != "kind"}
        known = {f.name for f in dataclasses.fields(self.Settings)}
        unknown = sorted(set(values) - known)
        if unknown:
            raise ValueError(f"{self.name} units take no parameter {', '.join(unknown)} "
                             f"(known: {', '.join(sorted(known))})")
        try:
            return self.Settings(**values)
        except TypeError as error:  # a required parameter missing
            raise ValueError(f"{self.name} units: {error}") from None

    def run(self, unit, checkpoint=None):
        """The unit's JSON-ready result (`seconds` is added by `units.run_unit`)."""
        raise NotImplementedError

    def cost(self, unit):
        """Rough run time in seconds on 2 free cores, for the progress bar's ETA."""
        raise NotImplementedError

    def record_shape(self, budget):
        """What the report reads from a unit's result, as a shape for `cache`'s checks."""
        return {"reward": float}

    def summarise(self, label, runs):
        """The `SettingStats` of a setting from its unit results (at least one)."""
        rewards = np.array([r["reward"] for r in runs])
        return SettingStats(label, self.name, len(runs), float(rewards.mean()), sd(rewards),
                            se(rewards), best=float(rewards.max()), seconds=_seconds(runs))

    def values(self, result):
        """A result's numbers, one CSV row each."""
        return [result["reward"]]

    def curve(self, stats, records):
        """Score against environment steps for the reward-vs-steps figure: ``(steps, mean,
        sd)`` over the runs, or None for a score that does not depend on steps (a
        reference policy's, drawn as a line)."""
        return None

    def plot(self, experiment, stats, runs, budget):
        """The experiment's figure, for an experiment of this kind."""
        raise NotImplementedError

    def table(self, experiment, stats, runs):
        """The report's table of the settings: our numbers beside the thesis's (lines of
        markdown)."""
        thesis = experiment.thesis
        ceiling = stats.get(experiment.ceiling)
        if ceiling is not None and not ceiling.score > 0:
            ceiling = None  # a share of nothing, or of a loss, means nothing
        share = "" if ceiling is None else f" share of the {experiment.ceiling}'s |"
        lines = ["| setting | runs | score +- sd over runs |" + share + " best evaluation | "
                 "mean abs. change between iterations | minutes per run | thesis |",
                 "| --- " * (7 + bool(share)) + "|"]
        for label, s in stats.items():
            part = "" if ceiling is None else f" {s.score / ceiling.score:.0%} |"
            lines.append(f"| {label} | {s.n_runs} | {fmt(s.score)} +- {fmt(s.score_sd)} |"
                         f"{part} {fmt(s.best)} | {fmt(s.instability)} | "
                         f"{s.seconds / 60:.1f} | {thesis.get(label, '')} |")
        randoms = [s.random_reward for s in stats.values() if not math.isnan(s.random_reward)]
        if randoms:
            lines.append(f"| random policy | | {fmt(sum(randoms) / len(randoms))} |"
                         + " |" * bool(share) + f" | | | {thesis.get('random policy', '')} |")
        return lines


def _seconds(runs):
    """Mean wall time of the runs."""
    return float(np.mean([r["seconds"] for r in runs]))


def fmt(value, digits=0):
    """A number for the report's tables ("-" for None or NaN)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    return f"{value:,.{digits}f}"
