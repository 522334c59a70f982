"""Why FQI has no stopping rule: how its iterates move on a fixed data set.

FQI as first formulated runs a set number of fitted-Q backups. A stopping rule would end
them once the Q-function stops changing. This benchmark measures, after each backup of
`fqi.FQI.learn_offline` on one of ``bench_offline``'s CartPole-v1 data sets (the same data,
Extra-Trees and discount), on the data's own states:

- ``q_change``: the RMS change of the Q-values (over states and actions) since the last
  backup, and ``q_rms`` their RMS (what a rule on the change of Q watches);
- ``greedy_flips``: the share of the states whose greedy action changed since the last
  backup (what the policy does);
- ``mean_return``: the greedy policy's mean return on the 20 held-out seeds, scored as
  ``bench_offline`` scores its runs (so that a run of its length ends on its figure).

A rule on the change of Q can stop at a good iteration only if the policy has settled by
the time that change is small. Run::

    python -m benchmarks.bench_stopping

It makes the data sets under ``--data`` as ``bench_offline`` does (or reuses them), writes
each finished run under ``--out/runs/`` (a rerun reuses those made from the same data), then
``bench_stopping.json`` and ``bench_stopping.png`` under ``--out``. ``--quick`` runs a tiny
size.
"""
import argparse
import json
import platform
import sys
from pathlib import Path

import numpy as np

from benchmarks import bench_offline

QUICK = {"transitions": 1_000, "iterations": 3, "seeds": [0], "datasets": ["random"],
         "medium_training_steps": bench_offline.QUICK["medium_training_steps"]}
# returns averaged from this iteration on, in the table: past the first backups' growth
SETTLED_FROM = 20


def trace_fqi(data, method, seed, n_iterations):
    """`FQI.learn_offline` on `data`, measured after every backup: one row per iteration."""
    states = data["observations"]
    # bench_offline's agent and scoring: a run as long as one of its runs ends on its figure
    agent = bench_offline.make_agent(method, seed)
    rows, last, measuring = [], [], np.zeros(2)  # measuring: its wall and CPU seconds

    def measure(locals_, globals_):
        _, seconds, cpu_seconds = bench_offline.timed(add_row, locals_["record"]["iteration"])
        measuring[:] += seconds, cpu_seconds

    def add_row(iteration):
        q = agent.q_values(states)
        row = {"iteration": iteration, "mean_return": bench_offline.held_out_return(agent),
               "q_rms": float(np.sqrt(np.mean(q ** 2))), "q_change": None, "greedy_flips": None}
        if last:
            row["q_change"] = float(np.sqrt(np.mean((q - last[0]) ** 2)))
            row["greedy_flips"] = float(np.mean(q.argmax(axis=1) != last[0].argmax(axis=1)))
        rows.append(row)
        last[:] = [q]

    _, seconds, cpu_seconds = bench_offline.timed(agent.learn_offline, data,
                                                  n_iterations=n_iterations, callback=measure)
    return {"budget": {"iterations": n_iterations}, "iterations": rows,
            "train_seconds": seconds - measuring[0],
            "train_cpu_seconds": cpu_seconds - measuring[1],
            "mean_return": rows[-1]["mean_return"], "settings": repr(agent.regressor)}


def summarise(runs):
    """Per run: the returns' range and mean from `SETTLED_FROM` on, the last Q change and
    the greedy flips over the same iterations."""
    summary = []
    for run in runs:
        late = [row for row in run["iterations"] if row["iteration"] >= SETTLED_FROM]
        if not late:
            late = run["iterations"][-1:]
        returns = [row["mean_return"] for row in late]
        flips = [row["greedy_flips"] for row in late if row["greedy_flips"] is not None]
        last = run["iterations"][-1]
        summary.append({
            "dataset": run["dataset"], "method": run["method"], "seed": run["seed"],
            "from_iteration": late[0]["iteration"], "return_min": float(min(returns)),
            "return_mean": float(np.mean(returns)), "return_max": float(max(returns)),
            "flips_min": float(min(flips)) if flips else None,
            "flips_max": float(max(flips)) if flips else None,
            "last_relative_change": (None if last["q_change"] is None
                                     else last["q_change"] / last["q_rms"])})
    return summary


def markdown(summary):
    """The summary as a markdown table, one row per run."""
    def share(value, digits=0):
        return "-" if value is None else f"{100 * value:.{digits}f}%"

    lines = ["| data | method | seed | iterations | held-out return: min / mean / max | "
             "greedy actions changed per backup | last RMS change of Q / RMS of Q |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for s in summary:
        lines.append(
            f"| {s['dataset']} | {s['method']} | {s['seed']} | from {s['from_iteration']} | "
            f"{s['return_min']:.0f} / {s['return_mean']:.0f} / {s['return_max']:.0f} | "
            f"{share(s['flips_min'])} to {share(s['flips_max'])} | "
            f"{share(s['last_relative_change'], 1)} |")
    return "\n".join(lines)


def plot(runs, path):
    """Per iteration: the relative change of Q, the greedy actions changed, the return."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    panels = (("q_change", "RMS change of Q / RMS of Q", True),
              ("greedy_flips", "states whose greedy action changed", False),
              ("mean_return", "mean return, 20 held-out seeds", False))
    for run in runs:
        rows = run["iterations"]
        label = f"{run['dataset']}, {run['method']}, seed {run['seed']}"
        for ax, (key, _, relative) in zip(axes, panels):
            points = [(row["iteration"], row[key] / row["q_rms"] if relative else row[key])
                      for row in rows if row[key] is not None]
            if points:
                ax.plot(*zip(*points), marker=".", label=label)
    for ax, (_, ylabel, relative) in zip(axes, panels):
        ax.set_xlabel("iteration (backups)")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        if relative:
            ax.set_yscale("log")
    axes[2].legend(fontsize=8)
    fig.suptitle(f"Offline {bench_offline.ENV_ID}: FQI's iterates, backup after backup")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", nargs="+", default=["medium"],
                        choices=bench_offline.DATASETS)
    parser.add_argument("--methods", nargs="+", default=list(bench_offline.FQI_METHODS),
                        choices=list(bench_offline.FQI_METHODS))
    parser.add_argument("--seeds", nargs="+", type=int, default=[0])
    parser.add_argument("--transitions", type=int, default=50_000,
                        help="transitions in each data set (bench_offline's)")
    parser.add_argument("--iterations", type=int, default=60, help="FQI's backups")
    parser.add_argument("--quick", action="store_true",
                        help="tiny sizes: " + ", ".join(f"{k} {v}" for k, v in QUICK.items()))
    parser.add_argument("--out", type=Path, default=Path("results/stopping"))
    parser.add_argument("--data", type=Path, default=Path("results/offline-data"),
                        help="folder of bench_offline's data sets (made there if missing)")
    # two iterations at least: the first change of Q comes with the second
    return bench_offline.sized_args(parser, parser.parse_args(argv), QUICK,
                                    {"transitions": 1, "iterations": 2})


def main(argv=None):
    args = parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    bench_offline.make_datasets(args.data, args.transitions, args.medium_training_steps)
    paths = bench_offline.run_part(
        args, args.methods, args.iterations,
        lambda data, method, seed, key: trace_fqi(data, method, seed, args.iterations),
        datasets=args.datasets)
    runs = [json.loads(path.read_text()) for path in paths]
    summary = summarise(runs)
    table = markdown(summary)
    print(table)
    report = {"benchmark": "bench_stopping", "env": bench_offline.ENV_ID,
              "gamma": bench_offline.GAMMA, "data": bench_offline.read_info(args.data),
              "args": bench_offline.jsonable(vars(args)),
              "python": platform.python_version(), "machine": platform.machine(),
              "command": " ".join(["python -m benchmarks.bench_stopping", *sys.argv[1:]]),
              "runs": runs, "summary": summary, "markdown": table}
    (args.out / "bench_stopping.json").write_text(json.dumps(report, indent=2))
    plot(runs, args.out / "bench_stopping.png")
    print(f"wrote {args.out / 'bench_stopping.json'} and {args.out / 'bench_stopping.png'}")


if __name__ == "__main__":
    main()
