"""How the fit time of one box-test tree grows with objects per state and with samples.

Thesis parameters: K=500 tests, n_min=30, fixed boxes of half-width TW=1 and random boxes.
Workloads:

- ``synthetic``: ``boxtrees.make_box_regression`` sets (Poisson number of objects, uniform in
  ``[-10, 10]^2``, 4 types), tests drawn in that square; objects per state in ``--objects``
  at ``--base-samples`` samples, and samples in ``--samples`` at ``--base-objects`` objects;
- ``local`` and ``global``: observations of the treasure game (``ObjectWorldTreasure-v0``,
  the batched engine, which gives the same transitions as ``gym.make``) under uniform random
  actions, one 50-step episode per world; the target is the discounted return of the rest of
  the episode (gamma = 0.5, as in FQI), a stand-in for the Q-targets FQI fits; tests are
  drawn in the view square (half-side 10 locally, 60 globally). Samples in
  ``--game-samples``.

For every configuration, ``--trees`` trees are grown one at a time in this thread and timed in
CPU seconds (``time.thread_time``), so other jobs on the machine change little. Beside the
time, each tree reports its nodes, depth, the balance of its splits (the median share of a
node's samples its smaller child takes, weighted by node size), the leaves where no test
split a non-constant node (each cost ``max_retries + 1`` rounds of K tests) and its *object
visits*: the number of (internal node, object of a sample of that node) pairs, the work of the
splits' partitions and, for one kind of box in one view, about a fixed multiple of the
objects the tests' strips hold. CPU nanoseconds per (test x object visit) flat across sizes
means the engine is linear in that work, so any faster-than-linear growth of the fit is the
growth of the trees themselves. Predict time is per (sample x tree), on held-out sets of the
same workload; data time is per sample (for the game: its env steps and the sets built from
them). From the rows at 5,000 game samples (a quarter of 20,000, one action's share), the CPU
time of one FQI run of the treasure game at the thesis budget is estimated per view.

Prints a table and the log-log slopes, writes ``bench_scaling.json`` and ``bench_scaling.png``
under ``--out``. ``--one`` grows a single tree and prints its time, for a profiler.

    python -m benchmarks.bench_scaling [--objects 16 64 256 360] [--samples 5000 20000 80000]
        [--views local global] [--game-samples 5000 20000] [--test-types fixed random]
        [--trees 2] [--out results] [--seed 0]
    python -m benchmarks.bench_scaling --one global:random:5000
    python -m benchmarks.bench_scaling --one synthetic:fixed:20000:360
"""
import argparse
import json
import platform
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

import envs
from boxtrees import BoxExtraTreeRegressor, ObjectSets, make_box_regression

K, N_MIN, TEST_WIDTH, GAMMA = 500, 30, 1.0, 0.5
# one FQI run of the treasure game at the thesis budget: per iteration, 20,000 new
# transitions, one 30-tree forest per action (fitted on that action's share) and 20,000
# evaluation steps; every collection step after the first iteration and every evaluation
# step predicts with all 4 forests
ITERATIONS, RUN_SAMPLES, RUN_TREES, ACTIONS = 20, 20000, 30, 4
EXTENT = 10.0           # synthetic objects lie in [-EXTENT, EXTENT]^2
EPISODE_STEPS = 50      # the game's max_steps: one episode per world
# the treasure-game views this benchmark measures (a subset of envs.VIEWS)
GAME_VIEWS = ("local", "global")


@dataclass(frozen=True)
class Config:
    """One measured workload: ``kind`` is "synthetic" or a game view."""

    kind: str
    test_type: str
    n_samples: int
    mean_objects: int = 0   # synthetic only; the game's is measured

    @property
    def label(self):
        size = f", {self.mean_objects} objects" if self.kind == "synthetic" else ""
        return f"{self.kind} {self.test_type}, N={self.n_samples}{size}"


def synthetic_data(n_samples, mean_objects, n_types, seed):
    """``make_box_regression`` sets and targets, and the square tests are drawn in."""
    X, y = make_box_regression(n_samples, mean_objects=mean_objects, n_types=n_types,
                               extent=EXTENT, random_state=seed)
    return X, y, (-EXTENT, EXTENT, -EXTENT, EXTENT)


def discounted_returns(rewards):
    """Per step of episodes laid out (steps, worlds): the discounted sum of the rewards from it
    to the end of the episode."""
    returns = np.zeros_like(rewards)
    following = np.zeros(rewards.shape[1])
    for t in range(len(rewards) - 1, -1, -1):
        following = rewards[t] + GAMMA * following
        returns[t] = following
    return returns


def game_data(view, n_samples, seed):
    """Treasure-game states under random actions, world after world, their discounted
    returns, and the view square."""
    n_worlds = -(-n_samples // EPISODE_STEPS)
    worlds = envs.BatchedObjectWorld(n_worlds, treasure=True, view=view)
    seeds = np.random.SeedSequence(seed).generate_state(n_worlds).astype(np.int64)
    obs, _ = worlds.reset(seed=[int(s) for s in seeds])
    rng = np.random.default_rng(seed)
    states, rewards = [], []
    for _ in range(EPISODE_STEPS):
        states.append(obs)
        obs, reward, *_ = worlds.step(rng.integers(4, size=n_worlds))
        rewards.append(reward)
    returns = discounted_returns(np.array(rewards, dtype=np.float64))
    sets = [states[t][i] for i in range(n_worlds) for t in range(EPISODE_STEPS)]
    bound = worlds.rules.obs_bound
    return (ObjectSets.from_sequence(sets[:n_samples]), returns.T.ravel()[:n_samples],
            (-bound, bound, -bound, bound))


def make_data(config, n_types, seed):
    """Training sets, targets and view bounds of a configuration."""
    if config.kind == "synthetic":
        return synthetic_data(config.n_samples, config.mean_objects, n_types, seed)
    return game_data(config.kind, config.n_samples, seed)


def make_tree(test_type, bounds, seed):
    """A tree with the thesis parameters."""
    return BoxExtraTreeRegressor(n_tests=K, min_samples_split=N_MIN, test_type=test_type,
                                 test_width=TEST_WIDTH, view_bounds=bounds, random_state=seed,
                                 relative_width=False, refine_tests=False)


def cpu_seconds(fn):
    """CPU time of this thread spent in one call, and its result."""
    start = time.thread_time()
    result = fn()
    return time.thread_time() - start, result


def smaller_share(arrays):
    """Median, over the samples of the internal nodes, of the share of its node's samples the
    smaller child takes (0.5: balanced splits; small: splits that peel off a few samples)."""
    inner = np.flatnonzero(arrays.children_left != -1)
    n = arrays.n_node_samples
    share = np.minimum(n[arrays.children_left[inner]], n[arrays.children_right[inner]]) / n[inner]
    order = np.argsort(share)
    weight = np.cumsum(n[inner][order])
    return float(share[order][np.searchsorted(weight, weight[-1] / 2)]) if inner.size else 0.5


def tree_counters(tree, X, y):
    """Nodes, depth, split balance, stuck leaves and object visits of a fitted tree on its
    training data.

    A leaf is stuck when it holds at least ``N_MIN`` samples whose targets differ: no test
    split it.
    """
    arrays = tree.tree_
    depth = arrays.node_depth()
    leaves = tree.apply(X)
    low = np.full(arrays.node_count, np.inf)
    high = np.full(arrays.node_count, -np.inf)
    np.minimum.at(low, leaves, y)
    np.maximum.at(high, leaves, y)
    stuck = (arrays.n_node_samples >= N_MIN) & (high > low)
    sizes = np.diff(X.offsets)
    path = depth[leaves]        # internal nodes on each sample's path
    return {"nodes": int(arrays.node_count), "max_depth": int(depth.max()),
            "mean_depth": float(path.mean()), "smaller_share": smaller_share(arrays),
            "stuck_leaves": int(stuck.sum()),
            "object_visits": float(np.dot(sizes, path))}


def measure(config, n_trees, n_predict, n_types, seed):
    """Fit ``n_trees`` trees of a configuration one by one; their times and counters."""
    data_s, (X, y, bounds) = cpu_seconds(lambda: make_data(config, n_types, seed))
    X_test, _, _ = make_data(Config(config.kind, config.test_type, n_predict,
                                    config.mean_objects), n_types, seed + 1)
    trees = []
    for k in range(n_trees):
        fit_s, tree = cpu_seconds(lambda: make_tree(config.test_type, bounds, seed + k).fit(X, y))
        predict_s, _ = cpu_seconds(lambda: tree.predict(X_test))
        trees.append({"fit_s": fit_s, "predict_us": 1e6 * predict_s / n_predict,
                      **tree_counters(tree, X, y)})
    row = {key: float(np.median([t[key] for t in trees])) for key in trees[0]}
    row["ns_per_test_visit"] = 1e9 * row["fit_s"] / (K * row["object_visits"])
    row["objects_per_state"] = float(len(X.data) / len(X))
    row["data_us"] = 1e6 * data_s / len(X)
    return {**asdict(config), **row, "trees": trees}


def slope(xs, ys):
    """Least-squares slope of log(y) against log(x)."""
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


FACTORS = ("fit_s", "nodes", "mean_depth", "object_visits", "ns_per_test_visit", "predict_us")


def axis_slopes(rows, axis):
    """Slopes of each factor against ``axis`` over rows of one kind and test type."""
    return {key: slope([r[axis] for r in rows], [r[key] for r in rows]) for key in FACTORS}


def sweeps(args):
    """The measured configurations, by sweep name: (configurations, x axis)."""
    out = {}
    for test_type in args.test_types:
        out[f"synthetic {test_type}, objects"] = (
            [Config("synthetic", test_type, args.base_samples, m) for m in args.objects],
            "objects_per_state")
        out[f"synthetic {test_type}, samples"] = (
            [Config("synthetic", test_type, n, args.base_objects) for n in args.samples],
            "n_samples")
        for view in args.views:
            out[f"{view} {test_type}, samples"] = (
                [Config(view, test_type, n) for n in args.game_samples], "n_samples")
        if args.base_samples in args.game_samples:
            out[f"game {test_type} (local, global), objects"] = (
                [Config(view, test_type, args.base_samples) for view in args.views],
                "objects_per_state")
    return out


def run(args):
    """Measure every distinct configuration once; rows and per-sweep slopes."""
    plan = sweeps(args)
    configs = list(dict.fromkeys(c for cs, _ in plan.values() for c in cs))
    rows = {}
    for config in tqdm(configs, desc="configurations"):
        rows[config] = measure(config, args.trees, args.predict_samples, args.n_types, args.seed)
    slopes = {name: axis_slopes([rows[c] for c in cs], axis)
              for name, (cs, axis) in plan.items() if len(cs) > 1}
    return plan, rows, slopes


def run_estimates(rows):
    """CPU seconds of one thesis-budget treasure run per view and test type, from the rows
    measured at ``RUN_SAMPLES / ACTIONS`` samples (an even share of the actions)."""
    estimates = {}
    for config, r in rows.items():
        if config.kind not in GAME_VIEWS or config.n_samples != RUN_SAMPLES // ACTIONS:
            continue
        fit = ITERATIONS * ACTIONS * RUN_TREES * r["fit_s"]
        walks = (2 * ITERATIONS - 1) * RUN_SAMPLES * ACTIONS * RUN_TREES
        steps = 2 * ITERATIONS * RUN_SAMPLES
        estimates[f"{config.kind} {config.test_type}"] = {
            "fit_s": fit, "predict_s": 1e-6 * walks * r["predict_us"],
            "env_s": 1e-6 * steps * r["data_us"],
            "total_s": fit + 1e-6 * (walks * r["predict_us"] + steps * r["data_us"])}
    return estimates


def print_table(rows):
    """One line per configuration: medians over its trees."""
    header = (f"{'workload':<44} {'obj/state':>9} {'fit s':>7} {'nodes':>6} {'depth':>5} "
              f"{'mean d':>6} {'minor':>5} {'stuck':>5} {'visits':>9} {'ns/test.visit':>13} "
              f"{'pred us':>8}")
    print(header)
    for config, r in rows.items():
        print(f"{config.label:<44} {r['objects_per_state']:9.1f} {r['fit_s']:7.2f} "
              f"{r['nodes']:6.0f} {r['max_depth']:5.0f} {r['mean_depth']:6.1f} "
              f"{r['smaller_share']:5.3f} "
              f"{r['stuck_leaves']:5.0f} {r['object_visits']:9.3g} "
              f"{r['ns_per_test_visit']:13.3f} {r['predict_us']:8.2f}")


def print_slopes(slopes):
    """The log-log slope of each factor, one line per sweep."""
    print(f"\nlog-log slopes (1 = linear)\n{'sweep':<38}" + "".join(f"{k:>18}" for k in FACTORS))
    for name, s in slopes.items():
        print(f"{name:<38}" + "".join(f"{s[k]:18.2f}" for k in FACTORS))


def print_estimates(estimates):
    """The thesis-budget run estimates, in CPU hours."""
    if not estimates:
        return
    print(f"\none treasure FQI run at the thesis budget ({ITERATIONS} iterations x "
          f"{RUN_SAMPLES} samples, {RUN_TREES} trees x {ACTIONS} actions), CPU hours")
    for name, e in estimates.items():
        print(f"  {name:<16} fit {e['fit_s'] / 3600:6.2f}  predict {e['predict_s'] / 3600:6.2f}"
              f"  env {e['env_s'] / 3600:5.2f}  total {e['total_s'] / 3600:6.2f}")


def spaced(ticks, ratio=1.15):
    """The sorted ``ticks`` less those within ``ratio`` of the previous one kept."""
    kept = ticks[:1]
    for t in ticks[1:]:
        if t > kept[-1] * ratio:
            kept.append(t)
    return kept


def plot(plan, rows, path):
    """Fit time against objects per state and against samples, log-log, with a slope-1 line
    through the first point of each sweep."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from matplotlib.ticker import NullFormatter

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    for ax, axis in zip(axes, ("objects_per_state", "n_samples")):
        ticks = set()
        for name, (cs, sweep_axis) in plan.items():
            if sweep_axis != axis or len(cs) < 2:
                continue
            xs = np.array([rows[c][axis] for c in cs])
            ys = np.array([rows[c]["fit_s"] for c in cs])
            line, = ax.plot(xs, ys, "o-", label=name.rsplit(",", 1)[0])
            ax.plot(xs, ys[0] * xs / xs[0], ":", color=line.get_color(), alpha=0.6)
            ticks.update(np.round(xs).astype(int))
        ax.set_xscale("log")
        ax.set_yscale("log")
        ticks = spaced(sorted(ticks))
        ax.set_xticks(ticks, [f"{t:,}" for t in ticks], fontsize=8)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_ylabel("fit CPU seconds per tree")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_xlabel("objects per state (game: local and global view)")
    axes[1].set_xlabel("samples")
    fig.suptitle(f"One tree, K={K}, n_min={N_MIN} (dotted: linear growth)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def profile_one(spec, n_types, seed):
    """Grow one tree of ``KIND:TEST_TYPE:N[:OBJECTS]`` and print its CPU time."""
    kind, test_type, n, *objects = spec.split(":")
    config = Config(kind, test_type, int(n), int(objects[0]) if objects else 0)
    X, y, bounds = make_data(config, n_types, seed)
    fit_s, tree = cpu_seconds(lambda: make_tree(test_type, bounds, seed).fit(X, y))
    print(f"{config.label}: {fit_s:.2f} CPU s, {tree.tree_.node_count} nodes")


def parse_args():
    """The command line (see the module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--objects", type=int, nargs="*", default=[16, 64, 256, 360],
                        help="mean objects per state of the synthetic objects sweep")
    parser.add_argument("--base-samples", type=int, default=20000,
                        help="samples of the objects sweep")
    parser.add_argument("--samples", type=int, nargs="*", default=[5000, 20000, 80000],
                        help="samples of the synthetic samples sweep")
    parser.add_argument("--base-objects", type=int, default=16,
                        help="mean objects per state of the samples sweep")
    parser.add_argument("--views", nargs="*", default=list(GAME_VIEWS), choices=GAME_VIEWS,
                        help="treasure-game views measured")
    parser.add_argument("--game-samples", type=int, nargs="*", default=[5000, 20000])
    parser.add_argument("--test-types", nargs="+", default=["fixed", "random"],
                        choices=["fixed", "bounded", "random", "classic"])
    parser.add_argument("--n-types", type=int, default=4, help="types of the synthetic sets")
    parser.add_argument("--trees", type=int, default=2, help="trees per configuration")
    parser.add_argument("--predict-samples", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="results", help="output folder")
    parser.add_argument("--one", metavar="KIND:TEST_TYPE:N[:OBJECTS]",
                        help="grow one tree (KIND: synthetic, local or global) and exit")
    return parser.parse_args()


def main():
    """Measure, print, and write the JSON and the plot (or grow the one tree of ``--one``)."""
    args = parse_args()
    if args.one:
        profile_one(args.one, args.n_types, args.seed)
        return
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    plan, rows, slopes = run(args)
    print_table(rows)
    print_slopes(slopes)
    estimates = run_estimates(rows)
    print_estimates(estimates)
    result = {"params": {"n_tests": K, "min_samples_split": N_MIN, "test_width": TEST_WIDTH,
                         **{k: v for k, v in vars(args).items() if k not in ("out", "one")}},
              "machine": {"python": platform.python_version(), "machine": platform.machine()},
              "rows": list(rows.values()), "slopes": slopes, "run_estimates": estimates}
    (out / "bench_scaling.json").write_text(json.dumps(result, indent=1))
    plot(plan, rows, out / "bench_scaling.png")
    print(f"\nwrote {out / 'bench_scaling.json'} and {out / 'bench_scaling.png'}")


if __name__ == "__main__":
    main()
