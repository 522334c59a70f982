"""The rules that check the thesis's claims on our numbers."""

import pytest

from benchmarks.reproduce.findings import (AtLeast, Falls, Faster, HighestPeak, MoreStable,
                                           NearRandom, Ranking, Sign, Similar)
from benchmarks.reproduce.stats import SettingStats


# ------------------------------------------------------------------------------ findings
def _stats(label, score, se=1.0, **kwargs):
    return SettingStats(label, "fqi", 1, score, 0.0, se, **kwargs)


def test_ranking_holds_fails_and_flags_noise():
    rule = Ranking((("a", "b"), ("c",)), "a ~ b > c")
    good = {"a": _stats("a", 100), "b": _stats("b", 90), "c": _stats("c", 10)}
    assert rule.check(good).holds is True
    assert rule.check({**good, "c": _stats("c", 95)}).holds is False
    assert "c not worse than b" in rule.check({**good, "c": _stats("c", 95)}).explanation
    assert "within noise" in rule.check({**good, "c": _stats("c", 89)}).explanation
    assert rule.check({"a": good["a"]}).holds is None  # settings not run
    assert rule.check({"a": good["a"]}).explanation == "not run: b, c"
    assert rule.check({}).explanation == "not run at this budget yet"
    # false on the settings run so far: false whatever the missing one scores
    partial = rule.check({"a": good["a"], "c": _stats("c", 120)})
    assert partial.holds is False and partial.explanation.endswith("; not run: b")
    assert "c not worse than a" in partial.explanation
    assert rule.check({"a": good["a"], "c": good["c"]}).holds is None  # could still fail
    assert rule.check({"a": good["a"], "b": _stats("b", 1)}).holds is None  # one group


def test_faster_is_false_once_a_setting_run_so_far_breaks_it():
    rule = Faster("a", ("b", "c"), 0.5, "a needs half the time")
    stats = {label: _stats(label, 0, seconds=seconds)
             for label, seconds in (("a", 10.0), ("b", 30.0), ("c", 15.0))}
    assert rule.check(stats).holds is False
    assert rule.check({k: stats[k] for k in "ab"}).holds is None       # c could be slower
    partial = rule.check({k: stats[k] for k in "ac"})
    assert partial.holds is False and partial.explanation.endswith("; not run: b")
    assert rule.check({"b": stats["b"], "c": stats["c"]}).holds is None  # a not run


def test_ranking_lower_is_better_for_rmse():
    rule = Ranking((("K=300",), ("K=50",)), "K=300 lowest")
    rmse = {"K=300": SettingStats("K=300", "rmse", 1, 1.0, 0, 0.01, lower_is_better=True),
            "K=50": SettingStats("K=50", "rmse", 1, 2.0, 0, 0.01, lower_is_better=True)}
    assert rule.check(rmse).holds is True


def test_other_rules():
    a, b = _stats("a", 100, instability=5, best=200, random_reward=-100), \
        _stats("b", 0, instability=50, best=150, random_reward=-100)
    stats = {"a": a, "b": b}
    assert Similar(("a", "b"), "").check(stats).holds is False
    assert Similar(("a", "b"), "").check({"a": a, "b": _stats("b", 99)}).holds is True
    assert MoreStable("a", ("b",), "").check(stats).holds is True
    assert MoreStable("b", ("a",), "").check(stats).holds is False
    assert Sign("b", True, "").check(stats).holds is False
    assert Sign("a", True, "").check(stats).holds is True
    assert Sign("a", True, "").check({"a": _stats("a", 1.5)}).holds is False  # noise
    assert NearRandom("b", "a", "").check({"a": a, "b": _stats("b", -90, random_reward=-100)}
                                          ).holds is True
    assert HighestPeak("a", ("a", "b"), "").check(stats).holds is True
    peaks = {"a": _stats("a", 0, best=300, mean_peak=100), "b": _stats("b", 0, best=200,
                                                                      mean_peak=150)}
    assert HighestPeak("a", ("a", "b"), "").check(peaks).holds is True
    assert HighestPeak("a", ("a", "b"), "", of_mean=True).check(peaks).holds is False
    spread = {"a": _stats("a", 0, instability=5, spread=50), "b": _stats("b", 0,
                                                                         instability=9, spread=10)}
    assert MoreStable("a", ("b",), "").check(spread).holds is True
    assert MoreStable("a", ("b",), "", measure="spread").check(spread).holds is False
    one_run = {"a": _stats("a", 0), "b": _stats("b", 0)}   # spread is NaN with one run
    assert MoreStable("a", ("b",), "", measure="spread").check(one_run).explanation == \
        "needs at least 2 runs"
    with pytest.raises(ValueError, match="measure must be one of"):
        MoreStable("a", ("b",), "", measure="band")
    assert Falls(("b", "a"), "").check(stats).holds is True
    timed = {"a": _stats("a", 100, seconds=50.0), "b": _stats("b", 0, seconds=100.0)}
    assert Faster("a", ("b",), 0.5, "").check(timed).holds is True
    assert Faster("a", ("b",), 0.4, "").check(timed).holds is False
    assert "a 0.8, b 1.7" in Faster("a", ("b",), 0.5, "").check(timed).explanation
    ref = {**stats, "ref": _stats("ref", 80)}
    assert AtLeast(("a", "b"), "ref", 1.25, "").check(ref).holds is True   # the best of them
    assert AtLeast(("a", "b"), "ref", 1.3, "").check(ref).holds is False
    assert "goal 1.3 x ref 80 = 104" in AtLeast(("a", "b"), "ref", 1.3, "").check(ref).explanation
    assert AtLeast(("a", "b"), "ref", 1.0, "").check({"b": b, "ref": b}).holds is None
