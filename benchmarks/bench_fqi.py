"""FQI on ObjectWorld-v0 at thesis scale: time per phase, reward curve, baselines, DQN.

The thesis run: box FQI with fixed boxes (M=30 trees, K=500 tests, n_min=30, TW=1,
``n_jobs=-1``), 20 iterations of 20,000 samples in the "normal" regime (new data every
iteration), evaluated after every iteration by the total greedy reward over 20,000 steps on
the 400 reference worlds. Further runs (``--runs``) use the same budget: the thesis's
"mixed" regime (``box-mixed``), kept data (``box-keep``), offline FQI (``box-offline``),
grid + ridge (``grid-ridge``), classic trees (``classic``) and stable-baselines3 DQN on the
10x10 grid observation with as many env steps (``dqn``, ``--dqn-steps``). Every FQI run is a
setting of the experiment registry (``benchmarks/reproduce/registry.py``), built as
``run_all.py`` builds it, so the two cannot drift apart.

Prints the phase times of every iteration and a summary, writes ``bench_fqi.json`` and the
reward curves ``bench_fqi.png`` under ``--out``.

    python -m benchmarks.bench_fqi                          # box + dqn, thesis scale
    python -m benchmarks.bench_fqi --runs box box-mixed box-keep --dqn-steps 100000
    python -m benchmarks.bench_fqi --quick                  # small smoke run
"""
import argparse
import json
import platform
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import envs
from fqi import RandomPolicy, evaluate

from .reproduce.budgets import BUDGETS
from .reproduce.kinds import KINDS
from .reproduce.kinds._game import make_agent
from .reproduce.registry import REGISTRY
from .reproduce.units import Unit, run_unit

ENV = "ObjectWorld-v0"
REFERENCE_WORLDS = envs.reference_worlds(400)  # the thesis's 400 evaluation episodes of 50 steps
PHASES = ("t_collect", "t_targets", "t_fit", "t_evaluate")
# each run: (experiment, setting) of the registry, and what it changes on top of it
FQI_RUNS = {
    "box": ("representations", "fixed TW=1", {}),
    "box-mixed": ("sampling", "mixed (every 5)", {}),
    "box-keep": ("keep_data", "keep data (100k)", {}),
    "box-offline": ("representations", "fixed TW=1", {"resample_every": None}),
    "grid-ridge": ("representations", "grid 10 + ridge", {}),
    "classic": ("representations", "classic", {}),
}
DQN_RUN = ("dqn", "DQN (grid 10 obs)")
THESIS_LEVEL, HUMAN_LEVEL = 100_000, 150_000


def run_fqi(name, iterations, samples, seed):
    """One FQI run; returns its summary with the per-iteration records."""
    experiment, label, changes = FQI_RUNS[name]
    params = {**REGISTRY[experiment].params(label), **changes}
    agent = make_agent(KINDS["fqi"].settings(params), BUDGETS["full"], seed, samples)
    print(f"\n== {name}: {agent!r}")
    print(f"{'it':>3} {'reward':>10} {'samples':>8} {'nodes/tree':>10} "
          + " ".join(f"{p[2:]:>9}" for p in PHASES) + f" {'total':>7}")

    def show(locals_, globals_):
        r = locals_["record"]
        print(f"{r['iteration']:>3} {r['reward']:>10,.0f} {r['n_samples']:>8,d} "
              f"{r['nodes_per_tree']:>10.0f} " + " ".join(f"{r[p]:>8.2f}s" for p in PHASES)
              + f" {r['t_total']:>6.2f}s", flush=True)

    start = time.perf_counter()
    agent.learn(n_iterations=iterations, callback=show)
    seconds = time.perf_counter() - start
    curve = [r["reward"] for r in agent.history]
    return {"name": name, "kind": "fqi", "params": {k: str(v) for k, v in params.items()},
            "regressor": repr(agent.regressor), "gamma": agent.gamma,
            "reward_curve": curve, "last5_mean": float(np.mean(curve[-5:])),
            "max": float(max(curve)), "seconds": seconds, "env_steps": agent.num_timesteps,
            "phase_seconds": {p: float(sum(r[p] for r in agent.history)) for p in PHASES},
            "history": agent.history}


def run_dqn(steps, seed):
    """The registry's DQN setting (stable-baselines3 DQN on 10 x 10 grid counts) for
    `steps` environment steps, scored on the 400 reference worlds."""
    print(f"\n== dqn: stable-baselines3 DQN on GridObservation(n_bins=10), {steps:,} steps")
    budget, (experiment, label) = replace(BUDGETS["full"], dqn_steps=steps), DQN_RUN
    result = run_unit(Unit(experiment, label, seed, REGISTRY[experiment].params(label, budget),
                           budget.samples, budget, path=None))
    print(f"reward {result['reward']:,.0f}  train {result['train_seconds']:.1f}s  "
          f"evaluate {result['eval_seconds']:.1f}s", flush=True)
    return {"name": "dqn", "kind": "dqn", "reward": result["reward"],
            "seconds": result["seconds"], "train_seconds": result["train_seconds"],
            "eval_seconds": result["eval_seconds"], "env_steps": steps}


def plot(runs, anchors, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5))
    for run in runs:
        if run["kind"] == "fqi":
            ax.plot(run["reward_curve"], marker="o", ms=3, label=run["name"])
        else:
            ax.axhline(run["reward"], color="tab:purple", ls="--",
                       label=f"DQN ({run['env_steps']:,} steps)")
    for label, value, style in [("random policy", anchors["random"], ":"),
                                ("thesis box FQI (~100k)", THESIS_LEVEL, "-."),
                                ("thesis human (~150k)", HUMAN_LEVEL, "--")]:
        ax.axhline(value, color="grey", ls=style, lw=1, label=label)
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.set_xlabel("iteration")
    ax.set_ylabel("reward over 20,000 greedy steps (reference worlds)")
    ax.set_title("Fitted Q-iteration on ObjectWorld-v0")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", nargs="+", default=["box", "dqn"],
                        choices=[*FQI_RUNS, "dqn"])
    parser.add_argument("--iterations", type=int, default=20)
    parser.add_argument("--samples", type=int, default=20_000)
    parser.add_argument("--dqn-steps", type=int, default=None,
                        help="DQN env steps (default: iterations x samples)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--quick", action="store_true",
                        help="smoke run: 3 iterations of 2,000 samples, 2,000 DQN steps")
    parser.add_argument("--out", default="results")
    args = parser.parse_args()
    if args.quick:
        args.iterations, args.samples = 3, 2_000
        args.dqn_steps = args.dqn_steps or 2_000
    dqn_steps = args.dqn_steps or args.iterations * args.samples

    anchors = {"random": evaluate(RandomPolicy(ENV, seed=0), ENV, seeds=REFERENCE_WORLDS).total,
               "greedy_heuristic": evaluate(envs.GreedyPolicy(envs.BatchedObjectWorld(1)), ENV,
                                            seeds=REFERENCE_WORLDS).total}
    print(f"random policy {anchors['random']:,.0f}, greedy heuristic "
          f"{anchors['greedy_heuristic']:,.0f} (reward over 20,000 reference steps)")
    runs = [run_dqn(dqn_steps, args.seed) if name == "dqn"
            else run_fqi(name, args.iterations, args.samples, args.seed) for name in args.runs]

    print(f"\n{'run':<12} {'last-5 mean':>12} {'max':>10} {'seconds':>8} {'env steps':>10}  "
          "time per phase (s)")
    for run in runs:
        if run["kind"] == "fqi":
            phases = " ".join(f"{p[2:]} {v:.1f}" for p, v in run["phase_seconds"].items())
            print(f"{run['name']:<12} {run['last5_mean']:>12,.0f} {run['max']:>10,.0f} "
                  f"{run['seconds']:>8.1f} {run['env_steps']:>10,d}  {phases}")
        else:
            print(f"{run['name']:<12} {run['reward']:>12,.0f} {'':>10} {run['seconds']:>8.1f} "
                  f"{run['env_steps']:>10,d}  train {run['train_seconds']:.1f} "
                  f"evaluate {run['eval_seconds']:.1f}")

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report = {"benchmark": "bench_fqi", "env": ENV, "args": vars(args), "anchors": anchors,
              "goals": {"seconds_per_run": 180, "last5_mean": THESIS_LEVEL,
                        "human": HUMAN_LEVEL},
              "python": platform.python_version(), "machine": platform.machine(),
              "runs": runs}
    (out / "bench_fqi.json").write_text(json.dumps(report, indent=2))
    plot(runs, anchors, out / "bench_fqi.png")
    print(f"wrote {out / 'bench_fqi.json'} and {out / 'bench_fqi.png'}")


if __name__ == "__main__":
    main()
