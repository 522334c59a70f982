"""Declarative checks of the thesis's claims, evaluated on our measured numbers.

Each rule is a small frozen dataclass with a ``claim`` (the thesis's wording, short) and a
``check(stats)`` method taking ``{label: SettingStats}`` and returning a `Verdict`. Nothing
here knows any result in advance: the verdicts come from the numbers only.
"""
import math
from dataclasses import dataclass, replace

__all__ = ["Verdict", "Ranking", "Similar", "MoreStable", "Sign", "NearRandom",
           "HighestPeak", "Falls", "Faster", "AtLeast"]

# Two scores closer than this many combined standard errors are "within noise".
_NOISE_SE = 2.0


@dataclass(frozen=True)
class Verdict:
    """Outcome of one rule: ``holds`` is True, False, or None (not enough data)."""

    claim: str
    holds: object
    explanation: str

    @property
    def mark(self):
        """``yes`` / ``no`` / ``n/a`` for tables."""
        return {True: "yes", False: "no"}.get(self.holds, "n/a")


def _fmt(value):
    return f"{value:,.0f}" if abs(value) >= 100 else f"{value:,.3g}"


class _Rule:
    """A claim about some settings: `check` `_judge`s it, or reports the settings not run;
    a claim that is false on the settings run so far is false whatever the rest scores
    when it holds of every pair or every other setting (`_on`)."""

    def _needs(self):
        return self.labels

    def _on(self, present):
        """The rule restricted to the settings `present`, if its being false on them makes
        it false (it is a conjunction over its settings); else None."""
        return None

    def check(self, stats):
        needs = self._needs()
        absent = [label for label in needs if label not in stats]
        if len(absent) == len(needs):
            return Verdict(self.claim, None, "not run at this budget yet")
        if absent:
            missing = f"not run: {', '.join(absent)}"
            part = self._on(set(needs) - set(absent))
            verdict = part._judge(stats) if part is not None else None
            if verdict is not None and verdict.holds is False:
                return Verdict(self.claim, False, f"{verdict.explanation}; {missing}")
            return Verdict(self.claim, None, missing)
        return self._judge(stats)


def _better(a, b):
    """Whether setting stats `a` scores better than `b` (lower RMSE, higher reward)."""
    return a.score < b.score if a.lower_is_better else a.score > b.score


def _gap_note(a, b):
    """' (within noise)' when the two scores differ by less than `_NOISE_SE` SEs."""
    se = math.hypot(a.score_se, b.score_se)
    if math.isnan(se) or abs(a.score - b.score) >= _NOISE_SE * se:
        return ""
    return " (within noise)"


@dataclass(frozen=True)
class Ranking(_Rule):
    """Every label of group ``i`` scores better than every label of any later group.

    Parameters
    ----------
    groups : tuple of tuple of str
        Best first; labels inside one group are not compared ("~" in the thesis's
        ordering).
    claim : str
    """

    groups: tuple
    claim: str

    def _needs(self):
        return [label for group in self.groups for label in group]

    def _on(self, present):
        groups = [kept for group in self.groups
                  if (kept := tuple(label for label in group if label in present))]
        return replace(self, groups=tuple(groups)) if len(groups) > 1 else None

    def _judge(self, stats):
        labels = self._needs()
        wrong, noisy = [], []
        for i, upper in enumerate(self.groups):
            for lower in self.groups[i + 1:]:
                for a in upper:
                    for b in lower:
                        note = _gap_note(stats[a], stats[b])
                        if not _better(stats[a], stats[b]):
                            wrong.append(f"{b} not worse than {a}{note}")
                        elif note:
                            noisy.append(f"{a} vs {b}")
        order = ", ".join(f"{label} {_fmt(stats[label].score)}" for label in sorted(
            labels, key=lambda label: stats[label].score,
            reverse=not stats[labels[0]].lower_is_better))
        if wrong:
            return Verdict(self.claim, False, f"measured, best first: {order}; out of order: "
                                              + "; ".join(wrong))
        tail = f"; holds but within noise for {', '.join(noisy)}" if noisy else ""
        return Verdict(self.claim, True, f"measured, best first: {order}{tail}")


@dataclass(frozen=True)
class Similar(_Rule):
    """No setting differs from another by more than `_NOISE_SE` combined SEs."""

    labels: tuple
    claim: str

    def _judge(self, stats):
        items = [stats[label] for label in self.labels]
        worst = max(((a, b) for a in items for b in items),
                    key=lambda p: abs(p[0].score - p[1].score) - _NOISE_SE * math.hypot(
                        p[0].score_se, p[1].score_se))
        a, b = worst
        se = math.hypot(a.score_se, b.score_se)
        spread = ", ".join(f"{s.label} {_fmt(s.score)}" for s in items)
        if math.isnan(se):
            return Verdict(self.claim, None, f"measured {spread}; too few values for a noise "
                                             f"estimate")
        holds = abs(a.score - b.score) < _NOISE_SE * se
        return Verdict(self.claim, holds,
                       f"measured {spread}; largest gap {_fmt(abs(a.score - b.score))} vs "
                       f"{_NOISE_SE:g} SE = {_fmt(_NOISE_SE * se)}")


_STABILITY = {"changes": ("instability", "mean |change| between iterations",
                          "needs at least 2 iterations"),
              "spread": ("spread", "sd over runs, mean over iterations",
                         "needs at least 2 runs")}


@dataclass(frozen=True)
class MoreStable(_Rule):
    """`stable` varies less than each of `others`: between consecutive iterations
    (``measure="changes"``), or from run to run (``"spread"``, the width of the band)."""

    stable: str
    others: tuple
    claim: str
    measure: str = "changes"

    def __post_init__(self):
        if self.measure not in _STABILITY:
            raise ValueError(f"measure must be one of {sorted(_STABILITY)}, got "
                             f"{self.measure!r}")

    def _needs(self):
        return (self.stable, *self.others)

    def _judge(self, stats):
        field, what, needs = _STABILITY[self.measure]
        values = {label: getattr(stats[label], field) for label in self._needs()}
        if any(math.isnan(v) for v in values.values()):
            return Verdict(self.claim, None, needs)
        holds = all(values[self.stable] < values[o] for o in self.others)
        listed = ", ".join(f"{label} {_fmt(v)}" for label, v in values.items())
        return Verdict(self.claim, holds, f"{what}: {listed}")


@dataclass(frozen=True)
class Sign(_Rule):
    """The score of `label` is positive (``positive=True``) or negative, by more than
    `_NOISE_SE` standard errors."""

    label: str
    positive: bool
    claim: str

    def _needs(self):
        return (self.label,)

    def _judge(self, stats):
        s = stats[self.label]
        margin = _NOISE_SE * s.score_se
        clear = not math.isnan(margin) and abs(s.score) >= margin
        note = "" if clear else f" (within noise of 0: 2 SE = {_fmt(margin)})"
        return Verdict(self.claim, clear and (s.score > 0) == self.positive,
                       f"measured {self.label} {_fmt(s.score)}{note}")


@dataclass(frozen=True)
class NearRandom(_Rule):
    """`label` scores closer to the random policy than to `reference`."""

    label: str
    reference: str
    claim: str

    def _needs(self):
        return (self.label, self.reference)

    def _judge(self, stats):
        s, ref = stats[self.label], stats[self.reference]
        holds = abs(s.score - s.random_reward) < abs(ref.score - s.score)
        return Verdict(self.claim, holds,
                       f"{self.label} {_fmt(s.score)}, random policy on its runs' seeds "
                       f"{_fmt(s.random_reward)}, "
                       f"{self.reference} {_fmt(ref.score)}")


@dataclass(frozen=True)
class HighestPeak(_Rule):
    """`label` reaches the best single evaluation among `labels` (of any run), or with
    ``of_mean=True`` the highest point of the mean curve over runs."""

    label: str
    labels: tuple
    claim: str
    of_mean: bool = False

    def _judge(self, stats):
        field, what = (("mean_peak", "peak of the mean curve") if self.of_mean
                       else ("best", "best single evaluation"))
        winner = max(self.labels, key=lambda label: getattr(stats[label], field))
        listed = ", ".join(f"{label} {_fmt(getattr(stats[label], field))}"
                           for label in self.labels)
        return Verdict(self.claim, winner == self.label, f"{what}: {listed}")


@dataclass(frozen=True)
class Falls(_Rule):
    """The score improves from the first to the last of `labels` (e.g. RMSE falls as M
    grows)."""

    labels: tuple
    claim: str

    def _judge(self, stats):
        first, last = stats[self.labels[0]], stats[self.labels[-1]]
        listed = ", ".join(f"{label} {_fmt(stats[label].score)}" for label in self.labels)
        return Verdict(self.claim, _better(last, first),
                       f"measured {listed}{_gap_note(first, last)}")


@dataclass(frozen=True)
class Faster(_Rule):
    """`label` takes at most `ratio` times the mean wall time per run of each of `others`."""

    label: str
    others: tuple
    ratio: float
    claim: str

    def _needs(self):
        return (self.label, *self.others)

    def _on(self, present):
        others = tuple(label for label in self.others if label in present)
        return replace(self, others=others) if self.label in present and others else None

    def _judge(self, stats):
        mine = stats[self.label].seconds
        listed = ", ".join(f"{label} {stats[label].seconds / 60:.1f}" for label in self._needs())
        holds = all(mine <= self.ratio * stats[o].seconds for o in self.others)
        return Verdict(self.claim, holds, f"minutes per run: {listed}")


@dataclass(frozen=True)
class AtLeast(_Rule):
    """The best score among `labels` reaches `ratio` times the score of `reference`."""

    labels: tuple
    reference: str
    ratio: float
    claim: str

    def _needs(self):
        return (*self.labels, self.reference)

    def _judge(self, stats):
        best = max(self.labels, key=lambda label: stats[label].score)
        goal = self.ratio * stats[self.reference].score
        return Verdict(self.claim, stats[best].score >= goal,
                       f"best: {best} {_fmt(stats[best].score)}; goal {self.ratio:g} x "
                       f"{self.reference} {_fmt(stats[self.reference].score)} = {_fmt(goal)}")
