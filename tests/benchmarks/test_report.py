"""Summaries, figures and REPORT.md."""
import json
import re
import shutil
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.colors import to_rgb

import envs
from benchmarks.reproduce import BUDGETS, EXPERIMENTS, REGISTRY, plots, runner
from benchmarks.reproduce.cache import load_unit, save_unit, unit_path
from benchmarks.reproduce.cli import main
from benchmarks.reproduce.kinds import KINDS
from benchmarks.reproduce.registry import resolve
from benchmarks.reproduce.report import write_outputs
from benchmarks.reproduce.runner import gather, plan
from envs._render import _STYLE

from harness import TINY, make_unit


def test_summarise_fqi_runs():
    runs = [{"rewards": [0.0, 10.0, 20.0], "random_reward": -5.0, "seconds": 2.0},
            {"rewards": [0.0, 30.0, 40.0], "random_reward": -7.0, "seconds": 4.0}]
    s = KINDS["fqi"].summarise("x", runs)
    assert s.score == pytest.approx((10 + 70 / 3) / 2)  # mean of all 3 iterations (< 5)
    assert s.curve_mean.tolist() == [-6.0, 0.0, 20.0, 30.0]
    assert s.instability == pytest.approx(15.0) and s.best == 40.0 and s.seconds == 3.0
    assert s.mean_peak == 30.0 and s.spread == pytest.approx(20 / 3)  # sd 0, 10, 10
    assert np.isnan(KINDS["fqi"].summarise("x", runs[:1]).spread)
    rmse = [{"fold_rmse": [1.0, 3.0], "seconds": 1.0}, {"fold_rmse": [4.0, 6.0], "seconds": 1.0}]
    assert KINDS["rmse"].summarise("x", rmse[:1]).score_se == pytest.approx(1.0)
    assert KINDS["rmse"].summarise("x", rmse).score_se == pytest.approx(
        np.std([2, 5], ddof=1) / np.sqrt(2))


# ------------------------------------------------------------------------------ report
@pytest.mark.parametrize("offset, zero_line", [(-150.0, False), (0.0, True)])
def test_versus_steps_zero_line_only_in_range_and_legend_below(offset, zero_line):
    """All-negative returns (MountainCar's) are not stretched up to a zero line, and the
    legend sits under the axes, off the curves."""
    steps = np.array([5_000, 10_000, 15_000])
    curves = {"a": (steps, offset + np.array([-50.0, 20.0, 40.0]), np.full(3, 5.0)),
              "b": (steps, offset + np.array([-40.0, -10.0, 30.0]), np.full(3, 5.0))}
    stats = {label: SimpleNamespace(score=curve[1][-1], seconds=60.0, n_runs=2)
             for label, curve in curves.items()}
    fig = plots.versus_steps(REGISTRY["control_mountaincar"], stats, curves, TINY,
                             threshold=offset - 20.0)
    ax = fig.axes[0]
    zero_lines = [line for line in ax.get_lines() if tuple(line.get_ydata()) == (0, 0)]
    assert len(zero_lines) == zero_line
    low, high = ax.get_ylim()
    assert (low < 0 < high) == zero_line
    fig.canvas.draw()
    legend_box = ax.get_legend().get_window_extent()
    assert legend_box.y1 < ax.get_window_extent().y0  # wholly below the axes
    plots.plt.close(fig)


@pytest.mark.parametrize("n_settings", [5, 6, 12])
def test_crowded_reward_curves_get_a_score_panel_best_on_top(n_settings):
    """Beyond five settings the curves' plateaus overlap: a panel beside them shows each
    score +-1 sd in its curve's colour, one row per setting, the best on the top row; no
    two curves share a colour."""
    scores = [3.0, 9.0, 1.0, 7.0, 5.0, 8.0, 2.0, 4.0, 6.0, 10.0, 12.0, 11.0][:n_settings]
    stats = {f"s{i}": SimpleNamespace(curve_mean=np.array([-9.0, score / 2, score]),
                                      curve_sd=np.ones(3), score=score, score_sd=0.5,
                                      n_runs=1 + i % 2)
             for i, score in enumerate(scores)}
    fig = plots.reward_curves(REGISTRY["fqi_TW"], stats, TINY)
    assert len(fig.axes) == 1 + (n_settings > 5)
    if n_settings > 5:
        curves, panel = fig.axes
        colours = {line.get_label().split(" (")[0]: line.get_color()
                   for line in curves.get_lines() if line.get_label().startswith("s")}
        assert len({to_rgb(colour) for colour in colours.values()}) == n_settings
        labels = [tick.get_text() for tick in panel.get_yticklabels()]
        order = sorted(stats, key=lambda label: stats[label].score)
        assert labels == [f"{label} ({stats[label].n_runs} run"
                          f"{'s' * (stats[label].n_runs > 1)})" for label in order]
        # one errorbar per row, bottom to top
        for row, (container, label) in enumerate(zip(panel.containers, order, strict=True)):
            (x,), (y,) = container.lines[0].get_data()
            assert (x, y) == (stats[label].score, row)
            assert to_rgb(container.lines[0].get_color()) == to_rgb(colours[label])
            assert container.has_xerr == (stats[label].n_runs > 1)
    plots.plt.close(fig)


def test_report_shows_thesis_numbers_beside_ours_and_computed_verdicts(tmp_path):
    experiment = REGISTRY["sampling"]
    budget = replace(TINY, iterations=3)
    for label, curves in {"normal": ([90e3, 10e3, 50e3], [80e3, 20e3, 50e3]),
                          "mixed (every 5)": ([50e3, 60e3, 70e3], [55e3, 65e3, 75e3])}.items():
        for seed, curve in enumerate(curves):
            save_unit(make_unit(tmp_path, "sampling", label, seed, budget, budget.samples),
                      {"rewards": list(curve), "random_reward": -95e3, "seconds": 60.0})
    report = write_outputs([experiment], budget, tmp_path, seeds=[0, 1])
    text = report.read_text()
    section = text[text.index('<a id="sampling">'):]
    assert "| mixed (every 5) | 2 | 62,500 +- 3,536 |" in section  # mean of the 3 it.
    assert "more stable, higher mean" in section  # the thesis's statement beside ours
    assert "- mixed has the higher mean: **yes**" in section
    assert "- mixed is more stable: **yes**" in section
    assert "| 3.9 | [sampling](#sampling) | 4/4 | mixed has the higher mean | yes |" in text
    assert (tmp_path / "fig3.9_sampling.png").exists()
    assert "Not run at this budget yet." in text  # the other experiments
    assert ("| 3.6 | [representations](#representations) | 0/10 | fixed ~ bounded > random box "
            "> grid > classic | n/a | not run at this budget yet |") in text


def test_figures_use_the_renderers_colours_and_envs_names():
    for kind, (colour, _, _) in _STYLE.items():  # a test box: the colour of what it tests
        assert to_rgb(plots._TYPE_COLOURS[kind]) == pytest.approx(np.array(colour) / 255)
    assert len(plots.TYPE_NAMES) == len(envs.TYPE_NAMES)
    assert plots.TYPE_NAMES[envs.MONEY_MARKER] == "money marker"
    assert plots.ACTION_NAMES == ("up", "right", "down", "left", "swipe up", "swipe right",
                                  "swipe down", "swipe left")


def test_budget_overrides_reach_every_setting_of_their_experiment_and_its_cache(tmp_path):
    budget = replace(TINY, overrides={"treasure": {"n_estimators": 1}})
    units = plan([REGISTRY["treasure"], REGISTRY["sampling"]], budget, tmp_path)
    trees = {(u.experiment, u.label): u.params["n_estimators"] for u in units}
    assert {v for (e, _), v in trees.items() if e == "treasure"} == {1}
    assert {v for (e, _), v in trees.items() if e == "sampling"} == {30}
    # a run cached without the override is not reused with it
    unit = next(u for u in units if u.experiment == "treasure")
    save_unit(replace(unit, params=REGISTRY["treasure"].params(unit.label)),
              {"rewards": [0.0], "seconds": 1.0})
    assert load_unit(unit) is None
    report = write_outputs([REGISTRY["treasure"]], budget, tmp_path).read_text()
    assert "`treasure` runs with n_estimators=1 (every setting alike)" in report


def test_report_marks_missing_runs_as_partial(tiny_run, tmp_path):
    out = tmp_path / "copy"  # the session's run stays as it is for the other tests
    shutil.copytree(tiny_run[0] / "runs", out / "runs")
    report = main(["--budget", "tiny", "--out", str(out), "--seeds", "2",
                   "--only", "sampling", "--report-only", "--no-progress"])
    text = report.read_text()
    assert "Partial: 2 of 4 runs finished" in text  # seed 1 never ran
    assert "This invocation ran" not in text  # a report-only call runs nothing


def test_baselines_share_their_owners_runs_and_read_against_the_ceiling(tiny_run):
    out, _ = tiny_run
    baselines = REGISTRY["baselines"]
    owners = {resolve(baselines, label)[0].name for label in baselines.settings}
    assert owners == {"representations", "keep_data", "keep_data_frame", "baselines",
                      "ceiling"}
    # one run of each reference policy, the budget's seeds for the rest
    assert len(runner.seeds_for(REGISTRY["ceiling"], BUDGETS["full"])) == 1
    stats, runs = gather(baselines, TINY, out)
    assert set(stats) == set(baselines.settings)
    section = (out / "REPORT.md").read_text().split('<a id="baselines"></a>')[1]
    ceiling = stats["look-ahead planner"].score
    for label, s in stats.items():
        assert f"| {label} | {s.n_runs} | {s.score:,.0f} +- {s.score_sd:,.0f} | " \
               f"{s.score / ceiling:.0%} |" in section
    fqi_run = runs["box FQI, fixed TW=1"][0]
    assert fqi_run["result"]["rewards"] == json.loads(unit_path(
        out, TINY, "representations", "fixed TW=1", 0).read_text())["result"]["rewards"]
    assert (out / "extra_baselines.png").stat().st_size > 0


def test_each_ablation_is_reported_under_why_it_differs_in_the_sections_it_explains(tiny_run):
    out, _ = tiny_run
    text = (out / "REPORT.md").read_text()
    sections = dict(re.findall(r'<a id="(\w+)"></a>\n(.*?)(?=<a id=|\Z)', text, re.S))
    summary = json.loads((out / "summary.json").read_text())["experiments"]
    for ablation in (e for e in EXPERIMENTS if e.explains):
        for name in ablation.explains:
            why = sections[name].split("### Why it differs", 1)[1]
            assert f"([{ablation.name}](#{ablation.name})," in why
            assert ablation.hypothesis in why
            claims = [rule.claim for rule in REGISTRY[name].findings]
            for finding in summary[ablation.name]["findings"]:   # the computed verdicts
                mark = {True: "yes", False: "no"}.get(finding["holds"], "n/a")
                line = f"- {finding['claim']}: **{mark}**. {finding['explanation']}"
                # listed where they re-check one of the section's own claims, only there
                related = any(finding["claim"] == c or finding["claim"].endswith(f": {c}")
                              for c in claims)
                assert (line in why) == related, (name, line)
            assert re.search(r"Shown( so far)?: (recovered in this ablation|undetermined|not "
                             r"recovered)",
                             why)
    rep = sections["representations"].split("### Why it differs", 1)[1]
    assert "grid + ridge reaches a positive reward: **" in rep and "10 > 15 > 21" not in rep
