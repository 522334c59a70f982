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

With ``--points``, the 3D study instead: point clouds, rows ``[x, y, z, 0]``, of 5 solid
shapes (ball, cube, upright cylinder and cone, flat torus; the shape uniform at random), each
drawn uniformly in its volume, scaled by a factor uniform in ``[0.8, 1.2]``, shifted by up to
0.2 along each axis and blurred by Gaussian noise (standard deviation 0.05); a share uniform
in ``[0, 0.2]`` of the points are distractors uniform in ``[-1.5, 1.5]^3``. Trained on 800
sets of 64 to 256 points, tested on 200 sets of exactly 64, 256 and 1024 points each. Models,
every one on one core and on the same sets: box forests on the sets as they are and on the
sets resampled to 64 and 128 points, a Deep Sets classifier in torch, and Set-Tree's GBeST (50
stages of depth-6 trees on items ``[x, y, z]``), in this process when ``settree`` imports,
else in the Python of ``--settree-python`` (an environment with ``settree``, which reads the
data from an ``.npz`` and needs neither boxtrees nor torch). Writes ``bench_points.json``
(with Set-Tree's fit seconds over each model's) and ``bench_points.png``.

    python -m benchmarks.bench_sets [--quick] [--out results] [--n-jobs 2] [--seed 0]
    python -m benchmarks.bench_sets --points [--quick] [--out results] [--settree-python PYTHON]
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from sklearn.ensemble import ExtraTreesClassifier, HistGradientBoostingClassifier
from threadpoolctl import threadpool_limits
from tqdm import tqdm

# boxtrees, fqi and torch are imported where they are used: Set-Tree's part of the 3D study
# runs this module in an environment that has none of them

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
    """Rows ``[f_1, ..., f_d, type]`` for ``points`` of shape (n, d), all of one type."""
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

# the 3D study
POINT_TRAIN_SIZES = (64, 256)
POINT_TEST_SIZES = (64, 256, 1024)
POINT_EXTENT = 1.5  # distractors are uniform in [-POINT_EXTENT, POINT_EXTENT]^3


def radius_xy(points):
    """Distance of each point of an (n, 3) array from the z axis."""
    return np.hypot(points[:, 0], points[:, 1])


def ball(points):
    """Whether each point lies in the unit ball."""
    return (points ** 2).sum(1) <= 1


def cube(points):
    """Whether each point lies in the cube of half-side 0.8."""
    return np.abs(points).max(1) <= 0.8


def cylinder(points):
    """Whether each point lies in the upright cylinder of radius and half-height 0.85."""
    return (radius_xy(points) <= 0.85) & (np.abs(points[:, 2]) <= 0.85)


def cone(points):
    """Whether each point lies in the upright cone of base radius 1 at z = -1, apex at z = 1."""
    return radius_xy(points) <= (1 - points[:, 2]) / 2


def torus(points):
    """Whether each point lies in the flat torus: ring of radius 0.65 around z, tube radius 0.3."""
    return (radius_xy(points) - 0.65) ** 2 + points[:, 2] ** 2 <= 0.3 ** 2


SHAPES = (ball, cube, cylinder, cone, torus)


def solid_points(rng, inside, n):
    """``n`` points uniform in the solid ``inside`` (a test of points in ``[-1, 1]^3``), shape (n, 3)."""
    points = np.empty((0, 3))
    while len(points) < n:
        draw = rng.uniform(-1, 1, (4 * n + 16, 3))
        points = np.concatenate([points, draw[inside(draw)]])
    return points[:n]


def point_set(rng, n):
    """One point cloud of the 3D study, rows ``[x, y, z, 0]``: ``(rows, label)``.

    The shape ``SHAPES[label]`` (label uniform) is scaled by a factor uniform in
    ``[0.8, 1.2]``, shifted by up to 0.2 along each axis and blurred by Gaussian noise of
    standard deviation 0.05; a share uniform in ``[0, 0.2]`` of the ``n`` points are
    distractors uniform in ``[-POINT_EXTENT, POINT_EXTENT]^3``.
    """
    label = rng.integers(0, len(SHAPES))
    n_distractors = rng.binomial(n, rng.uniform(0, 0.2))
    shape = solid_points(rng, SHAPES[label], n - n_distractors) * rng.uniform(0.8, 1.2)
    shape += rng.uniform(-0.2, 0.2, 3) + rng.normal(0, 0.05, shape.shape)
    distractors = rng.uniform(-POINT_EXTENT, POINT_EXTENT, (n_distractors, 3))
    return objects(np.concatenate([shape, distractors]), 0), float(label)


SET_DRAWS = {**TASKS, "points": point_set}


def make_sets(task, sizes, seed):
    """Sets of the given sizes (objects in random order) and their labels.

    Parameters
    ----------
    task : str
        A key of ``SET_DRAWS``: one of ``TASKS``, or ``"points"``.
    sizes : sequence of int
        Number of objects of each set.
    seed : int
        Seed of the generator.

    Returns
    -------
    sets : list of ndarray of shape (n_i, d + 1)
    labels : ndarray of shape (len(sizes),)
    """
    rng = np.random.default_rng(seed)
    sets, labels = [], []
    for n in sizes:
        rows, label = SET_DRAWS[task](rng, int(n))
        sets.append(rows[rng.permutation(len(rows))])
        labels.append(label)
    return sets, np.array(labels)


def make_data(task, n_train, n_test, seed, train_sizes=TRAIN_SIZES, test_sizes=TEST_SIZES):
    """Training sets (sizes uniform in ``train_sizes``, bounds included) and one test batch per
    test size.

    Returns
    -------
    train : tuple (sets, labels)
    tests : dict mapping each of ``test_sizes`` to (sets, labels)
    """
    sizes = np.random.default_rng(seed + 1000).integers(train_sizes[0], train_sizes[1] + 1, n_train)
    train = make_sets(task, sizes, seed)
    tests = {size: make_sets(task, np.full(n_test, size), seed + 10 + size) for size in test_sizes}
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
        from boxtrees import GridCounts

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
        from boxtrees import BoxExtraTreesRegressor
        from fqi import make_box_forest

        if defaults:
            self.model = BoxExtraTreesRegressor(n_estimators, n_jobs=n_jobs, random_state=seed)
        else:
            self.model = make_box_forest(n_estimators=n_estimators, n_jobs=n_jobs,
                                         random_state=seed).set_params(**params)

    def fit(self, sets, labels):
        """Fit on a list of ``(n_i, 3)`` object arrays and their 0/1 labels; returns self."""
        self.model.fit(as_object_sets(sets), labels)
        return self

    def predict(self, sets):
        """0/1 labels of a list of ``(n_i, 3)`` object arrays, shape (len(sets),)."""
        return (self.model.predict(as_object_sets(sets)) >= 0.5).astype(float)


def as_object_sets(sets):
    """A list of ``(n_i, d + 1)`` object arrays as one ``boxtrees.ObjectSets``."""
    from boxtrees import ObjectSets

    return ObjectSets.from_sequence(sets)


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
    """Set-Tree's gradient-boosted set trees (depth 6) on items ``[f_1, ..., f_d, one-hot type]``.

    Parameters
    ----------
    settree : module
        The ``settree`` package.
    n_types : int or None
        Number of object types, one-hot encoded after the attributes; None for the attributes
        alone (sets of one type).
    n_estimators : int
        Boosting stages (one tree per class and stage for more than 2 classes).
    seed : int
        Set-Tree's ``random_state``.
    """

    def __init__(self, settree, n_types, n_estimators, seed):
        self.settree = settree
        self.n_types = n_types
        self.model = settree.GradientBoostedSetTreeClassifier(
            learning_rate=0.1, n_estimators=n_estimators, max_depth=6, criterion="mse",
            operations=settree.OPERATIONS, use_attention_set=True, use_attention_set_comp=True,
            attention_set_limit=5, random_state=seed,
        )

    def _items(self, sets):
        """The sets as a Set-Tree dataset of item rows ``[f_1, ..., f_d, one-hot type]``."""
        if self.n_types is None:
            records = [s[:, :-1] for s in sets]
        else:
            one_hot = np.eye(self.n_types)
            records = [np.hstack([s[:, :-1], one_hot[s[:, -1].astype(int)]]) for s in sets]
        return self.settree.SetDataset(records=records, is_init=True)

    def fit(self, sets, labels):
        """Fit on a list of ``(n_i, d + 1)`` object arrays and their labels; returns self."""
        with warnings.catch_warnings():  # Set-Tree asks scikit-learn < 1.2 for its "mse", each tree
            warnings.filterwarnings("ignore", "Criterion 'mse' was deprecated", FutureWarning)
            self.model.fit(self._items(sets), labels.astype(int))
        return self

    def predict(self, sets):
        """Labels of a list of ``(n_i, d + 1)`` object arrays, shape (len(sets),)."""
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
    from boxtrees import BoxExtraTreesRegressor

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
        models["Set-Tree GBeST"] = lambda: SetTreeGBeST(settree, n_types(task), n_trees, seed)
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
    dict with ``accuracy`` (test size -> accuracy), ``fit_s`` and ``predict_s`` (all sizes) in
    wall-clock seconds, and ``fit_cpu_s``, the CPU seconds of the fit (this process's threads).
    """
    model = factory()
    start, start_cpu = time.perf_counter(), time.process_time()
    model.fit(*train)
    fit_s, fit_cpu_s = time.perf_counter() - start, time.process_time() - start_cpu
    accuracy, predict_s = {}, 0.0
    for size, (sets, labels) in tests.items():
        start = time.perf_counter()
        predicted = model.predict(sets)
        predict_s += time.perf_counter() - start
        accuracy[size] = float((predicted == labels).mean())
    return {"accuracy": accuracy, "fit_s": fit_s, "fit_cpu_s": fit_cpu_s, "predict_s": predict_s}


def run(args, fix):
    """Every model on every task; one result row per (task, model)."""
    data = {task: make_data(task, args.n_train, args.n_test, args.seed) for task in args.tasks}
    jobs = [(task, name, factory) for task in args.tasks
            for name, factory in model_factories(task, args, fix).items()]
    return [result_row(task, name, factory, data[task], args.n_jobs)
            for task, name, factory in tqdm(jobs, desc="models", unit="fit")]


def result_row(task, name, factory, data, n_jobs, sizes=TEST_SIZES):
    """Evaluate one model on ``data = (train, tests)`` within ``n_jobs`` OpenMP and BLAS
    threads; print its line (accuracies at ``sizes``) and return its row."""
    with threadpool_limits(n_jobs):
        row = {"task": task, "model": name, **evaluate(factory, *data)}
    tqdm.write(format_row(row, sizes))
    return row


def format_row(row, sizes=TEST_SIZES):
    """One line of the printed table, accuracies at ``sizes``."""
    accuracy = " ".join(f"{row['accuracy'][size]:.3f}" for size in sizes)
    return (f"{row['task']:<9} {row['model']:<48} {accuracy}   fit {row['fit_s']:7.2f} s"
            f"  predict {row['predict_s']:6.2f} s")


def plot(rows, tasks, path, test_sizes=TEST_SIZES, train_sizes=TRAIN_SIZES):
    """Accuracy against test set size, one panel per task; ``train_sizes`` (low, high) shaded."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(tasks), figsize=(5.5 * len(tasks), 5), sharey=True, squeeze=False)
    for ax, task in zip(axes[0], tasks):
        for row in (r for r in rows if r["task"] == task):
            style = "-" if row["model"].startswith("box") else "--"
            ax.plot(test_sizes, [row["accuracy"][s] for s in test_sizes], style, marker="o",
                    label=row["model"])
        ax.axvspan(*train_sizes, color="grey", alpha=0.15)
        ax.set(xscale="log", xticks=test_sizes, xticklabels=test_sizes, title=task,
               xlabel="objects per test set (training: shaded)")
        ax.set_ylim(min(0.4, *(r['accuracy'][s] for r in rows for s in test_sizes)) - 0.02, 1.02)
    axes[0][0].set_ylabel("accuracy")
    axes[0][-1].legend(fontsize=7, loc="lower left")
    fig.suptitle(f"Accuracy by test set size, trained on sets of {train_sizes[0]}-{train_sizes[1]} objects")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def resample(rng, sets, n_points):
    """Each set's rows drawn ``n_points`` times: without replacement, or with replacement from
    a set of fewer rows."""
    return [rows[rng.choice(len(rows), n_points, replace=len(rows) < n_points)] for rows in sets]


class ResampledBoxForest:
    """A ``BoxExtraTreesClassifier`` (one job) on object sets resampled to one size.

    A box test counts objects, and a cloud of 1,024 points has about 16 times the counts of
    one of 64 in every box: resampled to ``n_points`` each, clouds of every size have the
    counts seen at fit. Prediction averages the class probabilities of ``n_draws`` resamplings.

    Parameters
    ----------
    n_points : int or None
        Points per resampled set; None for the sets as they are.
    seed : int
        Seed of the forest and of the resampling.
    n_draws : int, default=16
        Resamplings averaged at prediction.
    **params
        Further parameters of the forest.
    """

    def __init__(self, n_points, seed, n_draws=16, **params):
        from boxtrees import BoxExtraTreesClassifier

        self.model = BoxExtraTreesClassifier(n_jobs=1, random_state=seed, **params)
        self.n_points, self.n_draws = n_points, n_draws
        self.rng = np.random.default_rng(seed)

    def fit(self, sets, labels):
        """Fit on a list of ``(n_i, d + 1)`` object arrays and their labels; returns self."""
        if self.n_points is not None:
            sets = resample(self.rng, sets, self.n_points)
        self.model.fit(as_object_sets(sets), labels)
        return self

    def predict(self, sets):
        """Labels of a list of ``(n_i, d + 1)`` object arrays, shape (len(sets),)."""
        if self.n_points is None:
            return self.model.predict(as_object_sets(sets))
        proba = sum(self.model.predict_proba(as_object_sets(resample(self.rng, sets, self.n_points)))
                    for _ in range(self.n_draws))
        return self.model.classes_[proba.argmax(1)]


class DeepSets:
    """A Deep Sets classifier in torch, trained with Adam on one thread.

    ``phi`` (3 layers of ``width`` ReLU units, as ``fqi.SetEncoder``'s object MLP plus one)
    maps each object's attributes, their mean over the set pools them, ``rho`` (a hidden
    layer of ``width``, then one score per class) classifies the pooled vector. The mean keeps
    the pooled vector's scale at every set size (``SetEncoder`` also pools the maximum, which
    grows with the set; with it a first trial lost 6 to 13 points). Sets are padded within
    each batch, the padding masked out of the mean; the learning rate follows a cosine schedule.

    Parameters
    ----------
    width : int
        Hidden units per layer.
    epochs : int
        Passes over the training sets.
    seed : int
        Seed of the initial weights and of the batch order.
    batch_size : int, default=32
        Sets per step.
    lr : float, default=1e-3
        Adam's initial learning rate.
    """

    def __init__(self, width, epochs, seed, batch_size=32, lr=1e-3):
        import torch

        torch.set_num_threads(1)
        self.width, self.epochs, self.seed = width, epochs, seed
        self.batch_size, self.lr = batch_size, lr

    def _network(self, n_attributes, n_classes):
        """``phi`` and ``rho``, as a pair of ``torch.nn.Sequential``."""
        from torch import nn

        width = self.width
        phi = nn.Sequential(nn.Linear(n_attributes, width), nn.ReLU(), nn.Linear(width, width),
                            nn.ReLU(), nn.Linear(width, width), nn.ReLU())
        rho = nn.Sequential(nn.Linear(width, width), nn.ReLU(), nn.Linear(width, n_classes))
        return phi, rho

    @staticmethod
    def _padded(sets):
        """Attributes padded to the largest set, ``(n, max_i n_i, d)``, and the mask of real rows."""
        import torch

        longest = max(len(rows) for rows in sets)
        x = np.zeros((len(sets), longest, sets[0].shape[1] - 1), dtype=np.float32)
        mask = np.zeros((len(sets), longest, 1), dtype=np.float32)
        for i, rows in enumerate(sets):
            x[i, :len(rows)], mask[i, :len(rows)] = rows[:, :-1], 1
        return torch.from_numpy(x), torch.from_numpy(mask)

    def _scores(self, sets):
        """Class scores of a batch of sets, a tensor of shape (len(sets), n_classes)."""
        x, mask = self._padded(sets)
        pooled = (self.phi(x) * mask).sum(1) / mask.sum(1)
        return self.rho(pooled)

    def fit(self, sets, labels):
        """Fit on a list of ``(n_i, d + 1)`` object arrays and their labels; returns self."""
        import torch

        torch.manual_seed(self.seed)
        rng = np.random.default_rng(self.seed)
        self.classes_, targets = np.unique(labels, return_inverse=True)
        self.phi, self.rho = self._network(sets[0].shape[1] - 1, len(self.classes_))
        optimizer = torch.optim.Adam([*self.phi.parameters(), *self.rho.parameters()], lr=self.lr)
        schedule = torch.optim.lr_scheduler.CosineAnnealingLR(optimizer, self.epochs)
        targets = torch.as_tensor(targets)
        for _ in range(self.epochs):
            order = rng.permutation(len(sets))
            for start in range(0, len(sets), self.batch_size):
                batch = order[start:start + self.batch_size]
                loss = torch.nn.functional.cross_entropy(self._scores([sets[i] for i in batch]),
                                                         targets[batch])
                optimizer.zero_grad()
                loss.backward()
                optimizer.step()
            schedule.step()
        return self

    def predict(self, sets):
        """Labels of a list of ``(n_i, d + 1)`` object arrays, shape (len(sets),)."""
        import torch

        with torch.no_grad():
            scores = torch.cat([self._scores(sets[start:start + 64])
                                for start in range(0, len(sets), 64)])
        return self.classes_[scores.argmax(1).numpy()]


# boxes over two of the three coordinates, or all three (the default groups for d = 3 are
# (x, y) and (x, y, z))
POINT_GROUPS = [(0, 1), (0, 2), (1, 2), (0, 1, 2)]
RESAMPLED = (64, 128)
POINT_FOREST = 100
DEEP_SETS_WIDTH, DEEP_SETS_LR = 256, 3e-3
SETTREE = "Set-Tree GBeST"


def point_models(args):
    """``{name: factory}`` of the 3D study's models but Set-Tree; a factory builds an unfitted model."""
    seed = args.seed
    models = {"box forest (defaults, 30 trees)": lambda: ResampledBoxForest(None, seed)}
    for n_points in RESAMPLED:
        models[f"box forest (resampled to {n_points} points, boxes over 2 or 3 coordinates, "
               f"{POINT_FOREST} trees)"] = lambda n=n_points: ResampledBoxForest(
            n, seed, column_groups=POINT_GROUPS, n_estimators=POINT_FOREST)
    models[f"Deep Sets (torch, width {DEEP_SETS_WIDTH}, mean pooling, Adam at {DEEP_SETS_LR:g}, "
           f"{args.epochs} epochs)"] = lambda: DeepSets(DEEP_SETS_WIDTH, args.epochs, seed,
                                                       lr=DEEP_SETS_LR)
    return models


def save_sets(path, data):
    """Write ``(train, tests)`` (as ``make_data`` returns them) to an ``.npz`` file."""
    train, tests = data
    arrays = {"test_sizes": np.array(list(tests))}
    for name, (sets, labels) in {"train": train, **{f"test_{n}": tests[n] for n in tests}}.items():
        arrays[f"{name}_rows"] = np.concatenate(sets)
        arrays[f"{name}_offsets"] = np.cumsum([0] + [len(rows) for rows in sets])
        arrays[f"{name}_labels"] = labels
    np.savez(path, **arrays)


def load_sets(path):
    """``(train, tests)`` from a file of ``save_sets``."""
    with np.load(path) as arrays:
        def batch(name):
            rows, offsets = arrays[f"{name}_rows"], arrays[f"{name}_offsets"]
            return np.split(rows, offsets[1:-1]), arrays[f"{name}_labels"]

        return batch("train"), {int(n): batch(f"test_{n}") for n in arrays["test_sizes"]}


def settree_row(args, data):
    """Set-Tree's row on ``data``: in this process when ``settree`` imports, else in
    ``--settree-python`` (reading the data from an ``.npz``); None without either."""
    settree = import_settree()
    if settree is not None:
        name = f"{SETTREE} ({args.n_trees} stages of depth-6 trees)"
        return result_row("points", name, lambda: SetTreeGBeST(settree, None, args.n_trees, args.seed),
                          data, 1, POINT_TEST_SIZES)
    if args.settree_python is None:
        print("settree does not import here and --settree-python is not given: Set-Tree is skipped")
        return None
    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as folder:
        data_path, result_path = Path(folder) / "points.npz", Path(folder) / "settree.json"
        save_sets(data_path, data)
        subprocess.run([args.settree_python, "-m", "benchmarks.bench_sets", "--points", "--seed",
                        str(args.seed), *(["--quick"] if args.quick else []),
                        "--settree-worker", str(data_path), str(result_path)],
                       cwd=root, env={**os.environ, "PYTHONPATH": str(root)}, check=True)
        row = json.loads(result_path.read_text())
    row["accuracy"] = {int(size): value for size, value in row["accuracy"].items()}  # JSON keys are str
    return row


def settree_worker(args):
    """Set-Tree's row on the data of ``--settree-worker DATA RESULT``, written to RESULT."""
    data_path, result_path = args.settree_worker
    if import_settree() is None:
        sys.exit(f"{sys.executable}: settree does not import")
    Path(result_path).write_text(json.dumps(settree_row(args, load_sets(data_path))))


def summarise_points(rows):
    """Each row's mean accuracy over the test sizes and, with Set-Tree's row, Set-Tree's fit
    seconds over the row's, wall-clock (``settree_fit_ratio``) and CPU
    (``settree_fit_cpu_ratio``); changes ``rows`` in place."""
    settree = [row for row in rows if row["model"].startswith(SETTREE)]
    for row in rows:
        row["mean_accuracy"] = float(np.mean(list(row["accuracy"].values())))
        if settree:
            row["settree_fit_ratio"] = settree[0]["fit_s"] / row["fit_s"]
            row["settree_fit_cpu_ratio"] = settree[0]["fit_cpu_s"] / row["fit_cpu_s"]


def run_points(args):
    """The 3D study: every model on the same point clouds, one core each; the result rows."""
    data = make_data("points", args.n_train, args.n_test, args.seed, POINT_TRAIN_SIZES,
                     POINT_TEST_SIZES)
    rows = [result_row("points", name, factory, data, 1, POINT_TEST_SIZES)
            for name, factory in point_models(args).items()]
    rows.append(settree_row(args, data))
    rows = [row for row in rows if row is not None]
    summarise_points(rows)
    return rows


def main_points(args):
    """Run the 3D study and write ``bench_points.json`` and ``bench_points.png``."""
    rows = run_points(args)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    config = {"n_train": args.n_train, "n_test_per_size": args.n_test,
              "train_sizes": POINT_TRAIN_SIZES, "test_sizes": POINT_TEST_SIZES,
              "shapes": [shape.__name__ for shape in SHAPES], "extent": POINT_EXTENT,
              "settree_trees": args.n_trees, "deep_sets_epochs": args.epochs, "seed": args.seed,
              "threads_per_model": 1, "python": platform.python_version()}
    table = markdown(rows, POINT_TEST_SIZES)
    print(table)
    for row in rows:
        ratios = (f", Set-Tree's fit seconds / its own {row['settree_fit_ratio']:.1f} (wall), "
                  f"{row['settree_fit_cpu_ratio']:.1f} (CPU)" if "settree_fit_ratio" in row else "")
        print(f"{row['model']}: mean accuracy {row['mean_accuracy']:.3f}, fit CPU "
              f"{row['fit_cpu_s']:.1f} s{ratios}")
    (out / "bench_points.json").write_text(
        json.dumps({"config": config, "rows": rows, "markdown": table}, indent=1))
    plot(rows, ["points"], out / "bench_points.png", POINT_TEST_SIZES, POINT_TRAIN_SIZES)
    print(f"wrote {out / 'bench_points.json'} and {out / 'bench_points.png'}")


def parse_args(argv=None):
    """Command-line options, with the data and model sizes of the chosen study and budget."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help="1,000 training sets, 500 per test size, 10 trees (--points: 150 "
                             "training sets, 30 per test size, 10 Set-Tree stages, 5 epochs)")
    parser.add_argument("--out", default="results", help="output folder")
    parser.add_argument("--n-jobs", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--tasks", default=",".join(TASKS), help="comma-separated subset of tasks")
    parser.add_argument("--fix", default=FIX, metavar="NAME=VALUE[,NAME=VALUE]",
                        help=f"estimator parameters of the extra box forests (default: {FIX}; '' for none)")
    parser.add_argument("--points", action="store_true", help="the 3D study, one core per model")
    parser.add_argument("--settree-python", metavar="PYTHON",
                        help="--points: a Python with settree, for Set-Tree's part")
    parser.add_argument("--settree-worker", nargs=2, metavar=("DATA", "RESULT"),
                        help="--points: Set-Tree's part alone, on the .npz DATA, its row to RESULT")
    args = parser.parse_args(argv)
    args.tasks = [t for t in args.tasks.split(",") if t]
    if not args.tasks or set(args.tasks) - set(TASKS):
        parser.error(f"--tasks must name some of {', '.join(TASKS)}")
    if args.points:
        args.n_train, args.n_test, args.n_trees, args.epochs = (
            (150, 30, 10, 5) if args.quick else (800, 200, N_TREES, 80))
    else:
        args.n_train, args.n_test, args.n_trees = (1000, 500, 10) if args.quick else (4000, 2000, N_TREES)
    return args


def markdown(rows, sizes=TEST_SIZES):
    """The accuracies at ``sizes`` as a markdown table, one row per task and model."""
    lines = ["| task | model | " + " | ".join(f"{n} objects" for n in sizes) + " | fit s |",
             "| --- | --- | " + "--- | " * len(sizes) + "--- |"]
    for row in rows:
        by_size = {int(size): value for size, value in row["accuracy"].items()}  # keys: int or JSON str
        accuracy = " | ".join(f"{by_size[n]:.3f}" for n in sizes)
        lines.append(f"| {row['task']} | {row['model']} | {accuracy} | {row['fit_s']:.1f} |")
    return "\n".join(lines)


def main(argv=None):
    """Run the comparison (``--points``: the 3D study) and write its JSON and PNG."""
    args = parse_args(argv)
    if args.settree_worker:
        settree_worker(args)
        return
    if args.points:
        main_points(args)
        return
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
