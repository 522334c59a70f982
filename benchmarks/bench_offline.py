"""Offline CartPole: FQI with Extra-Trees against d3rlpy's discrete CQL and DQN on the same data.

Two fixed data sets of CartPole-v1 transitions, the same number each (``--transitions``),
made once from seeded rollouts and saved as ``.npz`` (``observations``, ``actions``,
``rewards``, ``next_observations``, ``terminations``, ``truncations``, each episode's rows in
order):

- ``random``: the uniform random policy (`fqi.RandomPolicy`);
- ``medium``: an FQI agent stopped early (its defaults, 30 Extra-Trees with
  ``min_samples_split=10``, `MEDIUM_TRAINING_STEPS` environment steps), played with a random
  action with probability `MEDIUM_EPSILON`: 191 per episode, about 40 % of CartPole's
  maximum return of 500 (the random policy's: 22).

On each, every method learns from the data alone, once per seed:

- ``fqi-nmin10``, ``fqi-grown``: `fqi.FQI.learn_offline` with scikit-learn's
  ``ExtraTreesRegressor`` (30 trees, ``min_samples_split`` 10, or 2: grown out; one job),
  discount 0.99, ``--iterations`` fitted-Q backups, constrained to the actions the data
  support with ``--support-threshold`` (FQI's default, 0.3; ``none``: unconstrained, the
  runs made before FQI had the constraint);
- ``d3rlpy-dqn``, ``d3rlpy-cql``: d3rlpy's ``DQN`` and ``DiscreteCQL`` (d3rlpy's own
  discrete algorithms and default network, two hidden layers of 256) with the settings of
  d3rlpy's CartPole examples (learning rate 1e-3, target network copied every 100 updates),
  discount 0.99, ``--gradient-steps`` updates of 32 transitions (d3rlpy's offline CartPole
  tutorial runs 10,000), one torch thread.

Each learned greedy policy plays one episode on each of 20 held-out reset seeds
(`fqi.evaluate`, as in ``bench_control``; the data's resets draw seeds below them). Reported
per method and data set: the mean return over seeds (+- sd), and the training seconds (wall
and CPU, one core: single-job forests, one torch thread).

d3rlpy 2.8 pins gymnasium 1.0, so it lives in a venv of its own; that part imports only
numpy, gymnasium, torch and d3rlpy, saves each trained policy as TorchScript (d3rlpy's
``save_policy``), and the evaluation plays those in this venv. Everything, the d3rlpy part
through the other venv's interpreter::

    python -m benchmarks.bench_offline --d3rlpy-python <d3rlpy venv>/bin/python

or part by part (``--parts`` data, fqi, d3rlpy, report)::

    python -m benchmarks.bench_offline --parts data fqi
    PYTHONPATH=. <d3rlpy venv>/bin/python -m benchmarks.bench_offline --parts d3rlpy
    python -m benchmarks.bench_offline --parts report

``--quick`` runs every part at a tiny size. Writes ``bench_offline.json`` and
``bench_offline.png`` under ``--out``, and each finished run under ``--out/runs/`` (a rerun
reuses those made from the same data); the data sets and the d3rlpy policies go to
``--data``.
"""
import argparse
import hashlib
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
from tqdm.auto import tqdm

ENV_ID = "CartPole-v1"
GAMMA = 0.99
EVAL_EPISODES = 20  # `fqi.evaluate`'s held-out seeds 2**40, 2**40 + 1, ...
DATA_SEED = 0
KEYS = ("observations", "actions", "rewards", "next_observations", "terminations",
        "truncations")
DATASETS = ("random", "medium")
# The medium behaviour: FQI with its defaults stopped after this many environment steps
# (its greedy policy: 200 on the held-out seeds), then played with a random action at
# probability MEDIUM_EPSILON (191 per episode in the data: about 40 % of the maximum, 500).
MEDIUM_TRAINING_STEPS = 15_000
MEDIUM_EPSILON = 0.2
# Envs played side by side while collecting: one per 200 transitions, at most 50 (1,000
# steps each for 50,000 transitions: room for two episodes of CartPole's 500 steps).
COLLECT_STEPS_PER_ENV, MAX_COLLECT_ENVS = 200, 50
FQI_METHODS = {"fqi-nmin10": 10, "fqi-grown": 2}  # min_samples_split of the Extra-Trees
D3RLPY_METHODS = {
    # d3rlpy's CartPole examples (its data-collection script and online tutorial) train DQN
    # with these; its defaults (learning rate 6.25e-5, target copied every 8,000 updates)
    # are Atari's. CQL keeps its default conservative weight alpha=1.
    "d3rlpy-dqn": ("DQNConfig", {"learning_rate": 1e-3, "target_update_interval": 100,
                                 "batch_size": 32, "gamma": GAMMA}),
    "d3rlpy-cql": ("DiscreteCQLConfig", {"learning_rate": 1e-3, "target_update_interval": 100,
                                         "batch_size": 32, "gamma": GAMMA, "alpha": 1.0}),
}
METHODS = (*FQI_METHODS, *D3RLPY_METHODS)
PARTS = ("data", "fqi", "d3rlpy", "report")
QUICK = {"transitions": 1_000, "iterations": 3, "gradient_steps": 200, "seeds": [0],
         "medium_training_steps": 1_000}
D3RLPY_MISSING = ("the d3rlpy part needs d3rlpy, which pins gymnasium 1.0: install it in a venv "
                  "of its own (pip install torch --index-url https://download.pytorch.org/whl/cpu; "
                  "pip install d3rlpy) and pass --d3rlpy-python <that venv>/bin/python, or run "
                  "PYTHONPATH=. <that venv>/bin/python -m benchmarks.bench_offline --parts d3rlpy")


# ---------------------------------------------------------------------------- data sets
def collect(policy, n_transitions, seed, epsilon=0.0, n_envs=None):
    """Transitions of `policy` on CartPole, each episode's rows together and in order.

    `n_envs` envs play side by side (one batched ``predict`` per step); their first resets
    draw seeds below ``2**40`` from `seed`, later episodes start through the autoreset. Each
    env's rows follow one another; the last row of each env (and of the data) that ends no
    episode is marked truncated, so every episode ends with a termination or a truncation.

    Parameters
    ----------
    policy : object
        ``predict(observations, deterministic=True) -> (actions, state)`` for a batch.
    n_transitions : int
    seed : int
        Seeds the resets and the random actions.
    epsilon : float, default=0.0
        Probability of a uniform random action instead of the policy's.
    n_envs : int, default=None
        Default: one per `COLLECT_STEPS_PER_ENV` transitions, 1 to `MAX_COLLECT_ENVS`.

    Returns
    -------
    data : dict of ndarray
        One entry per key of `KEYS`, `n_transitions` rows each.
    episode_returns : ndarray
        Return of each episode that the env ended (not one cut by the end of the data).
    """
    from gymnasium.vector import AutoresetMode  # not in gymnasium 1.0 (d3rlpy's)

    if n_envs is None:
        n_envs = collect_envs(n_transitions)
    per_env = -(-n_transitions // n_envs)
    rng = np.random.default_rng(seed)
    env = gym.make_vec(ENV_ID, n_envs, vectorization_mode="sync",
                       vector_kwargs={"autoreset_mode": AutoresetMode.SAME_STEP})
    steps, returns, running = [], [], np.zeros(n_envs)
    try:
        obs, _ = env.reset(seed=rng.integers(2**40, size=n_envs).tolist())
        for _ in range(per_env):
            actions = np.asarray(policy.predict(obs, deterministic=True)[0])
            explore = rng.random(n_envs) < epsilon
            actions = np.where(explore, rng.integers(env.single_action_space.n, size=n_envs),
                               actions)
            next_obs, rewards, terminated, truncated, info = env.step(actions)
            ended = terminated | truncated
            final = next_obs.copy()
            if ended.any():
                final[ended] = np.stack(info["final_obs"][ended])
            steps.append((obs, actions, rewards, final, terminated, truncated))
            running += rewards
            returns.extend(running[ended])
            running[ended] = 0.0
            obs = next_obs
    finally:
        env.close()
    return _episode_order(steps, n_transitions), np.array(returns)


def collect_envs(n_transitions):
    """The envs `collect` plays side by side for `n_transitions` by default."""
    return int(np.clip(n_transitions // COLLECT_STEPS_PER_ENV, 1, MAX_COLLECT_ENVS))


def _episode_order(steps, n_transitions):
    """The per-step batches of `collect` as rows env after env, cut to `n_transitions`,
    with each env's (and the data's) last row marked truncated unless it ends an episode."""
    data = {}
    for key, values in zip(KEYS, zip(*steps)):
        stacked = np.stack([np.asarray(v) for v in values], axis=1)  # (env, step, ...)
        data[key] = stacked.reshape(-1, *stacked.shape[2:])[:n_transitions]
    per_env = len(steps)
    cuts = np.append(np.arange(per_env - 1, n_transitions, per_env), n_transitions - 1)
    data["truncations"][cuts] |= ~data["terminations"][cuts]
    data["actions"] = data["actions"].astype(np.int64)
    return data


def medium_policy(seed, training_steps):
    """The medium behaviour's greedy policy: FQI with its defaults (30 Extra-Trees,
    ``min_samples_split=10``, one job) after `training_steps` environment steps (its
    collection's ties broken at random, the default the data were made with)."""
    from fqi import FQI

    agent = FQI(make_regressor(10), ENV_ID, gamma=GAMMA, tie_break="random", eval_episodes=0,
                seed=seed)
    return agent.learn(total_timesteps=training_steps)


def make_datasets(data_dir, n_transitions, medium_training_steps, seed=DATA_SEED):
    """Make the ``random`` and ``medium`` data sets under `data_dir` (``<name>.npz``) unless
    they are there from the same settings; returns their description (``info.json``)."""
    from fqi import RandomPolicy

    data_dir.mkdir(parents=True, exist_ok=True)
    settings = {"env": ENV_ID, "transitions": n_transitions, "seed": seed,
                "collect_envs": collect_envs(n_transitions),
                "medium_training_steps": medium_training_steps, "medium_epsilon": MEDIUM_EPSILON}
    info_path = data_dir / "info.json"
    if info_path.exists():
        info = json.loads(info_path.read_text())
        if info["settings"] == settings and all(
                (data_dir / f"{name}.npz").exists() for name in DATASETS):
            return info
    info = {"settings": settings, "datasets": {}}
    behaviours = {"random": lambda: (RandomPolicy(ENV_ID, seed=seed), 0.0),
                  "medium": lambda: (medium_policy(seed, medium_training_steps), MEDIUM_EPSILON)}
    for name in tqdm(DATASETS, desc="data sets"):
        start = time.perf_counter()
        policy, epsilon = behaviours[name]()
        data, returns = collect(policy, n_transitions, seed + 1, epsilon)
        np.savez_compressed(data_dir / f"{name}.npz", **data)
        info["datasets"][name] = {
            "transitions": n_transitions, "episodes": int(returns.size),
            "behaviour_mean_return": float(returns.mean()) if returns.size else None,
            "behaviour_sd_return": float(returns.std()) if returns.size else None,
            "epsilon": epsilon, "sha256": data_digest(data),
            "seconds": time.perf_counter() - start}
    info_path.write_text(json.dumps(info, indent=1))
    return info


def load_dataset(data_dir, name):
    """The data set `name` saved by `make_datasets`, as a dict of arrays."""
    path = data_dir / f"{name}.npz"
    if not path.exists():
        raise FileNotFoundError(f"no data set {path}: run the data part first "
                                f"(--parts data)")
    with np.load(path) as saved:
        return {key: saved[key] for key in KEYS}


def data_digest(data):
    """SHA-256 of the arrays of a data set, in `KEYS` order: both venvs check they learn
    from the same data."""
    digest = hashlib.sha256()
    for key in KEYS:
        digest.update(np.ascontiguousarray(data[key]).tobytes())
    return digest.hexdigest()


# ---------------------------------------------------------------------------- runs
def make_regressor(min_samples_split):
    """Scikit-learn's Extra-Trees as the benchmarks use them: 30 trees, one job."""
    from sklearn.ensemble import ExtraTreesRegressor

    return ExtraTreesRegressor(n_estimators=30, min_samples_split=min_samples_split, n_jobs=1)


def timed(function, *args, **kwargs):
    """``function(*args, **kwargs)`` and its wall and CPU seconds."""
    start, cpu_start = time.perf_counter(), time.process_time()
    result = function(*args, **kwargs)
    return result, time.perf_counter() - start, time.process_time() - cpu_start


def held_out_return(policy):
    """The mean return of `policy`'s greedy play on the `EVAL_EPISODES` held-out seeds."""
    from fqi import evaluate

    env = gym.make_vec(ENV_ID, EVAL_EPISODES, vectorization_mode="sync")
    try:
        return evaluate(policy, env, n_episodes=EVAL_EPISODES).mean
    finally:
        env.close()


def make_agent(method, seed, support_threshold=None):
    """The untrained FQI agent of `method` (one of `FQI_METHODS`), as every run uses it,
    with FQI's offline constraint `support_threshold` (None: unconstrained)."""
    from fqi import FQI

    return FQI(make_regressor(FQI_METHODS[method]), ENV_ID, gamma=GAMMA, n_envs=1,
               eval_episodes=0, seed=seed, support_threshold=support_threshold)


def run_fqi(data, method, seed, n_iterations, support_threshold=None):
    """`FQI.learn_offline` on `data`; the record of the run (no file written)."""
    agent = make_agent(method, seed, support_threshold)
    _, seconds, cpu_seconds = timed(agent.learn_offline, data, n_iterations=n_iterations)
    return {"budget": {"iterations": n_iterations}, "train_seconds": seconds,
            "train_cpu_seconds": cpu_seconds, "mean_return": held_out_return(agent),
            "settings": repr(agent.regressor), "support_threshold": support_threshold}


def fqi_budget(args):
    """The budget part of an FQI run's key: the iterations, and the support threshold
    unless unconstrained (so runs of either kind are kept apart)."""
    if args.support_threshold is None:
        return args.iterations
    return f"{args.iterations}-support{args.support_threshold:g}"


def threshold(text):
    """``--support-threshold``: a number, or ``none``."""
    return None if text.lower() == "none" else float(text)


def _require_d3rlpy():
    """d3rlpy, or a RuntimeError saying how to get it."""
    try:
        import d3rlpy
    except ImportError:
        raise RuntimeError(D3RLPY_MISSING) from None
    _quiet_d3rlpy()
    return d3rlpy


def mdp_dataset(data):
    """`data` as a d3rlpy ``MDPDataset`` holding the same transitions.

    d3rlpy reads an episode as rows of observations and takes each next observation from
    the row after; it drops the last row of an episode that ends by a timeout. So an episode
    that ends truncated gets its true last next observation as one more row (action 0,
    reward 0) flagged as the timeout, and its every transition bootstraps, as in FQI; one
    that terminates keeps its rows, the last flagged terminal.
    """
    d3rlpy = _require_d3rlpy()
    ends = np.flatnonzero(data["terminations"] | data["truncations"])
    if ends.size == 0 or ends[-1] != len(data["actions"]) - 1:
        raise ValueError("the data's last row must end an episode (a termination or a "
                         "truncation)")
    columns = {key: [] for key in ("observations", "actions", "rewards", "terminals",
                                   "timeouts")}
    start = 0
    for end in ends:
        rows = slice(start, end + 1)
        n, terminal = end + 1 - start, bool(data["terminations"][end])
        observations = data["observations"][rows]
        actions, rewards = data["actions"][rows], data["rewards"][rows]
        flags = np.zeros(n + (not terminal))
        if not terminal:
            observations = np.vstack([observations, data["next_observations"][end]])
            actions, rewards = np.append(actions, 0), np.append(rewards, 0.0)
        flags[-1] = 1.0
        for key, value in zip(columns, (observations, actions, rewards,
                                        flags * terminal, flags * (not terminal))):
            columns[key].append(value)
        start = end + 1
    joined = {key: np.concatenate(values) for key, values in columns.items()}
    return d3rlpy.dataset.MDPDataset(
        joined["observations"].astype(np.float32), joined["actions"].astype(np.int64),
        joined["rewards"].astype(np.float32), joined["terminals"].astype(np.float32),
        joined["timeouts"].astype(np.float32), action_space=d3rlpy.ActionSpace.DISCRETE,
        action_size=int(data["actions"].max()) + 1)


def run_d3rlpy(data, method, seed, gradient_steps, policy_path):
    """d3rlpy's algorithm `method` on `data`, one torch thread, its greedy policy saved as
    TorchScript at `policy_path`; the record of the run (its return is played later, see
    `evaluate_policies`)."""
    d3rlpy = _require_d3rlpy()
    import torch

    config_name, settings = D3RLPY_METHODS[method]
    torch.set_num_threads(1)
    d3rlpy.seed(seed)
    dataset = mdp_dataset(data)
    algo = getattr(d3rlpy.algos, config_name)(**settings).create(device=False)
    _, seconds, cpu_seconds = timed(
        algo.fit, dataset, n_steps=gradient_steps, n_steps_per_epoch=gradient_steps,
        show_progress=False, save_interval=gradient_steps + 1,
        logger_adapter=d3rlpy.logging.NoopAdapterFactory())
    policy_path.parent.mkdir(parents=True, exist_ok=True)
    algo.save_policy(str(policy_path))
    return {"budget": {"gradient_steps": gradient_steps}, "train_seconds": seconds,
            "train_cpu_seconds": cpu_seconds, "mean_return": None,
            "policy": policy_path.name, "transitions_seen": dataset.transition_count,
            "settings": {"algorithm": config_name, **settings, "d3rlpy": d3rlpy.__version__,
                         "torch_threads": torch.get_num_threads()}}


def _quiet_d3rlpy():
    """d3rlpy's structlog messages at warnings and above only."""
    import logging

    import structlog

    structlog.configure(wrapper_class=structlog.make_filtering_bound_logger(logging.WARNING))


class TorchScriptPolicy:
    """A greedy policy saved by d3rlpy's ``save_policy`` (TorchScript), with the
    stable-baselines3 ``predict`` signature that `fqi.evaluate` plays.

    Parameters
    ----------
    path : str or path-like
    """

    def __init__(self, path):
        import warnings

        import torch

        self._torch = torch
        with warnings.catch_warnings():  # TorchScript is d3rlpy's export format
            warnings.simplefilter("ignore", DeprecationWarning)
            self.module = torch.jit.load(str(path))

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        """The greedy action of each observation of a batch."""
        with self._torch.no_grad():
            batch = self._torch.as_tensor(np.asarray(observation, dtype=np.float32))
            return self.module(batch).numpy().astype(np.int64).reshape(-1), None


# ---------------------------------------------------------------------------- the parts
def run_key(dataset, method, seed, budget, n_transitions):
    return f"{dataset}_{method}_seed{seed}_{n_transitions}_{budget}"


def run_part(args, methods, budget, train, datasets=DATASETS):
    """Each run of `methods` x `datasets` x ``args.seeds`` not already in ``args.out/runs``
    from the same data: trained with ``train(data, method, seed, key)`` and saved there.
    Returns the paths of the runs, in that order."""
    info = read_info(args.data)
    plan = [(name, method, seed) for name in datasets for method in methods
            for seed in args.seeds]
    paths = []
    for name, method, seed in tqdm(plan, desc=" and ".join(methods)):
        key = run_key(name, method, seed, budget, args.transitions)
        path = args.out / "runs" / f"{key}.json"
        paths.append(path)
        digest = info["datasets"][name]["sha256"]
        if path.exists() and json.loads(path.read_text())["data_sha256"] == digest:
            continue
        data = load_dataset(args.data, name)
        if data_digest(data) != digest:
            raise ValueError(f"{args.data / name}.npz is not the data of info.json: run the "
                             f"data part again")
        record = {"dataset": name, "method": method, "seed": seed, "data_sha256": digest,
                  **train(data, method, seed, key)}
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(record, indent=1))
        tqdm.write(f"{name:<7} {method:<11} seed {seed}: {record['train_seconds']:7.1f} s"
                   + ("" if record["mean_return"] is None
                      else f", mean return {record['mean_return']:6.1f}"))
    return paths


def read_info(data_dir):
    """The description of the data sets (``info.json``) that the data part wrote."""
    path = data_dir / "info.json"
    if not path.exists():
        raise FileNotFoundError(f"no {path}: run the data part first (--parts data)")
    return json.loads(path.read_text())


def fqi_part(args):
    run_part(args, list(FQI_METHODS), fqi_budget(args),
             lambda data, method, seed, key: run_fqi(data, method, seed, args.iterations,
                                                     args.support_threshold))


def d3rlpy_part(args):
    """The d3rlpy runs, here if d3rlpy imports, else through ``--d3rlpy-python``."""
    try:
        import d3rlpy  # noqa: F401
    except ImportError:
        if args.d3rlpy_python is None:
            raise SystemExit(f"bench_offline: {D3RLPY_MISSING}") from None
        d3rlpy_subprocess(args)
        return
    run_part(args, list(D3RLPY_METHODS), args.gradient_steps,
             lambda data, method, seed, key: run_d3rlpy(
                 data, method, seed, args.gradient_steps, args.data / "policies" / f"{key}.pt"))


def d3rlpy_subprocess(args):
    """The d3rlpy part run by the interpreter ``args.d3rlpy_python`` (this repository on
    its path), with the same sizes and folders."""
    root = Path(__file__).resolve().parent.parent
    argv = [args.d3rlpy_python, "-m", "benchmarks.bench_offline", "--parts", "d3rlpy",
            "--out", str(args.out.resolve()), "--data", str(args.data.resolve()),
            "--seeds", *map(str, args.seeds), "--transitions", str(args.transitions),
            "--gradient-steps", str(args.gradient_steps)]
    path = os.pathsep.join(filter(None, [str(root), os.environ.get("PYTHONPATH")]))
    code = subprocess.run(argv, check=False, cwd=root,
                          env={**os.environ, "PYTHONPATH": path}).returncode
    if code:
        raise SystemExit(f"bench_offline: the d3rlpy part failed under {args.d3rlpy_python} "
                         f"(exit status {code})")


def load_runs(args, info):
    """The finished runs of this invocation's plan (the sizes of `args`) made from the data
    of `info`, in plan order; a d3rlpy policy not yet scored is played first (and its
    return written to its run's file)."""
    runs = []
    for name in DATASETS:
        for method in METHODS:
            budget = fqi_budget(args) if method in FQI_METHODS else args.gradient_steps
            for seed in args.seeds:
                key = run_key(name, method, seed, budget, args.transitions)
                path = args.out / "runs" / f"{key}.json"
                if not path.exists():
                    continue
                record = json.loads(path.read_text())
                if record["data_sha256"] != info["datasets"][name]["sha256"]:
                    tqdm.write(f"{path} is of other data: left out (run its part again)")
                    continue
                if record["mean_return"] is None:
                    record["mean_return"] = score_policy(args.data, path, record)
                runs.append(record)
    return runs


def score_policy(data_dir, path, record):
    """The held-out return of the d3rlpy policy of the run `record` (from `path`), written
    to `path`."""
    policy_path = data_dir / "policies" / record["policy"]
    if not policy_path.exists():
        raise FileNotFoundError(f"{path} has no return yet and its policy {policy_path} is "
                                f"gone: run the d3rlpy part again")
    score = held_out_return(TorchScriptPolicy(policy_path))
    path.write_text(json.dumps({**record, "mean_return": score}, indent=1))
    return score


def summarise(runs):
    """Per data set and method: mean and sd over seeds of the held-out mean return, and the
    mean training seconds (wall, CPU)."""
    groups = {}
    for run in runs:
        if run["mean_return"] is not None:
            groups.setdefault((run["dataset"], run["method"]), []).append(run)
    return [{"dataset": name, "method": method, "seeds": [r["seed"] for r in group],
             "mean_return": float(np.mean([r["mean_return"] for r in group])),
             "sd_return": float(np.std([r["mean_return"] for r in group])),
             "train_seconds": float(np.mean([r["train_seconds"] for r in group])),
             "train_cpu_seconds": float(np.mean([r["train_cpu_seconds"] for r in group])),
             "budget": group[0]["budget"]}
            for (name, method), group in groups.items()]


def markdown(summary, info):
    """The results as a markdown table: one row per method, return and seconds per data
    set, and the behaviour policy's return in the data."""
    cells = {(s["dataset"], s["method"]): s for s in summary}
    header = " | ".join(f"{name}: return | {name}: seconds (CPU)" for name in DATASETS)
    lines = [f"| method | budget | {header} |", "| --- | --- |" + " --- | --- |" * len(DATASETS)]
    behaviour = [info["datasets"][name]["behaviour_mean_return"] for name in DATASETS]
    lines.append("| behaviour policy (the data) | - | " + " | ".join(
        f"{value:.1f} | -" for value in behaviour) + " |")
    for method in METHODS:
        row = [cells.get((name, method)) for name in DATASETS]
        if not any(row):
            continue
        budget = next(s["budget"] for s in row if s)
        budget = ", ".join(f"{value:,} {key.replace('_', ' ')}" for key, value in budget.items())
        lines.append(f"| {method} | {budget} | " + " | ".join(
            "- | -" if s is None else
            f"{s['mean_return']:.1f} +- {s['sd_return']:.1f} ({len(s['seeds'])} seeds) | "
            f"{s['train_seconds']:.1f} ({s['train_cpu_seconds']:.1f})" for s in row) + " |")
    return "\n".join(lines)


def plot(runs, info, path):
    """Return per method and data set (each seed a dot, the mean a bar, the behaviour a
    dashed line), and the training seconds."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.2))
    width = 0.8 / len(METHODS)
    colours = dict(zip(METHODS, ("tab:blue", "tab:cyan", "tab:purple", "tab:red")))
    for i, method in enumerate(METHODS):
        for j, name in enumerate(DATASETS):
            group = [r for r in runs if r["method"] == method and r["dataset"] == name
                     and r["mean_return"] is not None]
            if not group:
                continue
            x = j + (i - (len(METHODS) - 1) / 2) * width
            label = method if j == 0 else None
            returns = [r["mean_return"] for r in group]
            left.bar(x, np.mean(returns), width, color=colours[method], alpha=0.6, label=label)
            left.scatter([x] * len(returns), returns, color="k", s=8, zorder=3)
            right.bar(x, np.mean([r["train_seconds"] for r in group]), width,
                      color=colours[method], alpha=0.8, label=label)
    for j, name in enumerate(DATASETS):
        behaviour = info["datasets"][name]["behaviour_mean_return"]
        left.hlines(behaviour, j - 0.45, j + 0.45, colors="grey", linestyles="--",
                    label="behaviour policy" if j == 0 else None)
    for ax, ylabel in ((left, f"mean return, {EVAL_EPISODES} held-out seeds"),
                       (right, "training seconds, wall (one core each)")):
        ax.set_xticks(range(len(DATASETS)),
                      [f"{name} ({info['settings']['transitions']:,} transitions)"
                       for name in DATASETS])
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3, axis="y")
    left.set_ylim(0, 520)
    left.legend(fontsize=8, loc="upper left")
    fig.suptitle(f"Offline {ENV_ID}: FQI (Extra-Trees) and d3rlpy on the same data")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def report_part(args):
    """Score the d3rlpy policies, then write the JSON, the table and the PNG."""
    info = read_info(args.data)
    runs = load_runs(args, info)
    summary = summarise(runs)
    table = markdown(summary, info)
    print(table)
    report = {"benchmark": "bench_offline", "args": jsonable(vars(args)), "env": ENV_ID,
              "gamma": GAMMA, "eval_episodes": EVAL_EPISODES, "data": info,
              "methods": {"fqi": {m: repr(make_regressor(n)) for m, n in FQI_METHODS.items()},
                          "d3rlpy": D3RLPY_METHODS},
              "python": platform.python_version(), "machine": platform.machine(),
              "command": " ".join(["python -m benchmarks.bench_offline", *sys.argv[1:]]),
              "runs": runs, "summary": summary, "markdown": table}
    (args.out / "bench_offline.json").write_text(json.dumps(report, indent=2))
    plot(runs, info, args.out / "bench_offline.png")
    print(f"wrote {args.out / 'bench_offline.json'} and {args.out / 'bench_offline.png'}")


def jsonable(arguments):
    """Command-line arguments as JSON values (paths as strings)."""
    return {key: str(value) if isinstance(value, Path) else value
            for key, value in arguments.items()}


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parts", nargs="+", default=list(PARTS), choices=PARTS)
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2])
    parser.add_argument("--transitions", type=int, default=50_000,
                        help="transitions in each data set")
    parser.add_argument("--iterations", type=int, default=50, help="FQI's backups")
    parser.add_argument("--support-threshold", type=threshold, default=0.3,
                        help="FQI's offline constraint (support_threshold), or none")
    parser.add_argument("--gradient-steps", type=int, default=10_000,
                        help="d3rlpy's updates")
    parser.add_argument("--quick", action="store_true",
                        help="tiny sizes: " + ", ".join(f"{k} {v}" for k, v in QUICK.items()))
    parser.add_argument("--d3rlpy-python", default=None,
                        help="interpreter of a venv with d3rlpy, for the d3rlpy part when "
                             "d3rlpy does not import here")
    parser.add_argument("--out", type=Path, default=Path("results/offline"))
    parser.add_argument("--data", type=Path, default=Path("results/offline-data"),
                        help="folder of the data sets (.npz) and the d3rlpy policies")
    return sized_args(parser, parser.parse_args(argv), QUICK,
                      {"transitions": 1, "iterations": 1, "gradient_steps": 1})


def sized_args(parser, args, quick, minimums):
    """`args` with the medium behaviour's training steps, `quick`'s sizes under ``--quick``,
    and each size of `minimums` checked to be at least its value (else the parser's error)."""
    args.medium_training_steps = MEDIUM_TRAINING_STEPS
    if args.quick:
        for key, value in quick.items():
            setattr(args, key, value)
    for name, minimum in minimums.items():
        if getattr(args, name) < minimum:
            parser.error(f"--{name.replace('_', '-')} must be >= {minimum}, got "
                         f"{getattr(args, name)}")
    return args


def main(argv=None):
    args = parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    if "data" in args.parts:
        info = make_datasets(args.data, args.transitions, args.medium_training_steps)
        for name, about in info["datasets"].items():
            print(f"{name}: {about['transitions']:,} transitions, {about['episodes']} whole "
                  f"episodes, behaviour mean return {about['behaviour_mean_return']}")
    if "fqi" in args.parts:
        fqi_part(args)
    if "d3rlpy" in args.parts:
        d3rlpy_part(args)
    if "report" in args.parts:
        report_part(args)


if __name__ == "__main__":
    main()
