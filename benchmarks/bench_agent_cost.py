"""What FQI costs per environment step: seconds and threads started per 10,000 CartPole-v1
steps, by regressor, with the evaluation off (FQI's default) and on; and whether FQI's
defaults solve CartPole-v1 within 50,000 steps and 3 minutes.

An agent predicts once per environment step (collection, evaluation, `FQI.predict`), so a
regressor that starts threads on each call (scikit-learn's forests with ``n_jobs``, through
joblib) or an evaluation played after every iteration costs more than the learning. This
benchmark learns 10,000 steps of CartPole-v1 with FQI's defaults (16 envs, 2,500 samples
per round, 5 backups per round) and each regressor:

- scikit-learn's ``ExtraTreesRegressor(n_estimators=30)`` with ``n_jobs`` 1, 2 and -1;
- ``boxtrees.BoxExtraTreesRegressor(n_estimators=30)`` (a feature matrix: classic tests)
  with ``n_jobs`` 1 and -1;
- ``make_pipeline(StandardScaler(), Ridge())``;

once with no evaluation and once with 10 evaluation episodes after every iteration
(``eval_episodes=10``), counting the threads started during ``learn``. Then the
``solve`` runs: ``FQI(ExtraTreesRegressor(n_estimators=30, n_jobs=2), "CartPole-v1",
seed=s).learn(50_000)`` on held-out seeds, their seconds and the greedy policy's mean
return over 20 held-out episodes (CartPole-v1 counts 475 as solved, 500 at most). Run::

    python -m benchmarks.bench_agent_cost

It writes ``bench_agent_cost.json`` and ``bench_agent_cost.png`` under ``--out``.
``--quick`` learns 2,000 steps of each setting and skips the solve runs.
"""
import argparse
import json
import os
import platform
import threading
import time
from pathlib import Path

import numpy as np
from sklearn.ensemble import ExtraTreesRegressor
from sklearn.linear_model import Ridge
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from boxtrees import BoxExtraTreesRegressor
from fqi import FQI, evaluate

ENV = "CartPole-v1"
STEPS = 10_000
QUICK_STEPS = 2_000
SOLVE_STEPS = 50_000
SOLVE_SEEDS = (11, 12, 13)
SOLVED = 475.0
EVAL_EPISODES = 10
REGRESSORS = {
    "ExtraTrees n_jobs=1": lambda: ExtraTreesRegressor(n_estimators=30, n_jobs=1),
    "ExtraTrees n_jobs=2": lambda: ExtraTreesRegressor(n_estimators=30, n_jobs=2),
    "ExtraTrees n_jobs=-1": lambda: ExtraTreesRegressor(n_estimators=30, n_jobs=-1),
    "box forest n_jobs=1": lambda: BoxExtraTreesRegressor(n_estimators=30, n_jobs=1),
    "box forest n_jobs=-1": lambda: BoxExtraTreesRegressor(n_estimators=30, n_jobs=-1),
    "Ridge pipeline": lambda: make_pipeline(StandardScaler(), Ridge()),
}


class _ThreadStarts:
    """Counts the threads started while it is entered."""

    def __enter__(self):
        self.count, self._start = 0, threading.Thread.start

        def counted(thread, *args, **kwargs):
            self.count += 1
            return self._start(thread, *args, **kwargs)

        threading.Thread.start = counted
        return self

    def __exit__(self, *exc_info):
        threading.Thread.start = self._start


def cost(name, steps, eval_episodes, seed=0):
    """An agent made and taught ``learn(steps)``: seconds, threads started (the
    construction's trial fit included), and the seconds per 10,000 steps."""
    with _ThreadStarts() as threads:
        start = time.perf_counter()
        agent = FQI(REGRESSORS[name](), ENV, eval_episodes=eval_episodes, seed=seed)
        agent.learn(total_timesteps=steps)
        seconds = time.perf_counter() - start
    agent.get_env().close()
    scale = STEPS / agent.num_timesteps
    row = {"regressor": name, "evaluation": bool(eval_episodes), "steps": agent.num_timesteps,
           "seconds": seconds, "threads_started": threads.count,
           "seconds_per_10k_steps": seconds * scale,
           "t_evaluate": sum(r["t_evaluate"] for r in agent.history),
           "t_collect": sum(r["t_collect"] for r in agent.history),
           "t_fit": sum(r["t_fit"] for r in agent.history)}
    print(f"  {name:<22} evaluation {'on ' if eval_episodes else 'off'}  "
          f"{row['seconds_per_10k_steps']:7.1f} s per 10k steps  "
          f"{threads.count:5d} threads started  (evaluate {row['t_evaluate']:.1f} s)")
    return row


def solve(seed):
    """FQI's defaults with a 2-job forest for `SOLVE_STEPS` steps: seconds and the greedy
    policy's mean return on 20 held-out episodes."""
    agent = FQI(ExtraTreesRegressor(n_estimators=30, n_jobs=2), ENV, seed=seed)
    start = time.perf_counter()
    agent.learn(total_timesteps=SOLVE_STEPS)
    seconds = time.perf_counter() - start
    agent.get_env().close()
    result = evaluate(agent, ENV, n_episodes=20)
    row = {"seed": seed, "seconds": seconds, "mean_return": result.mean,
           "solved": result.mean >= SOLVED}
    print(f"  seed {seed}: {seconds:6.1f} s, mean return {result.mean:6.1f}")
    return row


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(dict.fromkeys(r["regressor"] for r in rows))
    fig, ax = plt.subplots(figsize=(7, 3.6))
    y = np.arange(len(names))
    for offset, evaluation, colour in ((-0.2, False, "tab:blue"), (0.2, True, "tab:orange")):
        seconds = [next(r["seconds_per_10k_steps"] for r in rows
                        if r["regressor"] == n and r["evaluation"] == evaluation) for n in names]
        ax.barh(y + offset, seconds, height=0.38, color=colour,
                label=f"evaluation {'on (10 episodes per iteration)' if evaluation else 'off'}")
    ax.set_yticks(y, names)
    ax.invert_yaxis()
    ax.set_xlabel("seconds per 10,000 CartPole-v1 steps")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help=f"{QUICK_STEPS:,} steps per setting, no solve runs")
    parser.add_argument("--out", default="results", help="output folder")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    steps = QUICK_STEPS if args.quick else STEPS

    print(f"FQI's defaults on {ENV}, {steps:,} steps per setting:")
    rows = [cost(name, steps, eval_episodes)
            for name in REGRESSORS for eval_episodes in (0, EVAL_EPISODES)]
    solves = []
    if not args.quick:
        print(f"FQI(ExtraTreesRegressor(n_estimators=30, n_jobs=2), {ENV!r}) for "
              f"{SOLVE_STEPS:,} steps, held-out seeds:")
        solves = [solve(seed) for seed in SOLVE_SEEDS]
    summary = {
        "max_threads_started": max(r["threads_started"] for r in rows),
        "solve_seconds_max": max((s["seconds"] for s in solves), default=None),
        "solved_runs": sum(s["solved"] for s in solves), "solve_runs": len(solves),
    }
    if solves:
        print(f"solved {summary['solved_runs']} of {len(solves)} runs (mean return >= "
              f"{SOLVED:.0f}); slowest {summary['solve_seconds_max']:.1f} s (goal: <= 180 s)")
    print(f"threads started in any run: at most {summary['max_threads_started']}")
    load = os.getloadavg()[1]
    report = {"env": ENV, "steps": steps, "rows": rows, "solves": solves, "summary": summary,
              "cpu_count": os.cpu_count(), "load_average_5min": load,
              "machine": platform.machine(), "python": platform.python_version()}
    (out / "bench_agent_cost.json").write_text(json.dumps(report, indent=2))
    plot(rows, out / "bench_agent_cost.png")
    print(f"wrote {out / 'bench_agent_cost.json'} and {out / 'bench_agent_cost.png'}")


if __name__ == "__main__":
    main()
