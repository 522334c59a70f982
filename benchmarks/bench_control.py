"""Classic control: FQI with Extra-Trees on the feature vector against tuned DQN, same steps.

On CartPole-v1, Acrobot-v1 and MountainCar-v0, each of

- ``fqi-sklearn``: `fqi.FQI` with ``sklearn.ensemble.ExtraTreesRegressor``;
- ``fqi-box``: `fqi.FQI` with ``boxtrees.BoxExtraTreesRegressor(test_type="classic")``;
- ``dqn``: stable-baselines3 DQN with rl-zoo3's tuned hyperparameters for the env

learns for the same number of environment steps (the env's budget, or ``--steps``), once per
seed. Every ``--eval-every`` steps the greedy policy plays one episode on each of 20
held-out reset seeds (`fqi.evaluate`, the same for every agent). Reported per run: the
mean return at the end of the budget, the environment steps at the first evaluation whose
mean reaches the env's solved threshold (CartPole 475, Acrobot -100, MountainCar -110),
and the wall and CPU time of training (evaluations excluded; one core per agent:
single-job forests, one torch thread).

FQI runs with the library's defaults on every env (`fqi.FQI`: discount 0.99, rounds of
2,500 steps from 16 envs each followed by 5 fitted-Q backups, every transition kept up to
100,000, epsilon falling from 1 to 0.05 over the first tenth of the steps): nothing is tuned
per env.

With MushroomRL installed, its ``FQI`` runs beside ours on CartPole with the same regressor,
the protocol it supports (offline, as first formulated): 10,000 transitions of the random
policy, 20 iterations; compared by the return of the greedy policy and the seconds per iteration.
MushroomRL 1.10.2 pins an old torch and numpy, so install it without them:
``.venv/bin/pip install --no-deps mushroom-rl==1.10.2 opencv-python-headless pygame``.

    python -m benchmarks.bench_control                                     # full: hours
    python -m benchmarks.bench_control --envs CartPole-v1 --seeds 0 --steps 3000 --eval-every 1000

Writes ``bench_control.json`` and ``bench_control.png`` (return against env steps) under
``--out``, and each finished run under ``--out/runs/``: a rerun with the same arguments reuses
those, so an interrupted full run resumes where it stopped.
"""
import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
from sklearn.ensemble import ExtraTreesRegressor
from tqdm.auto import tqdm

from fqi import FQI, evaluate, make_box_forest

from .reproduce.stats import median_steps, steps_to_threshold
from .training import EvalCallback, timed_learn, train_sb3
from .zoo_hyperparams import ZOO_DQN

# Tuned DQN: rl-zoo3's settings for each env (benchmarks/zoo_hyperparams.py; policy
# "MlpPolicy", its n_timesteps replaced by the budget below, the same for every agent).
DQN_HYPERPARAMS = {env_id: ZOO_DQN[env_id]
                   for env_id in ("CartPole-v1", "Acrobot-v1", "MountainCar-v0")}
# Budget (environment steps: rl-zoo3's n_timesteps) and solved threshold.
ENVS = {
    "CartPole-v1": {"steps": 50_000, "threshold": 475.0},
    "Acrobot-v1": {"steps": 100_000, "threshold": -100.0},
    "MountainCar-v0": {"steps": 120_000, "threshold": -110.0},
}
AGENTS = ("fqi-sklearn", "fqi-box", "dqn")
# `fqi.evaluate`'s held-out seeds: FQI draws its training reset seeds below them and DQN's
# env is seeded with the run's seed, so these episodes are played by no agent in training.
EVAL_EPISODES = 20
PEER_SAMPLES, PEER_ITERATIONS = 10_000, 20


def make_regressor(name):
    """The agent's Extra-Trees: 30 trees, nodes of fewer than 10 samples are leaves, one job."""
    if name == "fqi-sklearn":
        return ExtraTreesRegressor(n_estimators=30, min_samples_split=10, n_jobs=1)
    return make_box_forest(test_type="classic", n_estimators=30, n_tests=10,
                           min_samples_split=10, n_jobs=1)


def evaluations(env_id, every):
    """The held-out evaluation of every agent: the greedy policy's mean return on
    `EVAL_EPISODES` seeds, every `every` environment steps and at the end."""
    return EvalCallback(gym.make_vec(env_id, EVAL_EPISODES, vectorization_mode="sync"), every,
                        n_episodes=EVAL_EPISODES)


def run_fqi(env_id, agent_name, seed, steps, curve):
    """An FQI agent's run with the library's defaults; its training seconds (wall, CPU)."""
    agent = FQI(make_regressor(agent_name), env_id, eval_episodes=0, seed=seed)
    return timed_learn(agent, curve, total_timesteps=steps)


def run_dqn(env_id, seed, steps, curve):
    """The tuned DQN's run; its training seconds (wall, CPU)."""
    _, seconds, cpu_seconds = train_sb3("DQN", lambda: gym.make(env_id), steps,
                                        DQN_HYPERPARAMS[env_id], seed=seed, callback=curve)
    return seconds, cpu_seconds


def run(env_id, agent_name, seed, steps, every):
    curve = evaluations(env_id, min(every, steps))
    if agent_name == "dqn":
        seconds, cpu_seconds = run_dqn(env_id, seed, steps, curve)
    else:
        seconds, cpu_seconds = run_fqi(env_id, agent_name, seed, steps, curve)
    solved = steps_to_threshold(curve.evaluations, ENVS[env_id]["threshold"])
    return {"env": env_id, "agent": agent_name, "seed": seed,
            "env_steps": curve.evaluations[-1][0], "curve": curve.evaluations,
            "final_mean": curve.evaluations[-1][1], "steps_to_threshold": solved,
            "train_seconds": seconds, "train_cpu_seconds": cpu_seconds,
            "eval_seconds": curve.eval_seconds}


def run_peer(seed, samples):
    """Offline FQI on `samples` random-policy CartPole transitions, `PEER_ITERATIONS`
    iterations, ours and MushroomRL's, with the same regressor; None without MushroomRL."""
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    try:
        from mushroom_rl.algorithms.value import FQI as MushroomFQI
        from mushroom_rl.core import Core, Environment, MDPInfo
        from mushroom_rl.policy import EpsGreedy
        from mushroom_rl.utils.parameters import Parameter
        from mushroom_rl.utils.spaces import Box, Discrete
    except ImportError:
        return None
    env_id, gamma = "CartPole-v1", DQN_HYPERPARAMS["CartPole-v1"]["gamma"]
    eval_env = gym.make_vec(env_id, EVAL_EPISODES, vectorization_mode="sync")

    class Gymnasium(Environment):
        """A gymnasium env as a MushroomRL MDP (absorbing = terminated; the time limit is
        the MDP's horizon)."""

        def __init__(self):
            self.env = gym.make(env_id)
            space = self.env.observation_space
            super().__init__(MDPInfo(Box(space.low, space.high),
                                     Discrete(self.env.action_space.n), gamma,
                                     self.env.spec.max_episode_steps))
            self._seed = seed

        def reset(self, state=None):
            obs, _ = self.env.reset(seed=self._seed)
            self._seed = None
            return obs

        def step(self, action):
            obs, reward, terminated, _, info = self.env.step(int(action[0]))
            return obs, reward, terminated, info

    class Greedy:
        def __init__(self, approximator):
            self.approximator = approximator

        def predict(self, observation, deterministic=True):
            return self.approximator.predict(np.asarray(observation)).argmax(axis=1), None

    mdp = Gymnasium()
    policy = EpsGreedy(epsilon=Parameter(1.0))
    regressor = make_regressor("fqi-sklearn").get_params()
    del regressor["random_state"]
    mushroom = MushroomFQI(mdp.info, policy, ExtraTreesRegressor,
                           n_iterations=PEER_ITERATIONS, quiet=True, approximator_params={
                               "input_shape": mdp.info.observation_space.shape,
                               "output_shape": (1,), "n_actions": 2, **regressor})
    np.random.seed(seed)  # MushroomRL's policies and sklearn's trees draw from it
    dataset = Core(mushroom, mdp).evaluate(n_steps=samples, quiet=True)
    start = time.perf_counter()
    mushroom.fit(dataset)
    mushroom_seconds = (time.perf_counter() - start) / PEER_ITERATIONS

    ours = FQI(make_regressor("fqi-sklearn"), env_id, gamma=gamma,
               samples_per_iteration=samples, resample_every=None, n_envs=1,
               eval_episodes=0, seed=seed).learn(n_iterations=PEER_ITERATIONS)
    ours_seconds = np.mean([r["t_targets"] + r["t_fit"] for r in ours.history])
    return {"seed": seed, "samples": samples, "iterations": PEER_ITERATIONS,
            "mushroom_mean": evaluate(Greedy(mushroom.approximator), eval_env,
                                      n_episodes=EVAL_EPISODES).mean,
            "mushroom_seconds_per_iteration": mushroom_seconds,
            "ours_mean": evaluate(ours, eval_env, n_episodes=EVAL_EPISODES).mean,
            "ours_seconds_per_iteration": float(ours_seconds)}


def summarise(runs):
    """Per env and agent: mean and sd of the final mean return over seeds, the steps to the
    threshold (`training.median_steps`: a seed that never reached it counts as the last)
    and how many did, training seconds."""
    table = {}
    for run_ in runs:
        table.setdefault((run_["env"], run_["agent"]), []).append(run_)
    summary = []
    for (env_id, agent_name), group in table.items():
        finals = [r["final_mean"] for r in group]
        crossings = [r["steps_to_threshold"] for r in group]
        summary.append({
            "env": env_id, "agent": agent_name, "seeds": [r["seed"] for r in group],
            "final_mean": float(np.mean(finals)), "final_sd": float(np.std(finals)),
            "solved_runs": sum(c is not None for c in crossings),
            "median_steps_to_threshold": median_steps(crossings),
            "train_seconds": float(np.mean([r["train_seconds"] for r in group])),
            "train_cpu_seconds": float(np.mean([r["train_cpu_seconds"] for r in group])),
        })
    return summary


def markdown(summary, peers):
    lines = ["| env | agent | mean return (held-out seeds) | steps to threshold | solved runs "
             "| train seconds (CPU) |", "| --- | --- | --- | --- | --- | --- |"]
    for s in summary:
        steps = ("-" if s["median_steps_to_threshold"] is None
                 else f"{s['median_steps_to_threshold']:,.0f}")
        lines.append(f"| {s['env']} | {s['agent']} | {s['final_mean']:.1f} +- "
                     f"{s['final_sd']:.1f} | {steps} | {s['solved_runs']}/{len(s['seeds'])} | "
                     f"{s['train_seconds']:.0f} ({s['train_cpu_seconds']:.0f}) |")
    if peers:
        lines += ["", "| CartPole-v1, offline FQI | mean return | seconds per iteration |",
                  "| --- | --- | --- |"]
        for who in ("ours", "mushroom"):
            lines.append(f"| {'fqi' if who == 'ours' else 'MushroomRL'} | "
                         f"{np.mean([p[who + '_mean'] for p in peers]):.1f} | "
                         f"{np.mean([p[who + '_seconds_per_iteration'] for p in peers]):.2f} |")
    return "\n".join(lines)


def plot(runs, envs, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(envs), figsize=(5 * len(envs), 4), squeeze=False)
    colours = dict(zip(AGENTS, ("tab:blue", "tab:green", "tab:purple")))
    for ax, env_id in zip(axes[0], envs):
        for agent_name in AGENTS:
            curves = [np.array(r["curve"]) for r in runs
                      if r["env"] == env_id and r["agent"] == agent_name]
            for i, curve in enumerate(curves):
                ax.plot(curve[:, 0], curve[:, 1], color=colours[agent_name], alpha=0.7,
                        lw=1, label=agent_name if i == 0 else None)
        ax.axhline(ENVS[env_id]["threshold"], color="grey", ls="--", lw=1, label="solved")
        ax.set_title(env_id)
        ax.set_xlabel("environment steps")
        ax.set_ylabel("mean return, 20 held-out seeds")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", nargs="+", default=list(ENVS), choices=list(ENVS))
    parser.add_argument("--agents", nargs="+", default=list(AGENTS), choices=AGENTS)
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2])
    parser.add_argument("--steps", type=int, default=None,
                        help="environment steps of every run (default: each env's budget)")
    parser.add_argument("--eval-every", type=int, default=5000)
    parser.add_argument("--no-peer", action="store_true", help="skip MushroomRL's FQI")
    parser.add_argument("--out", default="results")
    args = parser.parse_args(argv)
    for name in ("steps", "eval_every"):
        value = getattr(args, name)
        if value is not None and value < 1:
            parser.error(f"--{name.replace('_', '-')} must be >= 1, got {value}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    plan = [(env_id, agent_name, seed) for env_id in args.envs for agent_name in args.agents
            for seed in args.seeds]
    runs = []
    for env_id, agent_name, seed in tqdm(plan, desc="bench_control"):
        steps = args.steps or ENVS[env_id]["steps"]
        cached = out / "runs" / f"{env_id}_{agent_name}_seed{seed}_{steps}_{args.eval_every}.json"
        if cached.exists():
            runs.append(json.loads(cached.read_text()))
        else:
            runs.append(run(env_id, agent_name, seed, steps, args.eval_every))
            cached.parent.mkdir(exist_ok=True)
            cached.write_text(json.dumps(runs[-1], indent=1))
        r = runs[-1]
        tqdm.write(f"{env_id:<15} {agent_name:<12} seed {seed}: mean return "
                   f"{r['final_mean']:8.1f}, threshold at "
                   f"{'-' if r['steps_to_threshold'] is None else r['steps_to_threshold']:>7}"
                   f" steps, {r['train_seconds']:6.1f} s")
    peers = []
    if "CartPole-v1" in args.envs and not args.no_peer:
        samples = min(PEER_SAMPLES, args.steps or PEER_SAMPLES)
        for seed in tqdm(args.seeds, desc="MushroomRL FQI (CartPole, offline)"):
            peer = run_peer(seed, samples)
            if peer is None:
                tqdm.write("MushroomRL is not installed: peer skipped (see --help)")
                break
            peers.append(peer)
    summary = summarise(runs)
    table = markdown(summary, peers)
    print(table)
    report = {"benchmark": "bench_control", "args": vars(args), "envs": ENVS,
              "dqn_hyperparams": DQN_HYPERPARAMS, "eval_episodes": EVAL_EPISODES,
              "fqi": {"settings": "the library's defaults",
                      "regressors": {name: repr(make_regressor(name))
                                     for name in AGENTS[:2]}},
              "python": platform.python_version(), "machine": platform.machine(),
              "command": " ".join(sys.argv), "runs": runs, "summary": summary,
              "peer": peers, "markdown": table}
    (out / "bench_control.json").write_text(json.dumps(report, indent=2))
    plot(runs, args.envs, out / "bench_control.png")
    print(f"wrote {out / 'bench_control.json'} and {out / 'bench_control.png'}")


if __name__ == "__main__":
    main()
