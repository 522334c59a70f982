"""Objects with d attributes: what the column groups buy, and what d costs.

- ``groups``: objects ``[x, y, w, h, dx, dy, type]`` (an object-centric Atari frame: position,
  size, motion) and ``[x, y, vx, type]``; the target counts the type-0 objects in the square
  of half-width 1.5 at the origin that move right (dx > 0, vx > 0). R^2 on held-out sets of
  forests (30 trees, the defaults) whose boxes span the default column groups, and others.
- ``cost``: fit CPU seconds per tree against d at a fixed number of objects (20,000 sets of
  16 objects on average), the default groups ``(0, 1), (0, 1, 2), ..., (0, 1, d - 1)``, one
  thread, both for the defaults and the thesis's fixed boxes.

Prints two tables and writes ``bench_attributes.json`` under ``--out``.

    python -m benchmarks.bench_attributes [--out results] [--quick]
"""
import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np
from sklearn.metrics import r2_score

from boxtrees import BoxExtraTreesRegressor

GROUPS = {
    6: {"default: (0, 1), (0, 1, c) for c >= 2": None,
        "(0, 1) and every other column alone": [(0, 1), (2,), (3,), (4,), (5,)],
        "one box over all six": [tuple(range(6))],
        "positions (0, 1) only": [(0, 1)]},
    3: {"default: (0, 1), (0, 1, 2)": None,
        "(0, 1) and (2,)": [(0, 1), (2,)],
        "positions (0, 1) only": [(0, 1)]},
}
DIMENSIONS = (1, 2, 3, 4, 6, 8)


def moving_sets(rng, n, d):
    """Sets of up to 14 objects: position in [-3, 3]^2, then d - 2 attributes of which the
    first after the sizes (column 4 for d = 6, column 2 for d = 3) is the motion."""
    sets = []
    for k in rng.integers(0, 15, n):
        columns = [rng.uniform(-3, 3, (k, 2))]
        if d == 6:
            columns.append(rng.uniform(0.1, 1, (k, 2)))      # sizes
            columns.append(rng.uniform(-1, 1, (k, 2)))       # motion
        else:
            columns.append(rng.uniform(-1, 1, (k, d - 2)))
        sets.append(np.column_stack([*columns, rng.integers(0, 2, k)]))
    return sets


def moving_right(sets, motion):
    return np.array([float(((np.abs(s[:, :2]).max(1) < 1.5) & (s[:, motion] > 0)
                            & (s[:, -1] == 0)).sum()) for s in sets])


def groups_table(n_train, n_trees):
    rows = []
    for d, motion in ((6, 4), (3, 2)):
        rng = np.random.default_rng(d)
        train, test = moving_sets(rng, n_train, d), moving_sets(rng, 1000, d)
        y, y_test = moving_right(train, motion), moving_right(test, motion)
        for name, groups in GROUPS[d].items():
            start = time.perf_counter()
            forest = BoxExtraTreesRegressor(n_trees, column_groups=groups, random_state=0,
                                            n_jobs=2).fit(train, y)
            rows.append({"d": d, "groups": name, "r2": r2_score(y_test, forest.predict(test)),
                         "fit_s": time.perf_counter() - start})
            print(f"d={d} {name:<44} R^2 {rows[-1]['r2']:.3f}  fit {rows[-1]['fit_s']:.2f} s",
                  flush=True)
    return rows


def cost_table(n_sets):
    rows = []
    for d in DIMENSIONS:
        rng = np.random.default_rng(0)
        sets = [np.column_stack([rng.uniform(-5, 5, (k, d)), rng.integers(0, 4, k)])
                for k in rng.poisson(16, n_sets)]
        y = np.array([float((s[:, 0] > 0).sum()) for s in sets]) + rng.normal(0, 0.1, n_sets)
        row = {"d": d}
        for name, params in (("defaults", {}),
                             ("thesis fixed TW=1", dict(test_type="fixed", test_width=1.0,
                                                        relative_width=False, refine_tests=False,
                                                        bootstrap=False))):
            forest = BoxExtraTreesRegressor(2, n_jobs=1, random_state=0, **params)
            start = time.process_time()
            forest.fit(sets, y)
            row[name] = (time.process_time() - start) / 2
        rows.append(row)
        print(f"d={d}  fit CPU s per tree: defaults {row['defaults']:.3f}, "
              f"thesis fixed {row['thesis fixed TW=1']:.3f}", flush=True)
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="results")
    parser.add_argument("--quick", action="store_true", help="1,000 training sets, 5 trees")
    args = parser.parse_args(argv)
    n_train, n_trees, n_sets = (1000, 5, 2000) if args.quick else (4000, 30, 20000)
    result = {"config": {"n_train": n_train, "n_trees": n_trees, "cost_sets": n_sets,
                         "python": platform.python_version()},
              "groups": groups_table(n_train, n_trees), "cost": cost_table(n_sets)}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "bench_attributes.json").write_text(json.dumps(result, indent=1))
    print(f"wrote {out / 'bench_attributes.json'}")


if __name__ == "__main__":
    main()
