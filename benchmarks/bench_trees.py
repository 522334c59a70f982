"""Speed and accuracy of BoxExtraTreesRegressor against scikit-learn's ExtraTreesRegressor.

Workloads (thesis parameters K=500, n_min=30, M=30):
- object sets (~16 objects per sample, 4 types, target = box counts): our forest with fixed
  TW=1 boxes and with random boxes, vs sklearn ET on GridCounts(10) features;
- a dense 10,000 x 20 regression: our forest on the feature matrix (classic tests, K = number
  of features) vs sklearn ET with max_features=all, same trees and n_min;
- predict latency of the 30-tree fixed-box forest fitted on 5,000 sets (n_jobs=1 and -1):
  one set per call over 300 different sets, the same set repeated, and the cost per set of
  batches of 1, 16 and 400 sets;
- peak memory (RSS) of fitting 2 trees on a 200,000 x 50 float32 matrix with default
  parameters, ours and sklearn's, each in a fresh interpreter, beside the interpreter with
  the libraries and the data alone.

Prints a table, writes ``bench_trees.json`` and ``bench_trees.png`` under ``--out``.

    python -m benchmarks.bench_trees [--quick] [--out results] [--n-jobs 2]
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from sklearn.datasets import make_friedman1
from sklearn.ensemble import ExtraTreesRegressor
from sklearn.metrics import r2_score

from boxtrees import GridCounts, make_box_regression
from fqi import make_box_forest

M, K, N_MIN = 30, 500, 30


def timed(fn):
    """Wall time of one call, and its result."""
    start = time.perf_counter()
    result = fn()
    return time.perf_counter() - start, result


def run_model(name, model, X, y, X_test, y_test):
    fit_s, _ = timed(lambda: model.fit(X, y))
    predict_s, pred = timed(lambda: model.predict(X_test))
    row = {"model": name, "n_samples": len(y), "fit_s": fit_s, "predict_s": predict_s,
           "r2": r2_score(y_test, pred)}
    print(f"  {name:<34} n={len(y):>6}  fit {fit_s:7.2f} s  predict {predict_s:6.3f} s  R2 {row['r2']:.3f}")
    return row


def object_set_workload(n_samples, n_jobs, seed=0):
    X, y = make_box_regression(n_samples, random_state=seed)
    X_test, y_test = make_box_regression(5000, random_state=seed + 1)
    rows, forests = [], {}
    for test_type in ("fixed", "random"):
        forests[test_type] = make_box_forest(
            test_type=test_type, n_estimators=M, n_tests=K, min_samples_split=N_MIN,
            n_jobs=n_jobs, random_state=seed,
        )
        rows.append(run_model(f"box forest ({test_type})", forests[test_type], X, y, X_test, y_test))
    grid = GridCounts(10).fit(X)
    et = ExtraTreesRegressor(M, min_samples_split=N_MIN, max_features=1.0, n_jobs=n_jobs, random_state=seed)
    rows.append(run_model("sklearn ET on GridCounts(10)", et, grid.transform(X), y,
                          grid.transform(X_test), y_test))
    return rows, forests["fixed"]  # the deepest trees: the latency worst case


def dense_workload(n_jobs, seed=0):
    X, y = make_friedman1(15000, n_features=20, noise=1.0, random_state=seed)
    X, X_test, y, y_test = X[:10000], X[10000:], y[:10000], y[10000:]
    ours = make_box_forest(test_type="classic", n_estimators=M, n_tests=X.shape[1],
                           min_samples_split=N_MIN, n_jobs=n_jobs, random_state=seed)
    et = ExtraTreesRegressor(M, min_samples_split=N_MIN, max_features=1.0, n_jobs=n_jobs, random_state=seed)
    return [run_model("box forest (classic) on matrix", ours, X, y, X_test, y_test),
            run_model("sklearn ET on matrix", et, X, y, X_test, y_test)]


def _median_us(call, n_calls):
    """Median wall time of ``n_calls`` calls of ``call()``, in microseconds."""
    times = []
    for _ in range(n_calls):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return float(np.median(times) * 1e6)


def predict_latency(forest, quick=False):
    """What a forest's ``predict`` costs, in microseconds: one set per call over 300 different
    sets (3 rounds) with ``n_jobs=1`` and with ``n_jobs=-1`` (``make_box_forest``'s
    default), the same set repeated, and the cost per set of batches of 1, 16 and 400 sets."""
    X, _ = make_box_regression(400, random_state=99)
    sets = [np.asarray(X[i]) for i in range(len(X))]
    own = forest.get_params()["n_jobs"]
    latency = {}
    try:
        for label, n_jobs in (("n_jobs=1", 1), ("n_jobs=-1", -1)):
            forest.set_params(n_jobs=n_jobs)
            forest.predict(sets[:1])
            times = []
            for _ in range(1 if quick else 3):
                for s in sets[:300]:
                    start = time.perf_counter()
                    forest.predict([s])
                    times.append(time.perf_counter() - start)
            latency[f"single_set_us ({label})"] = float(np.median(times) * 1e6)
        forest.set_params(n_jobs=1)
        latency["same_set_us (n_jobs=1)"] = _median_us(lambda: forest.predict(sets[:1]),
                                                       300 if quick else 2000)
        for label, n_jobs in (("n_jobs=1", 1), ("n_jobs=-1", -1)):
            forest.set_params(n_jobs=n_jobs)
            for n in (1, 16, 400):
                calls = max(5 if quick else 20, (300 if quick else 4000) // n)
                latency[f"batch_{n}_us_per_set ({label})"] = _median_us(
                    lambda: forest.predict(sets[:n]), calls) / n
    finally:
        forest.set_params(n_jobs=own)
    return latency


_MEMORY_SCRIPT = """
import sys
import numpy as np
import json
from boxtrees import BoxExtraTreesRegressor
from sklearn.ensemble import ExtraTreesRegressor
rng = np.random.default_rng(0)
X = np.empty((200_000, 50), dtype=np.float32)
for start in range(0, len(X), 10_000):   # no float64 copy of the whole matrix
    X[start:start + 10_000] = rng.normal(size=(10_000, 50))
y = X[:, 0] + rng.normal(size=len(X))
model = {"ours": lambda: BoxExtraTreesRegressor(**json.loads(sys.argv[2])),
         "sklearn": lambda: ExtraTreesRegressor(2, n_jobs=1, random_state=0)}.get(sys.argv[1])
if model is not None:
    model().fit(X, y)
# the peak of this process image (getrusage's ru_maxrss would keep the parent's from fork)
print(next(line.split()[1] for line in open("/proc/self/status") if line.startswith("VmHWM")))
"""


def dense_fit_memory():
    """Peak RSS in MB of a fresh interpreter holding the libraries and the 200,000 x 50
    matrix ("data"), and of one that also fits 2 trees on it, ours and sklearn's."""
    peaks = {}
    # the thesis's forest (its parameters passed: the script imports no more than it uses)
    ours = json.dumps(make_box_forest(n_estimators=2, n_jobs=1, random_state=0).get_params())
    for who in ("data", "ours", "sklearn"):
        done = subprocess.run([sys.executable, "-c", _MEMORY_SCRIPT, who, ours], check=True,
                              capture_output=True, text=True)
        peaks[who] = int(done.stdout.split()[-1]) / 1024   # VmHWM is in KiB
    return peaks


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = [f"{r['model']}\n(n={r['n_samples']})" for r in rows]
    fig, axes = plt.subplots(1, 2, figsize=(12, 0.55 * len(rows) + 1.5), sharey=True)
    colours = ["tab:blue" if r["model"].startswith("box") else "tab:grey" for r in rows]
    fit = [r["fit_s"] for r in rows]
    axes[0].barh(labels, fit, color=colours)
    axes[0].set_xscale("log")
    axes[0].set_xlabel("fit time (s, log scale)")
    axes[1].barh(labels, [r["r2"] for r in rows], color=colours)
    axes[1].set_xlabel("held-out $R^2$")
    for i, r in enumerate(rows):
        axes[0].text(r["fit_s"], i, f" {r['fit_s']:.2f} s", va="center")
        axes[1].text(r["r2"], i, f" {r['r2']:.3f}", va="center")
    axes[0].set_xlim(right=max(fit) * 6)
    axes[1].set_xlim(0, 1.15)
    axes[0].invert_yaxis()
    fig.suptitle("BoxExtraTreesRegressor vs scikit-learn ExtraTreesRegressor (30 trees, n_min=30)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="only N=5,000 object sets")
    parser.add_argument("--out", default="results", help="output folder")
    parser.add_argument("--n-jobs", type=int, default=2)
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    sizes = [5000] if args.quick else [5000, 20000]
    rows = []
    for n in sizes:
        print(f"object sets, N={n}:")
        workload_rows, forest = object_set_workload(n, args.n_jobs)
        rows += workload_rows
        if n == 5000:
            latency_forest = forest
    print("dense 10,000 x 20 (Friedman #1):")
    rows += dense_workload(args.n_jobs)
    latency = predict_latency(latency_forest, quick=args.quick)
    latency_us = latency["single_set_us (n_jobs=1)"]
    print("predict, 30 fixed-box trees fitted on 5,000 sets (median, us):")
    for name, value in latency.items():
        print(f"  {name:<40} {value:7.1f}")
    memory = dense_fit_memory()
    print(f"dense fit peak RSS, 200,000 x 50, 2 trees: ours {memory['ours']:.0f} MB, sklearn "
          f"{memory['sklearn']:.0f} MB (libraries and data alone: {memory['data']:.0f} MB)")

    def ratio(model_a, model_b, n, key="fit_s"):
        a = next(r for r in rows if r["model"] == model_a and r["n_samples"] == n)
        b = next(r for r in rows if r["model"] == model_b and r["n_samples"] == n)
        return b[key] / a[key]

    n_big = sizes[-1]
    summary = {
        "object_fit_speedup_vs_sklearn_grid": ratio("box forest (fixed)", "sklearn ET on GridCounts(10)", n_big),
        "object_fit_speedup_n": n_big,
        "dense_fit_speedup_vs_sklearn": ratio("box forest (classic) on matrix", "sklearn ET on matrix", 10000),
        "single_sample_predict_us": latency_us,
        "predict_latency_us": latency,
        "dense_fit_peak_rss_mb": memory,
    }
    print(f"\nobject-set fit speed-up vs sklearn-on-grid at N={n_big}: "
          f"{summary['object_fit_speedup_vs_sklearn_grid']:.1f}x (target >= 5x at N=20,000)")
    print(f"dense fit speed-up vs sklearn: {summary['dense_fit_speedup_vs_sklearn']:.2f}x (target >= 1x)")
    print(f"single-set predict over 300 sets: {latency_us:.1f} us (target <= 25 us); batch of "
          f"400: {latency['batch_400_us_per_set (n_jobs=1)']:.1f} us per set (target <= 5 us)")
    print(f"dense fit memory: {memory['ours']:.0f} MB vs sklearn's {memory['sklearn']:.0f} MB "
          "(target: at most sklearn's)")
    load = os.getloadavg()[1]
    print(f"load average over the last 5 minutes: {load:.1f} on {os.cpu_count()} cores "
          "(other processes slow both sides)")
    report = {"rows": rows, "summary": summary, "n_jobs": args.n_jobs, "cpu_count": os.cpu_count(),
              "load_average_5min": load, "machine": platform.machine(),
              "python": platform.python_version()}
    (out / "bench_trees.json").write_text(json.dumps(report, indent=2))
    plot(rows, out / "bench_trees.png")
    print(f"wrote {out / 'bench_trees.json'} and {out / 'bench_trees.png'}")


if __name__ == "__main__":
    main()
