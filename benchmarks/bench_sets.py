"""Set-size shift: accuracy when the sets seen at prediction are larger than at training.

Every model is trained on 4,000 sets of 15 to 25 objects (about 20) and tested on sets of
exactly 10, 20, 50, 100 and 300 objects. Objects are ``(x, y, type)`` rows with positions in
``[-10, 10]^2``. The label depends only on the objects of the informative types inside the
region ``R = (0.5, 3.5) x (-0.5, 2.5)``, whose number is drawn independently of the set size;
the rest of the set is background that grows with the set size:

- ``presence``: one type; with probability 1/2 one object lies in ``R`` (label 1), all other
  objects are uniform outside ``R``;
- ``count``: ``k`` uniform in ``{0, 1, 2, 3}`` objects of type 0 in ``R``, label ``k >= 2``;
  background objects are of type 0 (uniform outside ``R``) or type 1 (uniform anywhere,
  ``R`` included), with probability 1/2 each;
- ``compare``: ``k0`` objects of type 0 and ``k1`` of type 1 in ``R``, ``k0 != k1`` uniform in
  ``{0, 1, 2, 3}``, label ``k0 > k1``; background of both types, uniform outside ``R``.

A model that has learnt the rule keeps its accuracy at every size. Models:

- ``BoxExtraTreesRegressor`` (50 trees) with its defaults, and the thesis's forest
  (``fqi.make_box_forest``) with each test type, their predictions thresholded at 0.5; the
  thesis's forests again with the estimator parameters of ``--fix NAME=VALUE[,NAME=VALUE]``
  (default ``FIX``; skipped, with a message, when the estimator lacks one of them);
- scikit-learn's ``ExtraTreesClassifier`` (Gini, and entropy: what that criterion would
  change) and ``HistGradientBoostingClassifier`` on hand-made set features: per-type counts on a 10 x 10 grid, and per-type mean, minimum and
  maximum of x and y (missing when a set has no object of a type);
- Set-Tree's gradient-boosted set trees (GBeST: 50 trees, depth 6) on items
  ``[x, y, one-hot type]``, when the ``settree`` package can be imported.

Writes ``bench_sets.json`` (accuracy by test size, fit and predict times) and
``bench_sets.png`` under ``--out``.

    python -m benchmarks.bench_sets [--quick] [--out results] [--n-jobs 2] [--seed 0]
"""
import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np
from sklearn.ensemble import ExtraTreesClassifier, HistGradientBoostingClassifier
from threadpoolctl import threadpool_limits
from tqdm import tqdm

from boxtrees import BoxExtraTreesRegressor, GridCounts, ObjectSets
from fqi import make_box_forest

EXTENT = 10.0
REGION = (0.5, 3.5, -0.5, 2.5)
TRAIN_SIZES = (15, 25)
TEST_SIZES = (10, 20, 50, 100, 300)
TEST_TYPES = ("fixed", "bounded", "random", "classic")
N_TREES = 50
# the size-robust forest: box tests refined on the node's objects, one bootstrap sample per tree
FIX = "refine_tests=true,bootstrap=true"


def uniform_in(rng, n, box):
    """``n`` points uniform in ``box = (xmin, xmax, ymin, ymax)``, shape (n, 2)."""
    x0, x1, y0, y1 = box
    return np.column_stack([rng.uniform(x0, x1, n), rng.uniform(y0, y1, n)])


def in_region(points):
    """Whether each point lies strictly inside ``REGION``."""
    x0, x1, y0, y1 = REGION
    x, y = points[:, 0], points[:, 1]
    return (x > x0) & (x < x1) & (y > y0) & (y < y1)


def anywhere(rng, n):
    """``n`` points uniform in the whole area."""
    return uniform_in(rng, n, (-EXTENT, EXTENT, -EXTENT, EXTENT))


def outside(rng, n):
    """``n`` points uniform in the area outside ``REGION`` (rejection sampling)."""
    points = np.empty((0, 2))
    while len(points) < n:
        draw = anywhere(rng, 2 * n + 8)
        points = np.concatenate([points, draw[~in_region(draw)]])
    return points[:n]


def objects(points, object_type):
    """Rows ``[x, y, type]`` for ``points`` of one type."""
    return np.column_stack([points, np.full(len(points), object_type, dtype=float)])


def presence_set(rng, n):
    """One set of the presence task: ``(rows, label)``."""
    k = rng.integers(0, 2)
    rows = np.concatenate([objects(uniform_in(rng, k, REGION), 0), objects(outside(rng, n - k), 0)])
    return rows, float(k)


def count_set(rng, n):
    """One set of the count-threshold task: ``(rows, label)``."""
    k = rng.integers(0, 4)
    background_type = rng.integers(0, 2, n - k)
    rows = np.concatenate([
        objects(uniform_in(rng, k, REGION), 0),
        objects(outside(rng, int((background_type == 0).sum())), 0),
        objects(anywhere(rng, int((background_type == 1).sum())), 1),
    ])
    return rows, float(k >= 2)


def compare_set(rng, n):
    """One set of the two-type comparison task: ``(rows, label)``."""
    k0, k1 = rng.integers(0, 4, 2)
    while k0 == k1:
        k0, k1 = rng.integers(0, 4, 2)
    background_type = rng.integers(0, 2, n - k0 - k1)
    rows = np.concatenate([
        objects(uniform_in(rng, k0, REGION), 0),
        objects(uniform_in(rng, k1, REGION), 1),
        objects(outside(rng, int((background_type == 0).sum())), 0),
        objects(outside(rng, int((background_type == 1).sum())), 1),
    ])
    return rows, float(k0 > k1)


TASKS = {"presence": presence_set, "count": count_set, "compare": compare_set}


def make_sets(task, sizes, seed):
    """Sets of the given sizes (objects in random order) and their labels.

    Parameters
    ----------
    task : str
        A key of ``TASKS``.
    sizes : sequence of int
        Number of objects of each set.
    seed : int
        Seed of the generator.

    Returns
    -------
    sets : list of ndarray of shape (n_i, 3)
    labels : ndarray of shape (len(sizes),)
    """
    rng = np.random.default_rng(seed)
    sets, labels = [], []
    for n in sizes:
        rows, label = TASKS[task](rng, int(n))
        sets.append(rows[rng.permutation(len(rows))])
        labels.append(label)
    return sets, np.array(labels)


def make_data(task, n_train, n_test, seed):
    """Training sets (sizes uniform in ``TRAIN_SIZES``) and one test batch per test size.

    Returns
    -------
    train : tuple (sets, labels)
    tests : dict mapping each of ``TEST_SIZES`` to (sets, labels)
    """
    train_sizes = np.random.default_rng(seed + 1000).integers(TRAIN_SIZES[0], TRAIN_SIZES[1] + 1, n_train)
    train = make_sets(task, train_sizes, seed)
    tests = {size: make_sets(task, np.full(n_test, size), seed + 10 + size) for size in TEST_SIZES}
    return train, tests


def n_types(task):
    """Number of object types of a task."""
    return 1 if task == "presence" else 2


class SetFeatures:
    """Fixed-length features of object sets: grid counts and per-type coordinate summaries.

    Parameters
    ----------
    n_types : int
        Types ``0 .. n_types - 1`` are described.
    n_bins : int, default=10
        Grid cells per axis over ``[-EXTENT, EXTENT]^2``.
    """

    def __init__(self, n_types, n_bins=10):
        self.n_types = n_types
        self.grid = GridCounts(n_bins, view_bounds=EXTENT, n_types=n_types).fit([np.empty((0, 3))])

    def transform(self, sets):
        """Feature matrix of shape (n_sets, n_bins**2 * n_types + 6 * n_types)."""
        return np.hstack([self.grid.transform(sets), np.array([self._summary(s) for s in sets])])

    def _summary(self, rows):
        """Mean, minimum and maximum of x and y of each type (NaN for an absent type)."""
        values = []
        for t in range(self.n_types):
            points = rows[rows[:, 2] == t, :2]
            if len(points):
                values += [*points.mean(0), *points.min(0), *points.max(0)]
            else:
                values += [np.nan] * 6
        return values


class BoxForest:
    """A box forest on the object sets, its prediction thresholded at 0.5: the thesis's
    forest (``fqi.make_box_forest``) with ``params`` changed, or with ``defaults`` the
    estimator's own defaults."""

    def __init__(self, n_estimators, n_jobs, seed, defaults=False, **params):
        if defaults:
            self.model = BoxExtraTreesRegressor(n_estimators, n_jobs=n_jobs, random_state=seed)
        else:
            self.model = make_box_forest(n_estimators=n_estimators, n_jobs=n_jobs,
                                         random_state=seed).set_params(**params)

    def fit(self, sets, labels):
        """Fit on a list of ``(n_i, 3)`` object arrays and their 0/1 labels; returns self."""
        self.model.fit(ObjectSets.from_sequence(sets), labels)
        return self

    def predict(self, sets):
        """0/1 labels of a list of ``(n_i, 3)`` object arrays, shape (len(sets),)."""
        return (self.model.predict(ObjectSets.from_sequence(sets)) >= 0.5).astype(float)


class OnFeatures:
    """A scikit-learn classifier on ``SetFeatures``."""

    def __init__(self, classifier, task):
        self.classifier = classifier
        self.features = SetFeatures(n_types(task))

    def fit(self, sets, labels):
        """Fit on a list of ``(n_i, 3)`` object arrays and their 0/1 labels; returns self."""
        self.classifier.fit(self.features.transform(sets), labels)
        return self

    def predict(self, sets):
        """0/1 labels of a list of ``(n_i, 3)`` object arrays, shape (len(sets),)."""
        return self.classifier.predict(self.features.transform(sets))


class SetTreeGBeST:
    """Set-Tree's gradient-boosted set trees on items ``[x, y, one-hot type]``."""

    def __init__(self, settree, task, n_estimators, seed):
        self.settree = settree
        self.n_types = n_types(task)
        self.model = settree.GradientBoostedSetTreeClassifier(
            learning_rate=0.1, n_estimators=n_estimators, max_depth=6, criterion="mse",
            operations=settree.OPERATIONS, use_attention_set=True, use_attention_set_comp=True,
            attention_set_limit=5, random_state=seed,
        )

    def _items(self, sets):
        """The sets as a Set-Tree dataset of item rows ``[x, y, one-hot type]``."""
        one_hot = np.eye(self.n_types)
        records = [np.hstack([s[:, :2], one_hot[s[:, 2].astype(int)]]) for s in sets]
        return self.settree.SetDataset(records=records, is_init=True)

    def fit(self, sets, labels):
        """Fit on a list of ``(n_i, 3)`` object arrays and their 0/1 labels; returns self."""
        self.model.fit(self._items(sets), labels.astype(int))
        return self

    def predict(self, sets):
        """0/1 labels of a list of ``(n_i, 3)`` object arrays, shape (len(sets),)."""
        return self.model.predict(self._items(sets)).astype(float)


def parse_fix(text):
    """``"a=1,b=true"`` -> ``{"a": 1, "b": True}``: booleans, numbers, else strings."""
    params = {}
    for item in filter(None, text.split(",")):
        name, _, value = (part.strip() for part in item.partition("="))
        if value.lower() in ("true", "false"):
            params[name] = value.lower() == "true"
        else:
            try:
                params[name] = json.loads(value)
            except json.JSONDecodeError:
                params[name] = value
    return params


def unsupported(params):
    """The names in ``params`` that ``BoxExtraTreesRegressor`` does not accept."""
    return sorted(set(params) - set(BoxExtraTreesRegressor().get_params()))


def model_factories(task, args, fix):
    """``{name: factory}`` of the models compared on ``task``; a factory builds an unfitted model."""
    n_trees, jobs, seed = args.n_trees, args.n_jobs, args.seed
    models = {"box forest (defaults)": lambda: BoxForest(n_trees, jobs, seed, defaults=True)}
    for test_type in TEST_TYPES:
        models[f"box forest ({test_type})"] = (
            lambda t=test_type: BoxForest(n_trees, jobs, seed, test_type=t))
        if fix:
            models[f"box forest ({test_type}, {args.fix})"] = (
                lambda t=test_type: BoxForest(n_trees, jobs, seed, test_type=t, **fix))
    models["sklearn ExtraTrees on set features"] = lambda: OnFeatures(
        ExtraTreesClassifier(n_trees, n_jobs=jobs, random_state=seed), task)
    # what the entropy criterion would change (the box classifiers use Gini)
    models["sklearn ExtraTrees (entropy) on set features"] = lambda: OnFeatures(
        ExtraTreesClassifier(n_trees, criterion="entropy", n_jobs=jobs, random_state=seed), task)
    models["sklearn HistGradientBoosting on set features"] = lambda: OnFeatures(
        HistGradientBoostingClassifier(random_state=seed), task)
    settree = import_settree()
    if settree is not None:
        models["Set-Tree GBeST"] = lambda: SetTreeGBeST(settree, task, n_trees, seed)
    return models


def import_settree():
    """The ``settree`` module, or None when it cannot be imported."""
    try:
        import settree
    except Exception:  # an unmaintained package: any import failure means "not available"
        return None
    return settree


def evaluate(factory, train, tests):
    """Fit one model and measure its accuracy at each test size.

    Returns
    -------
    dict with ``accuracy`` (test size -> accuracy), ``fit_s`` and ``predict_s`` (all sizes).
    """
    model = factory()
    start = time.perf_counter()
    model.fit(*train)
    fit_s = time.perf_counter() - start
    accuracy, predict_s = {}, 0.0
    for size, (sets, labels) in tests.items():
        start = time.perf_counter()
        predicted = model.predict(sets)
        predict_s += time.perf_counter() - start
        accuracy[size] = float((predicted == labels).mean())
    return {"accuracy": accuracy, "fit_s": fit_s, "predict_s": predict_s}


def run(args, fix):
    """Every model on every task; one result row per (task, model)."""
    data = {task: make_data(task, args.n_train, args.n_test, args.seed) for task in args.tasks}
    jobs = [(task, name, factory) for task in args.tasks
            for name, factory in model_factories(task, args, fix).items()]
    rows = []
    for task, name, factory in tqdm(jobs, desc="models", unit="fit"):
        with threadpool_limits(args.n_jobs):  # OpenMP models stay within --n-jobs cores
            row = {"task": task, "model": name, **evaluate(factory, *data[task])}
        rows.append(row)
        tqdm.write(format_row(row))
    return rows


def format_row(row):
    """One line of the printed table."""
    accuracy = " ".join(f"{row['accuracy'][size]:.3f}" for size in TEST_SIZES)
    return (f"{row['task']:<9} {row['model']:<48} {accuracy}   fit {row['fit_s']:7.2f} s"
            f"  predict {row['predict_s']:6.2f} s")


def plot(rows, tasks, path):
    """Accuracy against test set size, one panel per task."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(tasks), figsize=(5.5 * len(tasks), 5), sharey=True, squeeze=False)
    for ax, task in zip(axes[0], tasks):
        for row in (r for r in rows if r["task"] == task):
            style = "-" if row["model"].startswith("box") else "--"
            ax.plot(TEST_SIZES, [row["accuracy"][s] for s in TEST_SIZES], style, marker="o",
                    label=row["model"])
        ax.axvspan(*TRAIN_SIZES, color="grey", alpha=0.15)
        ax.set(xscale="log", xticks=TEST_SIZES, xticklabels=TEST_SIZES, title=task,
               xlabel="objects per test set (training: shaded)")
        ax.set_ylim(min(0.4, *(r['accuracy'][s] for r in rows for s in TEST_SIZES)) - 0.02, 1.02)
    axes[0][0].set_ylabel("accuracy")
    axes[0][-1].legend(fontsize=7, loc="lower left")
    fig.suptitle(f"Accuracy by test set size, trained on sets of {TRAIN_SIZES[0]}-{TRAIN_SIZES[1]} objects")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def parse_args(argv=None):
    """Command-line options, with the data and forest sizes of the chosen budget."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="1,000 training sets, 500 per test size, 10 trees")
    parser.add_argument("--out", default="results", help="output folder")
    parser.add_argument("--n-jobs", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--tasks", default=",".join(TASKS), help="comma-separated subset of tasks")
    parser.add_argument("--fix", default=FIX, metavar="NAME=VALUE[,NAME=VALUE]",
                        help=f"estimator parameters of the extra box forests (default: {FIX}; '' for none)")
    args = parser.parse_args(argv)
    args.tasks = [t for t in args.tasks.split(",") if t]
    if not args.tasks or set(args.tasks) - set(TASKS):
        parser.error(f"--tasks must name some of {', '.join(TASKS)}")
    args.n_train, args.n_test, args.n_trees = (1000, 500, 10) if args.quick else (4000, 2000, N_TREES)
    return args


def markdown(rows):
    """The accuracies by test size as a markdown table, one row per task and model."""
    lines = ["| task | model | " + " | ".join(f"{n} objects" for n in TEST_SIZES) + " | fit s |",
             "| --- | --- | " + "--- | " * len(TEST_SIZES) + "--- |"]
    for row in rows:
        by_size = {int(size): value for size, value in row["accuracy"].items()}  # keys: int or JSON str
        accuracy = " | ".join(f"{by_size[n]:.3f}" for n in TEST_SIZES)
        lines.append(f"| {row['task']} | {row['model']} | {accuracy} | {row['fit_s']:.1f} |")
    return "\n".join(lines)


def main(argv=None):
    """Run the comparison and write its JSON and PNG."""
    args = parse_args(argv)
    fix = parse_fix(args.fix)
    missing = unsupported(fix)
    if missing:
        print(f"BoxExtraTreesRegressor has no parameter {', '.join(missing)}: the --fix forests are skipped")
        fix = {}
    rows = run(args, fix)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    config = {"n_train": args.n_train, "n_test_per_size": args.n_test, "n_trees": args.n_trees,
              "train_sizes": TRAIN_SIZES, "test_sizes": TEST_SIZES, "region": REGION,
              "extent": EXTENT, "seed": args.seed, "fix": fix, "python": platform.python_version()}
    table = markdown(rows)
    print(table)
    (out / "bench_sets.json").write_text(
        json.dumps({"config": config, "rows": rows, "markdown": table}, indent=1))
    plot(rows, args.tasks, out / "bench_sets.png")
    print(f"wrote {out / 'bench_sets.json'} and {out / 'bench_sets.png'}")


if __name__ == "__main__":
    main()
