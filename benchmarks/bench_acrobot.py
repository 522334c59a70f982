"""Acrobot-v1: exploratory FQI settings against the tuned DQN, in environment steps to -100.

Variations of the registry's ``control_acrobot`` setting with one forest over observation
and action (whose runs ``run_all --only control_acrobot`` makes, stopped at 50,000 steps):
its FQI arguments (20 `leaf_backups`, 4 envs, random actions held for zeta(3)-distributed
durations, ``action_input``) with ``--trees`` grown-out Extra-Trees, or one forest per
action (``--per-action``), learn on the schedule of DQN's 100,000 steps and stop at
``--stop`` steps. Every 5,000 steps its
greedy policy plays 20 held-out episodes, as the registry's ``control`` kind scores its runs
(`benchmarks.training.EvalCallback` on a synchronous vector env, `fqi.evaluate`'s default
seeds). Printed and written per seed: the curve and the first evaluation at or above -100;
beside them, the same figure of the registry's tuned DQN runs when they are cached under
``--results`` (``control_acrobot``).

    python -m benchmarks.bench_acrobot --seeds 0 1 2 3 4 --trees 150 --out docs/results/acrobot
    python -m benchmarks.bench_acrobot --seeds 0 --trees 5 --stop 1000 --out /tmp/acrobot

Writes ``bench_acrobot.json`` and ``bench_acrobot.png`` (return against steps) under
``--out``; seeds run in parallel processes (``--jobs``), one core each.
"""
import argparse
import json
from pathlib import Path

import gymnasium as gym
from joblib import Parallel, delayed
from sklearn.ensemble import ExtraTreesRegressor

from fqi import FQI

from .reproduce.budgets import BUDGETS
from .reproduce.cache import unit_path
from .reproduce.kinds import KINDS
from .reproduce.registry import ACTION_INPUT_LABEL, REGISTRY
from .reproduce.stats import median_steps, steps_to_threshold
from .training import EvalCallback, StopAt, timed_learn

SETTING = KINDS["control"].settings(REGISTRY["control_acrobot"].params(ACTION_INPUT_LABEL))
ENV, THRESHOLD, BUDGET = SETTING.env_id, SETTING.threshold, SETTING.steps
# the registry's tuned-DQN runs, under --results
DQN_RUNS = unit_path("", BUDGETS["full"], "control_acrobot", "DQN (rl-zoo3)", 0).parent


def run_seed(seed, n_trees, stop, action_input):
    """One FQI run; its curve, first crossing and training seconds."""
    agent = FQI(ExtraTreesRegressor(n_estimators=n_trees), ENV,
                **{**SETTING.fqi, "action_input": action_input}, eval_episodes=0, seed=seed)
    evaluation = gym.make_vec(ENV, SETTING.eval_episodes, vectorization_mode="sync")
    curve = EvalCallback(evaluation, SETTING.eval_every, n_episodes=SETTING.eval_episodes)
    seconds, _ = timed_learn(agent, [curve, StopAt(stop)], total_timesteps=BUDGET)
    evaluation.close()
    return {"seed": seed, "curve": curve.evaluations,
            "first_crossing": steps_to_threshold(curve.evaluations, THRESHOLD),
            "train_seconds": seconds}


def dqn_crossings(results):
    """Seed -> first crossing of the registry's cached tuned-DQN runs (empty without them)."""
    return {int(path.stem.removeprefix("seed")):
            json.loads(path.read_text())["result"]["steps_to_threshold"]
            for path in sorted((Path(results) / DQN_RUNS).glob("seed*.json"))}


def plot(runs, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    for run in runs:
        steps, values = zip(*run["curve"])
        ax.plot(steps, values, marker="o", label=f"seed {run['seed']}")
    ax.axhline(THRESHOLD, color="k", ls="--", lw=1, label="threshold")
    ax.set(xlabel="environment steps",
           ylabel=f"mean return ({SETTING.eval_episodes} held-out episodes)",
           title=f"FQI on {ENV}", ylim=(-510, -50))
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2, 3, 4])
    parser.add_argument("--trees", type=int, default=150)
    parser.add_argument("--stop", type=int, default=25_000, help="steps at which to stop")
    parser.add_argument("--per-action", action="store_true",
                        help="a forest per action instead of action_input")
    parser.add_argument("--jobs", type=int, default=2, help="seeds run in parallel")
    parser.add_argument("--results", default="docs/results",
                        help="the registry's results folder, for the DQN runs")
    parser.add_argument("--out", default="results/acrobot")
    args = parser.parse_args(argv)
    runs = Parallel(n_jobs=args.jobs)(
        delayed(run_seed)(seed, args.trees, args.stop, not args.per_action)
        for seed in args.seeds)
    dqn = dqn_crossings(args.results)
    print(f"{'seed':>4} {'first past -100':>16} {'DQN':>8} {'train s':>8}  curve")
    for run in runs:
        crossing = run["first_crossing"]
        print(f"{run['seed']:>4} {crossing or 'not':>16} {dqn.get(run['seed']) or '-':>8} "
              f"{run['train_seconds']:>8.0f}  "
              + " ".join(f"{value:.1f}" for _, value in run["curve"]))
    fqi_median = median_steps([run["first_crossing"] for run in runs])
    dqn_median = median_steps(list(dqn.values()))
    print("median first crossing: "
          + ", ".join(f"{who} {'not reached' if steps is None else f'{steps:,.0f}'}"
                      for who, steps in (("FQI", fqi_median), ("DQN", dqn_median))))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    summary = {"env": ENV, "threshold": THRESHOLD, "budget": BUDGET, "stop": args.stop,
               "trees": args.trees, "action_input": not args.per_action,
               "fqi_median": fqi_median, "dqn_first_crossing": dqn,
               "dqn_median": dqn_median,
               "runs": runs}
    (out / "bench_acrobot.json").write_text(json.dumps(summary, indent=1))
    plot(runs, out / "bench_acrobot.png")
    print(f"wrote {out / 'bench_acrobot.json'} and {out / 'bench_acrobot.png'}")
    return summary


if __name__ == "__main__":
    main()
