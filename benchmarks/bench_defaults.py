"""The measurements behind the estimators' defaults (docs/boxtrees.md, "Defaults").

Candidate settings of ``BoxExtraTreesRegressor`` (30 trees) on four kinds of data:

- ``coin``: the README's task (objects of type 0 in the unit square at the origin, among sets
  of up to 12 objects of types 0 and 1 in [-3, 3]^2), R^2 on 500 held-out sets, with the
  coordinates in their units, x100 (pixels) and x0.01: a default must not care;
- ``coin noisy``: the same with N(0, 1) noise on the training targets (a Q-function's);
- ``motion``: objects ``[x, y, vx, type]``, the number of type-0 objects in the square of
  half-width 1.5 at the origin that move right (vx > 0): an attribute beyond the position;
- ``presence``, ``count``, ``compare``: the set-size tasks of ``bench_sets.py``, trained on
  4,000 sets of 15-25 objects, accuracy on sets of 20 and of 300 objects.

Prints a table and writes ``bench_defaults.json`` under ``--out``.

    python -m benchmarks.bench_defaults [--out results] [--n-jobs 2]
"""
import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np
from sklearn.metrics import r2_score

from benchmarks.bench_sets import make_data
from boxtrees import BoxExtraTreesRegressor

N_TREES = 30
THESIS = dict(test_type="fixed", test_width=1.0, relative_width=False, refine_tests=False,
              bootstrap=False)
CANDIDATES = {
    "thesis (fixed TW=1 absolute, plain)": THESIS,
    "random, refined, bootstrap": dict(test_type="random", refine_tests=True, bootstrap=True),
    "fixed 0.1 relative, refined, bootstrap": dict(test_type="fixed", test_width=0.1,
                                                   refine_tests=True, bootstrap=True),
    "fixed 0.2 relative, refined, bootstrap": dict(test_type="fixed", test_width=0.2,
                                                   refine_tests=True, bootstrap=True),
    "bounded 0.25 relative, refined, bootstrap": dict(test_type="bounded", test_width=0.25,
                                                      refine_tests=True, bootstrap=True),
    "random, not refined": dict(test_type="random", refine_tests=False, bootstrap=False),
}
SPLITS = (2, 5, 10, 30)     # min_samples_split, on the default's test kind


def coin_task(seed, n):
    """``(sets, targets)`` of the README's coin task."""
    rng = np.random.default_rng(seed)
    sets = [np.column_stack([rng.uniform(-3, 3, (k, 2)), rng.integers(0, 2, k)])
            for k in rng.integers(0, 12, n)]
    return sets, np.array([float(((np.abs(s[:, :2]).max(1) < 1) & (s[:, 2] == 0)).sum())
                           for s in sets])


def motion_task(seed, n):
    """``(sets, targets)`` of the motion task (objects ``[x, y, vx, type]``)."""
    rng = np.random.default_rng(seed)
    sets = [np.column_stack([rng.uniform(-3, 3, (k, 2)), rng.uniform(-1, 1, k),
                             rng.integers(0, 2, k)]) for k in rng.integers(0, 15, n)]
    return sets, np.array([float(((np.abs(s[:, :2]).max(1) < 1.5) & (s[:, 2] > 0)
                                  & (s[:, 3] == 0)).sum()) for s in sets])


def scaled(sets, factor):
    """The sets with their attributes multiplied by ``factor`` (a number, or one per attribute)."""
    return [np.column_stack([s[:, :-1] * factor, s[:, -1]]) for s in sets]


def r2(params, train, test, n_jobs, seed=0):
    forest = BoxExtraTreesRegressor(N_TREES, n_jobs=n_jobs, random_state=seed, **params)
    return r2_score(test[1], forest.fit(*train).predict(test[0]))


def size_accuracy(params, data, n_jobs):
    """Accuracy at 20 and 300 objects of a forest thresholded at 0.5."""
    (train, labels), tests = data
    forest = BoxExtraTreesRegressor(N_TREES, n_jobs=n_jobs, random_state=0, **params)
    forest.fit(train, labels)
    return {n: float(((forest.predict(tests[n][0]) >= 0.5) == (tests[n][1] > 0.5)).mean())
            for n in (20, 300)}


def measure(params, data, n_jobs):
    """Every score of one candidate."""
    start = time.perf_counter()
    coin_train, coin_test = data["coin"]
    row = {f"coin x{f:g}": r2(params, (scaled(coin_train[0], f), coin_train[1]),
                              (scaled(coin_test[0], f), coin_test[1]), n_jobs)
           for f in (1, 100, 0.01)}
    row["coin noisy"] = r2(params, data["coin noisy"], coin_test, n_jobs)
    row["motion"] = r2(params, *data["motion"], n_jobs)
    for task in ("presence", "count", "compare"):
        for n, value in size_accuracy(params, data[task], n_jobs).items():
            row[f"{task} {n}"] = value
    row["seconds"] = time.perf_counter() - start
    return row


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="results")
    parser.add_argument("--n-jobs", type=int, default=2)
    args = parser.parse_args(argv)
    coin_train, coin_test = coin_task(0, 2000), coin_task(1, 500)
    noisy = (coin_train[0], coin_train[1] + np.random.default_rng(2).normal(0, 1, 2000))
    data = {"coin": (coin_train, coin_test), "coin noisy": noisy,
            "motion": (motion_task(3, 3000), motion_task(4, 600)),
            **{task: make_data(task, 4000, 1000, seed=0) for task in ("presence", "count", "compare")}}
    rows = {}
    candidates = {**CANDIDATES, **{f"random, refined, bootstrap, min_samples_split={n}":
                                   dict(CANDIDATES["random, refined, bootstrap"], min_samples_split=n)
                                   for n in SPLITS}}
    for name, params in candidates.items():
        rows[name] = measure(params, data, args.n_jobs)
        print(f"{name:<58}" + " ".join(f"{k} {v:.3f}" for k, v in rows[name].items()), flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "bench_defaults.json").write_text(json.dumps(
        {"config": {"n_trees": N_TREES, "python": platform.python_version()},
         "candidates": {name: {k: v for k, v in params.items()} for name, params in candidates.items()},
         "rows": rows}, indent=1))
    print(f"wrote {out / 'bench_defaults.json'}")


if __name__ == "__main__":
    main()
