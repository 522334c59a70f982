"""Steps per second of the ObjectWorld env: single gymnasium env vs the batched engine.

Both run the uniform random policy (actions drawn beforehand, so only the env is timed),
resetting every episode (50 steps). The single env is timed as the raw class and through
``gymnasium.make`` (which adds the passive checker, order-enforcing and time-limit
wrappers); the ratio uses the raw class, the faster of the two.

Prints a table and writes ``bench_env.json`` under ``--out``.

    python -m benchmarks.bench_env [--out results] [--steps 20000] [--worlds 400]
"""
import argparse
import json
import platform
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

import envs

VARIANTS = {"4 actions": {}, "sword": {"sword": True},
            "treasure (minimap)": {"treasure": True, "view": "minimap"}}


def single_steps_per_s(env, n_steps, seed=0):
    """Steps/s of one env under the random policy, resets included."""
    actions = np.random.default_rng(seed).integers(env.action_space.n, size=n_steps)
    env.reset(seed=seed)
    start = time.perf_counter()
    for action in actions:
        truncated = env.step(action)[3]
        if truncated:
            env.reset()
    return n_steps / (time.perf_counter() - start)


def batched_steps_per_s(n_worlds, n_batch_steps, rules, seed=0):
    """World-steps/s of `BatchedObjectWorld` under the random policy, resets included."""
    worlds = envs.BatchedObjectWorld(n_worlds, **rules)
    actions = np.random.default_rng(seed).integers(
        worlds.rules.n_actions, size=(n_batch_steps, n_worlds))
    worlds.reset(seed=seed)
    start = time.perf_counter()
    for batch in actions:
        truncated = worlds.step(batch)[3]
        if truncated[0]:
            worlds.reset()
    return n_worlds * n_batch_steps / (time.perf_counter() - start)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results", help="directory of bench_env.json")
    parser.add_argument("--steps", type=int, default=20_000, help="single-env steps per variant")
    parser.add_argument("--worlds", type=int, default=400, help="worlds of the batched env")
    parser.add_argument("--batch-steps", type=int, default=500,
                        help="batched steps per variant (10 episodes by default)")
    args = parser.parse_args()

    rows = []
    print(f"{'variant':<20} {'single raw':>12} {'gym.make':>12} "
          f"{'batched x' + str(args.worlds):>14} {'ratio':>7}   (steps/s)")
    for name, rules in VARIANTS.items():
        raw = single_steps_per_s(envs.ObjectWorldEnv(**rules), args.steps)
        made = single_steps_per_s(gym.make("ObjectWorld-v0", **rules), args.steps)
        batched = batched_steps_per_s(args.worlds, args.batch_steps, rules)
        rows.append({"variant": name, "rules": rules, "single_steps_per_s": raw,
                     "gym_make_steps_per_s": made, "n_worlds": args.worlds,
                     "batched_steps_per_s": batched, "ratio": batched / raw})
        print(f"{name:<20} {raw:>12,.0f} {made:>12,.0f} {batched:>14,.0f} {batched / raw:>6.0f}x")

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report = {"benchmark": "bench_env", "policy": "uniform random",
              "single_steps": args.steps, "batched_steps": args.batch_steps,
              "python": platform.python_version(), "numpy": np.__version__,
              "machine": platform.machine(), "results": rows}
    (out / "bench_env.json").write_text(json.dumps(report, indent=2))
    print(f"wrote {out / 'bench_env.json'}")


if __name__ == "__main__":
    main()
