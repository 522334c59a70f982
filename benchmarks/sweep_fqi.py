"""Choose FQI's default discount factor: reward curves for several gammas at small budget.

Box FQI (fixed boxes TW=1, K=500, n_min=30, but M=10 trees to keep it cheap) on
ObjectWorld-v0, `--iterations` iterations of `--samples` samples in the thesis's "normal"
regime, several seeds per gamma; the score of a run is the mean evaluation reward (20,000
greedy steps on the reference worlds) over its last 5 iterations.

    python benchmarks/gamma_fqi.py [--gammas 0.5 0.8 0.9 0.95] [--seeds 0 1]
                                   [--iterations 10] [--samples 10000] [--out results]
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np

from fqi import FQI, make_box_forest

ENV = "ObjectWorld-v0"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gammas", type=float, nargs="+", default=[0.5, 0.8, 0.9, 0.95])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--iterations", type=int, default=10)
    parser.add_argument("--samples", type=int, default=10_000)
    parser.add_argument("--trees", type=int, default=10)
    parser.add_argument("--out", default="results")
    args = parser.parse_args()

    runs = []
    print(f"{'gamma':>6} {'seed':>5} {'last-5 mean':>12} {'max':>9} {'seconds':>8}  curve")
    for gamma in args.gammas:
        for seed in args.seeds:
            start = time.perf_counter()
            agent = FQI(make_box_forest(ENV, n_estimators=args.trees), ENV, gamma=gamma,
                        samples_per_iteration=args.samples, seed=seed)
            curve = [r["reward"] for r in agent.learn(args.iterations).history]
            seconds = time.perf_counter() - start
            last = float(np.mean(curve[-5:]))
            runs.append({"gamma": gamma, "seed": seed, "curve": curve, "last5_mean": last,
                         "seconds": seconds})
            print(f"{gamma:>6} {seed:>5} {last:>12,.0f} {max(curve):>9,.0f} {seconds:>8.1f}  "
                  + " ".join(f"{r / 1000:.0f}k" for r in curve), flush=True)
    summary = {g: float(np.mean([r["last5_mean"] for r in runs if r["gamma"] == g]))
               for g in args.gammas}
    print("mean of last-5 means per gamma: "
          + ", ".join(f"{g}: {v:,.0f}" for g, v in summary.items()))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "gamma_fqi.json").write_text(json.dumps(
        {"benchmark": "gamma_fqi", "env": ENV, "args": vars(args), "runs": runs,
         "last5_mean_per_gamma": summary}, indent=2))
    print(f"wrote {out / 'gamma_fqi.json'}")


if __name__ == "__main__":
    main()
