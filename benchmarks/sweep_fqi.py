"""Compare FQI settings at small budget: the discount factor, or the data regime.

Box FQI (fixed boxes TW=1, K=500, n_min=30, but M=10 trees to keep it cheap) on
ObjectWorld-v0, `--iterations` iterations of `--samples` samples, several seeds per
setting; the score of a run is the mean evaluation reward (20,000 greedy steps on the
reference worlds) over its last 5 iterations.

    python -m benchmarks.sweep_fqi gamma  [--values 0.5 0.8 0.9 0.95] [--seeds 0 1 2 3]
    python -m benchmarks.sweep_fqi regime [--values normal mixed keep offline] [--seeds 0 1]
        [--iterations 10] [--samples 10000] [--trees 10] [--out results]

The gamma sweep runs the "normal" regime; the regime sweep uses the harness's gamma (0.5).
Each regime is a setting of the experiment registry (``benchmarks/reproduce/registry.py``),
built as ``run_all.py`` builds it, with ``--trees`` trees. Writes ``sweep_fqi_<what>.json``
under ``--out``.
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np

from .reproduce.budgets import BUDGETS
from .reproduce.kinds import KINDS
from .reproduce.kinds._game import make_agent
from .reproduce.registry import REGISTRY

ENV = "ObjectWorld-v0"
# each regime: (experiment, setting) of the registry, and what it changes on top of it
REGIMES = {
    "normal": ("sampling", "normal", {}),
    "mixed": ("sampling", "mixed (every 5)", {}),
    "keep": ("keep_data", "keep data (100k)", {}),
    "offline": ("sampling", "normal", {"resample_every": None}),
}
SWEEPS = {
    "gamma": (["0.5", "0.8", "0.9", "0.95"], lambda value: ("sampling", "normal",
                                                           {"gamma": float(value)})),
    "regime": (list(REGIMES), lambda value: REGIMES[value]),
}


def _params(setting, trees):
    """A registry setting's parameters with its changes and ``trees`` trees."""
    experiment, label, changes = setting
    return {**REGISTRY[experiment].params(label), **changes, "n_estimators": trees}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=list(SWEEPS))
    parser.add_argument("--values", nargs="+", default=None)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--iterations", type=int, default=10)
    parser.add_argument("--samples", type=int, default=10_000)
    parser.add_argument("--trees", type=int, default=10)
    parser.add_argument("--out", default="results")
    args = parser.parse_args()
    defaults, settings = SWEEPS[args.what]
    values = args.values or defaults

    runs = []
    print(f"{args.what:>8} {'seed':>5} {'last-5 mean':>12} {'max':>9} {'seconds':>8}  curve")
    for value in values:
        for seed in args.seeds:
            start = time.perf_counter()
            agent = make_agent(KINDS["fqi"].settings(_params(settings(value), args.trees)),
                               BUDGETS["full"], seed, args.samples)
            curve = [r["reward"] for r in agent.learn(n_iterations=args.iterations).history]
            seconds = time.perf_counter() - start
            last = float(np.mean(curve[-5:]))
            runs.append({args.what: value, "seed": seed, "curve": curve, "last5_mean": last,
                         "seconds": seconds, "env_steps": agent.num_timesteps})
            print(f"{value:>8} {seed:>5} {last:>12,.0f} {max(curve):>9,.0f} {seconds:>8.1f}  "
                  + " ".join(f"{r / 1000:.0f}k" for r in curve), flush=True)
    summary = {}
    for value in values:
        scores = [r["last5_mean"] for r in runs if r[args.what] == value]
        summary[value] = {"mean": float(np.mean(scores)), "sd": float(np.std(scores))}
    print("last-5 mean over seeds: " + ", ".join(
        f"{v}: {s['mean']:,.0f} +- {s['sd']:,.0f}" for v, s in summary.items()))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"sweep_fqi_{args.what}.json"
    path.write_text(json.dumps({"benchmark": "sweep_fqi", "what": args.what, "env": ENV,
                                "args": vars(args), "runs": runs, "summary": summary},
                               indent=2))
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
