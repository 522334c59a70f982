"""The ceiling of the 4-action and sword games: `envs.LookaheadPlanner` on the reference worlds.

The planner plays with the simulator in hand: it copies each world's whole state, move noise
included, and searches action sequences on the copies. It is an upper reference, not a
learner; learners' scores read as fractions of its score. Every score is the total reward of
one 50-step episode on each of the first ``--episodes`` reference worlds
(`envs.reference_worlds`; 400 episodes are the thesis's 20,000 evaluation steps), next to the
greedy heuristic (`envs.GreedyPolicy`), the uniform random policy (action seed 0) and the
thesis's human player (about 150,000 over 400 episodes, 4-action game only).

First a budget sweep on the first ``--sweep-episodes`` worlds: each ``--sweep`` setting is
``DEPTHxWIDTH`` (search depth x sequences kept per level), its compute the world steps the
search simulates per decision. Then the ``--depth``/``--width`` setting on ``--episodes``
worlds. Times: wall and CPU seconds of the planner (numpy on one core). Prints tables and
writes, under ``--out``, ``bench_planner_sweep_<game>.json`` and ``.png`` (reward vs simulated
steps per decision) for the sweep and ``bench_planner_<game>.json`` for the chosen setting.

    python -m benchmarks.bench_planner [--games 4-actions sword] [--episodes 400]
        [--depth 5] [--width 16] [--sweep-episodes 40] [--sweep 1x1 2x4 3x4 5x16 8x16 8x64]
        [--out results]
"""
import argparse
import json
import platform
import re
import sys
import time
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

import envs

from .calibrate_env import policy_totals

GAMES = {"4-actions": {}, "sword": {"sword": True}}
HUMAN_PER_EPISODE = {"4-actions": 150_000 / 400}  # thesis: about 150,000 over 400 episodes
DEFAULT_SWEEP = ["1x1", "2x4", "3x4", "5x16", "8x16", "8x64"]


def budget(text):
    """A ``DEPTHxWIDTH`` sweep setting as ``(depth, width)``, for argparse."""
    match = re.fullmatch(r"([1-9][0-9]*)x([1-9][0-9]*)", text)
    if match is None:
        raise argparse.ArgumentTypeError(f"expected DEPTHxWIDTH with positive ints, e.g. 5x16; "
                                         f"got {text!r}")
    return int(match[1]), int(match[2])


def planner_run(game, seeds, depth, width):
    """Play one episode per world of `seeds` with the planner; its totals, times and compute."""
    planner = envs.LookaheadPlanner(depth=depth, width=width)
    worlds = envs.BatchedObjectWorld(len(seeds), **GAMES[game])
    worlds.reset(seed=seeds)
    totals = np.zeros(len(seeds))
    wall, cpu = time.perf_counter(), time.process_time()
    for _ in tqdm(range(worlds.rules.max_steps), desc=f"{game} {depth}x{width}",
                  unit="step", leave=False):
        totals += worlds.step(planner.act(worlds))[1]
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    decisions = len(seeds) * worlds.rules.max_steps
    return {"depth": depth, "width": width, "route_width": planner.route_width,
            "discount": planner.discount, "episodes": len(seeds), "total": float(totals.sum()),
            "mean": float(totals.mean()),
            "se": float(totals.std(ddof=1) / np.sqrt(len(seeds))) if len(seeds) > 1 else None,
            "wall_s": wall, "cpu_s": cpu,
            "simulated_steps_per_decision": planner.simulated_steps / decisions,
            "per_episode": totals.tolist()}


def baselines(game, seeds):
    """Totals of the greedy heuristic, the random policy and (4 actions) the human on `seeds`."""
    human = HUMAN_PER_EPISODE.get(game)
    return {"greedy": float(policy_totals(GAMES[game], seeds, "greedy").sum()),
            "random": float(policy_totals(GAMES[game], seeds, "random").sum()),
            "human": None if human is None else human * len(seeds)}


def print_sweep(game, rows, reference):
    print(f"\n{game}: budget sweep on {rows[0]['episodes']} reference episodes "
          f"(greedy {reference['greedy']:,.0f})")
    print(f"{'depth x width':>13} {'total':>10} {'mean +- se':>16} {'/ greedy':>9} "
          f"{'sim. steps':>11} {'wall s':>8} {'cpu s':>8}")
    for row in rows:
        spread = f"{row['mean']:.1f} +- {row['se'] or 0:.1f}"
        print(f"{row['depth']:>7}x{row['width']:<5} {row['total']:>10,.0f} {spread:>16} "
              f"{row['total'] / reference['greedy']:>9.2f} "
              f"{row['simulated_steps_per_decision']:>11,.0f} {row['wall_s']:>8.1f} "
              f"{row['cpu_s']:>8.1f}")


def print_full(game, row, reference):
    ceiling = row["total"]
    steps = envs.WorldRules(**GAMES[game]).max_steps * row["episodes"]
    print(f"\n{game}: {row['episodes']} reference episodes ({steps:,} steps), "
          f"planner {row['depth']}x{row['width']} in {row['wall_s']:.0f} s wall, "
          f"{row['cpu_s']:.0f} s CPU")
    print(f"{'player':<26} {'total':>12} {'per episode':>12} {'of planner':>11}")
    players = [(f"planner {row['depth']}x{row['width']} (ceiling)", ceiling),
               ("greedy heuristic", reference["greedy"]),
               ("human (thesis, about)", reference["human"]),
               ("random (action seed 0)", reference["random"])]
    for name, total in players:
        if total is None:
            print(f"{name:<26} {'-':>12} {'-':>12} {'-':>11}")
        else:
            print(f"{name:<26} {total:>12,.0f} {total / row['episodes']:>12.1f} "
                  f"{total / ceiling:>11.1%}")


def plot(path, game, rows, reference):
    """Mean reward per episode vs simulated steps per decision, the greedy (human) lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    x = [row["simulated_steps_per_decision"] for row in rows]
    ax.errorbar(x, [row["mean"] for row in rows], yerr=[row["se"] or 0 for row in rows],
                marker="o", capsize=3, label="look-ahead planner")
    for row, xi in zip(rows, x):
        ax.annotate(f"{row['depth']}x{row['width']}", (xi, row["mean"]),
                    textcoords="offset points", xytext=(4, -12), fontsize=8)
    n = rows[0]["episodes"]
    ax.axhline(reference["greedy"] / n, color="tab:orange", ls="--", label="greedy heuristic")
    if reference["human"] is not None:
        ax.axhline(reference["human"] / n, color="tab:green", ls=":", label="human (thesis)")
    ax.set_xscale("log")
    ax.margins(x=0.15)
    ax.set_xlabel("simulated world steps per decision")
    ax.set_ylabel(f"mean reward per episode ({n} episodes)")
    ax.set_title(f"{game}: reward vs search budget")
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--games", nargs="+", choices=list(GAMES), default=list(GAMES))
    parser.add_argument("--episodes", type=int, default=400,
                        help="reference episodes of the chosen setting (0: none)")
    parser.add_argument("--depth", type=int, default=5, help="search depth of the chosen setting")
    parser.add_argument("--width", type=int, default=16, help="beam width of the chosen setting")
    parser.add_argument("--sweep-episodes", type=int, default=40,
                        help="reference episodes of the budget sweep (0: no sweep)")
    parser.add_argument("--sweep", nargs="+", type=budget, default=None, metavar="DEPTHxWIDTH",
                        help=f"settings of the sweep (default {' '.join(DEFAULT_SWEEP)})")
    parser.add_argument("--out", default="results", help="directory of the JSON and PNG files")
    args = parser.parse_args()
    for name in ("episodes", "sweep_episodes"):
        if not 0 <= getattr(args, name) <= 400:
            parser.error(f"--{name.replace('_', '-')} must lie in [0, 400] (there are 400 "
                         f"reference worlds), got {getattr(args, name)}")
    if args.episodes == args.sweep_episodes == 0:
        parser.error("nothing to run: --episodes and --sweep-episodes are both 0")
    try:
        envs.LookaheadPlanner(depth=args.depth, width=args.width)
    except (TypeError, ValueError) as error:
        parser.error(str(error))
    sweep = args.sweep or [budget(text) for text in DEFAULT_SWEEP]
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        parser.error(f"cannot write to --out {args.out!r}: {error.strerror}")

    for game in args.games:
        common = {"benchmark": "bench_planner", "game": game, "rules": GAMES[game],
                  "note": "upper reference, not a learner: the planner copies the whole world "
                          "state, move noise included, and searches on the copies",
                  "worlds": "the first n of envs.reference_worlds", "command": sys.argv[1:],
                  "python": platform.python_version(), "numpy": np.__version__,
                  "machine": platform.machine()}
        if args.sweep_episodes:
            seeds = envs.reference_worlds(args.sweep_episodes)
            reference = baselines(game, seeds)
            rows = [planner_run(game, seeds, depth, width) for depth, width in sweep]
            print_sweep(game, rows, reference)
            path = out / f"bench_planner_sweep_{game}.json"
            path.write_text(json.dumps({**common, "baselines": reference, "rows": rows},
                                       indent=2))
            plot(path.with_suffix(".png"), game, rows, reference)
            print(f"wrote {path} and {path.with_suffix('.png')}")
        if args.episodes:
            seeds = envs.reference_worlds(args.episodes)
            reference = baselines(game, seeds)
            row = planner_run(game, seeds, args.depth, args.width)
            print_full(game, row, reference)
            path = out / f"bench_planner_{game}.json"
            path.write_text(json.dumps({**common, "baselines": reference, **row}, indent=2))
            print(f"wrote {path}")


if __name__ == "__main__":
    main()
