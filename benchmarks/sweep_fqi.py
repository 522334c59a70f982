"""Compare FQI settings at small budget: the discount factor, or the data regime.

Box FQI (fixed boxes TW=1, K=500, n_min=30, but M=10 trees to keep it cheap) on
ObjectWorld-v0, `--iterations` iterations of `--samples` samples, several seeds per
setting; the score of a run is the mean evaluation reward (20,000 greedy steps on the
reference worlds) over its last 5 iterations.

    python benchmarks/sweep_fqi.py gamma  [--values 0.5 0.8 0.9 0.95] [--seeds 0 1 2 3]
    python benchmarks/sweep_fqi.py regime [--values normal mixed keep offline] [--seeds 0 1]
        [--iterations 10] [--samples 10000] [--trees 10] [--out results]

The gamma sweep runs the "normal" regime; the regime sweep uses FQI's default gamma.
Writes ``sweep_fqi_<what>.json`` under ``--out``.
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np

import envs
from fqi import FQI, make_box_forest

ENV = "ObjectWorld-v0"
REGIMES = {
    "normal": {"resample_every": 1},
    "mixed": {"resample_every": 5},
    "keep": {"keep_data": True, "max_samples": 100_000},
    "offline": {"resample_every": None},
}
SWEEPS = {
    "gamma": (["0.5", "0.8", "0.9", "0.95"], lambda value: {"gamma": float(value)}),
    "regime": (list(REGIMES), lambda value: REGIMES[value]),
}


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
            agent = FQI(make_box_forest(ENV, n_estimators=args.trees), ENV,
                        samples_per_iteration=args.samples, n_envs=400,
                        eval_seeds=envs.reference_worlds(400), seed=seed, **settings(value))
            curve = [r["reward"] for r in agent.learn(args.iterations).history]
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
