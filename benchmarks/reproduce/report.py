"""Outputs of a reproduction: figures, raw numbers (CSV, JSON) and REPORT.md."""
import csv
import json
import time
from pathlib import Path

from . import plots
from .budgets import EVAL_REFERENCE_STEPS
from .kinds import KINDS
from .registry import EXPERIMENTS, REGISTRY, resolve
from .runner import gather, setting_units
from .stats import last_window

__all__ = ["write_outputs", "figure_name"]


def figure_name(experiment):
    """File name of an experiment's figure, e.g. ``fig3.6_representations.png``."""
    prefix = "extra" if experiment.figure == "extra" else f"fig{experiment.figure}"
    return f"{prefix}_{experiment.name}.png"


def write_outputs(experiments, budget, out, seeds=None, elapsed=None, n_run=None):
    """Write every figure with finished runs, the raw CSVs, ``summary.json`` and
    ``REPORT.md`` under `out`, and print the summary table.

    The report covers every registry experiment (not only `experiments`), so that a full
    reproduction spread over several invocations reports all that is finished so far.

    Parameters
    ----------
    experiments : sequence of Experiment
        Those run by this invocation (named in the report's header).
    budget : Budget
    out : path-like
    seeds : sequence of int, default=None
        As given to the runner (None: the budget's).
    elapsed : float, default=None
        Seconds this invocation spent running.
    n_run : int, default=None
        Units this invocation ran (the rest were cached).

    Returns
    -------
    report : pathlib.Path
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    sections, summary, rows, measured = [], {}, [], {}
    lent = {(owner.name, owner_label) for other in EXPERIMENTS if not other.on_demand
            for owner, owner_label in (resolve(other, label) for label in other.settings)}
    for experiment in EXPERIMENTS:
        stats, runs = gather(experiment, budget, out, seeds)
        if experiment.on_demand and all("same_as" in experiment.settings[label]
                                        or (experiment.name, label) in lent for label in stats):
            # not run yet: only settings shared with (``same_as``) others have runs, or its
            # own settings that a default experiment shares (and so ran)
            continue
        planned = sum(len(setting_units(experiment, label, budget, out, seeds))
                      for label in experiment.settings)
        done = sum(s.n_runs for s in stats.values())
        measured[experiment.name] = (stats, runs, [rule.check(stats) for rule in
                                                   experiment.findings], done, planned)
    for name, (stats, runs, verdicts, done, planned) in measured.items():
        experiment = REGISTRY[name]
        if stats:
            plots.save(_figure(experiment, stats, runs, budget), out / figure_name(experiment))
            _write_csv(experiment, runs, out / f"{experiment.name}.csv")
        summary[experiment.name] = _summary_entry(experiment, stats, verdicts, done, planned)
        ablations = [(REGISTRY[other], measured[other]) for other in measured
                     if name in REGISTRY[other].explains]
        sections.append(_section(experiment, stats, runs, verdicts, done, planned)
                        + _why_it_differs(experiment, ablations))
        rows.extend((experiment, v, done, planned) for v in verdicts)
        if not experiment.findings:
            rows.append((experiment, None, done, planned))
    (out / "summary.json").write_text(json.dumps(
        {"budget": budget.name, "experiments": summary}, indent=1, allow_nan=True))
    report = out / "REPORT.md"
    report.write_text(_header(experiments, budget, seeds, elapsed, n_run)
                      + _summary_table(rows) + "\n".join(sections))
    print(_console_summary(rows))
    return report


def _figure(experiment, stats, runs, budget):
    """The experiment's figure: its kind's, or reward against environment steps of every
    setting (``plot="steps"``)."""
    if experiment.plot == "steps":
        curves = {label: KINDS[s.kind].curve(s, runs[label]) for label, s in stats.items()}
        return plots.versus_steps(experiment, stats, curves, budget)
    return KINDS[experiment.kind].plot(experiment, stats, runs, budget)


def _header(experiments, budget, seeds, elapsed, n_run):
    ran = ", ".join(e.name for e in experiments)
    timing = "" if elapsed is None else (f" This invocation ran {n_run} run(s) in "
                                         f"{elapsed / 60:.1f} min ({ran}).")
    dqn_steps = budget.dqn_steps or budget.iterations * budget.samples
    rescaled = ("" if budget.eval_steps == EVAL_REFERENCE_STEPS
                else " (fewer than the thesis: rewards rescaled)")
    return (
        f"# Reproducing the thesis: report ({budget.name} budget)\n\n"
        f"Written by `python -m benchmarks.run_all` on {time.strftime('%Y-%m-%d %H:%M')}."
        f"{timing} Finished runs are cached under `runs/{budget.name}/`; re-running the "
        f"command resumes.\n\n"
        f"Budget `{budget.name}`: {budget.seeds} run(s) per setting (fewer where an "
        f"experiment says)"
        f"{'' if seeds is None else f' (this invocation: seeds {list(seeds)})'}, "
        f"{budget.iterations} iterations x {budget.samples:,} samples (x2 for the sword game), "
        f"greedy evaluation over {budget.eval_steps:,} steps on the fixed reference worlds"
        f"{rescaled}; every reward is per {EVAL_REFERENCE_STEPS:,} steps as in the thesis. "
        f"RMSE: {budget.rmse_folds}-fold CV on {budget.rmse_samples:,} random-policy samples. "
        f"DQN: {dqn_steps:,} env steps."
        + ("" if budget.max_trees is None else
           f" Forests capped at {budget.max_trees} trees, {budget.max_tests} tests.")
        + "".join(f" At this budget `{name}` runs with "
                  + ", ".join(f"{key}={value}" for key, value in params.items())
                  + " (every setting alike)." for name, params in budget.overrides.items())
        + f"\n\nScores: FQI = mean reward of the last {last_window(budget)} iterations (mean "
        f"over runs, +- sd over runs); 'within noise' = the gap is under 2 standard errors of "
        f"the averaged rewards. Verdicts are computed from these numbers by the rules in "
        f"`benchmarks/reproduce/registry.py`. Times are each run's wall time as it ran, "
        f"other runs perhaps sharing the cores (`--jobs 2`, as `make bench`).\n\n")


def _summary_table(rows):
    lines = ["## Summary", "", "| figure | experiment | runs | thesis finding | reproduces? "
             "| measured |", "| --- | --- | --- | --- | --- | --- |"]
    for experiment, verdict, done, planned in rows:
        claim, mark, text = ("(no claim: extra)", "-", "") if verdict is None else \
            (verdict.claim, verdict.mark, verdict.explanation)
        lines.append(f"| {experiment.figure} | [{experiment.name}](#{experiment.name}) | "
                     f"{done}/{planned} | {claim} | {mark} | {text} |")
    return "\n".join(lines) + "\n\n"


def _console_summary(rows):
    lines = [f"{'figure':<7} {'experiment':<16} {'runs':>7}  {'holds':<5} finding"]
    for experiment, verdict, done, planned in rows:
        mark, claim = ("-", "(extra)") if verdict is None else (verdict.mark, verdict.claim)
        lines.append(f"{experiment.figure:<7} {experiment.name:<16} {done:>3}/{planned:<3}  "
                     f"{mark:<5} {claim}")
    return "\n".join(lines)


def _section(experiment, stats, runs, verdicts, done, planned):
    figure = "" if experiment.figure == "extra" else f" (thesis Fig. {experiment.figure})"
    lines = [f"<a id=\"{experiment.name}\"></a>", f"## {experiment.title}{figure}", ""]
    if not stats:
        return "\n".join(lines + ["Not run at this budget yet.", ""])
    status = "" if done == planned else f" **Partial: {done} of {planned} runs finished.**"
    lines += [f"`{experiment.name}`, {done}/{planned} runs.{status}", "",
              f"![{experiment.name}]({figure_name(experiment)})", ""]
    lines += KINDS[experiment.kind].table(experiment, stats, runs)
    if verdicts:
        whose = "Claims" if experiment.figure == "extra" else "Thesis findings"
        lines += ["", f"{whose}, checked on these numbers:", ""]
        lines += _verdict_lines(verdicts)
    if experiment.notes:
        lines += ["", f"Notes: {experiment.notes}"]
    return "\n".join(lines + [""])


def _why_it_differs(experiment, ablations):
    """The "Why it differs" part of a section: each ablation's hypothesis, and the claims of
    `experiment` it re-checks (as they are, or prefixed by the ablation's setting)."""
    if not ablations:
        return ""
    claims = [rule.claim for rule in experiment.findings]
    lines = ["", "### Why it differs", ""]
    for ablation, (stats, _, verdicts, done, planned) in ablations:
        partial = "" if done == planned else f" **Partial: {done} of {planned} runs.**"
        lines += [f"**Hypothesis** ([{ablation.name}](#{ablation.name}), {done}/{planned} "
                  f"runs):{partial} {ablation.hypothesis}", ""]
        if not stats:
            lines += ["Not run at this budget yet.", ""]
            continue
        related = [v for v in verdicts
                   if any(v.claim == c or v.claim.endswith(f": {c}") for c in claims)]
        lines += _verdict_lines(related)
        recovered = [v.claim for v in related if v.holds]
        undecided = [v.claim for v in related if v.holds is None]
        if recovered:
            shown = f"recovered in this ablation: {'; '.join(recovered)}."
        elif undecided:
            shown = f"undetermined: not enough runs for {'; '.join(undecided)}."
        else:
            shown = "not recovered in this ablation."
        lines += ["", f"Shown{' so far' if partial else ''}: {shown}", ""]
    return "\n".join(lines)


def _verdict_lines(verdicts):
    return [f"- {v.claim}: **{v.mark}**. {v.explanation}" for v in verdicts]


def _summary_entry(experiment, stats, verdicts, done, planned):
    return {
        "figure": experiment.figure, "title": experiment.title, "runs": done,
        "planned": planned,
        "settings": {label: {"n_runs": s.n_runs, "score": s.score, "score_sd": s.score_sd,
                             "score_se": s.score_se, "best": s.best,
                             "instability": s.instability, "mean_peak": s.mean_peak,
                             "spread": s.spread, "random_reward": s.random_reward,
                             "seconds": s.seconds, "thesis": experiment.thesis.get(label)}
                     for label, s in stats.items()},
        "findings": [{"claim": v.claim, "holds": v.holds, "explanation": v.explanation}
                     for v in verdicts],
    }


def _write_csv(experiment, runs, path):
    """Raw per-run numbers: one row per value of its kind (an FQI run's iterations, an
    RMSE study's folds, a baseline's final reward)."""
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["experiment", "setting", "seed", "step", "value", "seconds"])
        for label, records in runs.items():
            for record in records:
                result, seed = record["result"], record["seed"]
                values = KINDS[record["params"]["kind"]].values(result)
                for step, value in enumerate(values):
                    writer.writerow([experiment.name, label, seed, step, value,
                                     round(result["seconds"], 2)])
