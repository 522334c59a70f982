"""Calibration of the ObjectWorld defaults: random-policy and heuristic scores.

Every score is the total reward over 20,000 steps: one 50-step episode on each of the 400
reference worlds (`envs.reference_worlds(400)`), as the thesis evaluates. The uniform random
policy is run with several action seeds (the first one is the headline figure); the greedy
heuristic (`envs.GreedyPolicy`) is deterministic. Thesis anchors: random about -100,000
(4 actions) and about -6,000,000 (sword); the issue asks for [-120,000, -80,000] and
-6,000,000 +- 30 %.

Prints a table and writes ``calibrate_env.json`` under ``--out``.

    python -m benchmarks.calibrate_env [--out results] [--policy-seeds 5]
"""
import argparse
import json
from pathlib import Path

import numpy as np

import envs

N_WORLDS = 400
VARIANTS = {
    "4 actions": ({}, (-120_000, -80_000)),
    "sword": ({"sword": True}, (-7_800_000, -4_200_000)),
    "treasure (local)": ({"treasure": True}, None),
}


def policy_totals(rules, seeds, policy, seed=0):
    """Per-episode totals of `policy` ("random", with action seed `seed`, or "greedy", the
    deterministic `envs.GreedyPolicy`): one episode on the world of each reset seed of
    `seeds`, under the `envs.WorldRules` keywords `rules`. Also used by bench_planner.py."""
    if policy not in ("random", "greedy"):
        raise ValueError(f"policy must be 'random' or 'greedy', got {policy!r}")
    worlds = envs.BatchedObjectWorld(len(seeds), **rules)
    obs, _ = worlds.reset(seed=seeds)
    greedy = envs.GreedyPolicy(worlds)
    rng = np.random.default_rng(seed)
    totals = np.zeros(len(seeds))
    for _ in range(worlds.rules.max_steps):
        if policy == "greedy":
            actions = greedy.predict(obs)[0]
        else:
            actions = rng.integers(worlds.single_action_space.n, size=len(seeds))
        obs, rewards, _, _, _ = worlds.step(actions)
        totals += rewards
    return totals


def total_reward(rules, policy, seed=0):
    """Total reward of `policy` (as in `policy_totals`) over one episode per reference
    world."""
    return policy_totals(rules, envs.reference_worlds(N_WORLDS), policy, seed).sum()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results", help="directory of calibrate_env.json")
    parser.add_argument("--policy-seeds", type=int, default=5,
                        help="action seeds of the random policy")
    args = parser.parse_args()

    rules = envs.WorldRules()
    print("defaults: " + ", ".join(f"{k}={getattr(rules, k)}" for k in (
        "size_w", "n_money", "n_walls", "n_grass", "n_enemies", "enemy_speed",
        "contact_radius", "swipe_size", "view_size", "max_steps")))
    print(f"{'variant':<18} {'random (seed 0)':>16} {'random mean +- sd':>22} "
          f"{'target':>24} {'ok':>4} {'greedy':>10}")
    rows = []
    for name, (rules, target) in VARIANTS.items():
        randoms = [total_reward(rules, "random", seed) for seed in range(args.policy_seeds)]
        greedy = total_reward(rules, "greedy")
        ok = None if target is None else bool(target[0] <= randoms[0] <= target[1])
        rows.append({"variant": name, "rules": rules, "steps": N_WORLDS * 50,
                     "random": randoms[0], "random_all_seeds": randoms,
                     "random_mean": float(np.mean(randoms)), "random_sd": float(np.std(randoms)),
                     "target": target, "within_target": ok, "greedy": greedy})
        spread = f"{np.mean(randoms):,.0f} +- {np.std(randoms):,.0f}"
        bounds = "" if target is None else f"[{target[0]:,}, {target[1]:,}]"
        print(f"{name:<18} {randoms[0]:>16,.0f} {spread:>22} {bounds:>24} "
              f"{'' if ok is None else ('yes' if ok else 'NO'):>4} {greedy:>10,.0f}")

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report = {"benchmark": "calibrate_env", "worlds": "envs.reference_worlds(400)",
              "defaults": envs.WorldRules().__dict__, "results": rows}
    (out / "calibrate_env.json").write_text(json.dumps(report, indent=2))
    print(f"wrote {out / 'calibrate_env.json'}")


if __name__ == "__main__":
    main()
