"""How far FQI's exploration reaches before any fit: its first round of random play, one-step
or with random actions held (``FQI(exploration_zeta=mu)``), on an env whose reward hides
behind a long sequence of actions (MountainCar-v0 by default).

Each setting plays ``--episodes`` episodes on ``--n-envs`` copies of the env through FQI's own
collection (its first round, before any Q-function exists, is random play) and prints how
many episodes ended in a termination (on MountainCar: reached the goal), the mean return and
the mean length; writes ``bench_exploration.json`` under ``--out``.

    python -m benchmarks.bench_exploration
    python -m benchmarks.bench_exploration --env Acrobot-v1 --zeta 2 1.5
"""
import argparse
import json
import platform
from pathlib import Path

import gymnasium as gym
import numpy as np
from gymnasium.wrappers.vector import RecordEpisodeStatistics
from sklearn.dummy import DummyRegressor

from fqi import FQI


def random_play(env_id, zeta, episodes, n_envs, seed):
    """The episodes of FQI's first round on `env_id` (random actions, held when `zeta`):
    their returns, lengths and whether each ended in a termination."""
    max_steps = gym.spec(env_id).max_episode_steps
    env = RecordEpisodeStatistics(gym.make_vec(env_id, num_envs=n_envs), buffer_length=episodes)
    agent = FQI(DummyRegressor(), env, samples_per_iteration=episodes * max_steps,
                exploration_zeta=zeta, eval_episodes=0, seed=seed)
    agent.learn(n_iterations=1)
    returns = np.array(env.return_queue)[:episodes]
    lengths = np.array(env.length_queue)[:episodes]
    env.close()
    return {"env": env_id, "zeta": zeta, "episodes": len(returns),
            "terminated": int((lengths < max_steps).sum()),
            "mean_return": float(returns.mean()), "mean_length": float(lengths.mean())}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="MountainCar-v0")
    parser.add_argument("--zeta", type=float, nargs="*", default=[3.0, 2.0, 1.5],
                        help="hold parameters to try besides one-step play")
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--n-envs", type=int, default=8)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="results")
    args = parser.parse_args(argv)
    rows = [random_play(args.env, zeta, args.episodes, args.n_envs, args.seed)
            for zeta in (None, *args.zeta)]
    print(f"{'exploration':<22} {'terminated':>12} {'mean return':>12} {'mean length':>12}")
    for row in rows:
        name = "one-step" if row["zeta"] is None else f"held, zeta {row['zeta']:g}"
        print(f"{name:<22} {row['terminated']:>5} of {row['episodes']:<4} "
              f"{row['mean_return']:>12.1f} {row['mean_length']:>12.1f}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "bench_exploration.json").write_text(json.dumps(
        {"benchmark": "bench_exploration", "args": vars(args), "rows": rows,
         "python": platform.python_version()}, indent=2))
    print(f"wrote {out / 'bench_exploration.json'}")


if __name__ == "__main__":
    main()
