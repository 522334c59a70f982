"""One unit of work per (setting, seed): an FQI run, an RMSE study, a DQN run, a tuned
stable-baselines3 run, a reference policy's score (the planner's ceiling, the scripted
heuristic, random play), or the attention figure's forest. Each returns a JSON-ready dict."""
import dataclasses
import inspect
import time
from functools import lru_cache

import gymnasium as gym
import numpy as np
from sklearn.base import clone
from sklearn.model_selection import KFold
from threadpoolctl import threadpool_limits

import envs
from boxtrees import ObjectSets
from fqi import (FQI, GridObservation, RandomPolicy, evaluate, make_box_forest, make_grid_ridge,
                 train_dqn)

__all__ = ["run_unit", "make_agent", "GAMMA"]

# Discount factor of every FQI and DQN run (the thesis does not state one; 0.5 scored best
# in the measured comparison of docs/fqi.md, "Discount factor"). Pinned here so a changed
# library default cannot silently change cached results.
GAMMA = 0.5
_TOP_TESTS = 4  # boxes drawn per action and object type in the attention figure
_ATTENTION_CANDIDATES = 40  # reference worlds searched for a busy view to draw on


def run_unit(params, budget, seed, samples, checkpoint=None):
    """Run one unit.

    Parameters
    ----------
    params : dict
        The setting's parameters (`Experiment.params`); ``params["kind"]`` picks the unit.
    budget : reproduce.budgets.Budget
    seed : int
    samples : int
        Samples per FQI iteration (the budget's, scaled by the experiment).
    checkpoint : reproduce.cache.Checkpoint, default=None
        An FQI run saves its state there after its iterations (at most every
        ``checkpoint.interval`` seconds) and resumes from what it finds there, to the result
        it would have had uninterrupted. Other kinds ignore it.

    Returns
    -------
    result : dict
        JSON-ready; always has ``seconds`` (a resumed run's: of all its parts).
    """
    start = time.perf_counter()
    runner = {"fqi": _fqi, "rmse": _rmse, "dqn": _dqn, "sb3": _sb3, "policy": _policy,
              "attention": _attention}
    resumable = {"checkpoint": checkpoint} if params["kind"] == "fqi" else {}
    # One BLAS thread: the forests bring their own threads, and on 2 shared cores the
    # ridge fit of the grid baseline ran 10x slower with OpenBLAS's 2 threads (measured).
    with threadpool_limits(1, user_api="blas"):
        result = runner[params["kind"]](params, budget, seed, samples, **resumable)
    result["seconds"] = result.pop("earlier_seconds", 0.0) + time.perf_counter() - start
    return result


def _env_kwargs(params):
    """The game's arguments a setting changes: its ``view`` and its ``rules`` (constants of
    `envs.WorldRules`, for the ablations)."""
    return {**({"view": params["view"]} if "view" in params else {}), **params.get("rules", {})}


def _make_env(params):
    return gym.make(params["env_id"], **_env_kwargs(params))


def _reference_seeds(env, budget):
    """The thesis's evaluation on the game's reference worlds: one episode of ``max_steps``
    per world, ``budget.eval_steps`` steps in all."""
    return envs.reference_worlds(budget.eval_steps // env.unwrapped.rules.max_steps)


def _regressor(params, env, budget, seed):
    """The setting's regressor, with the budget's caps on M and K."""
    if params["model"] == "grid":
        return make_grid_ridge(env, n_bins=params["n_bins"], alpha=params.get("alpha", 1.0))
    return make_box_forest(
        env, test_type=params["test_type"], test_width=params.get("test_width", 1.0),
        n_estimators=_capped(params["n_estimators"], budget.max_trees),
        n_tests=_capped(params["n_tests"], budget.max_tests),
        min_samples_split=params["min_samples_split"], n_jobs=-1, random_state=seed)


def _capped(value, cap):
    return value if cap is None else min(value, cap)


def make_agent(params, budget, seed, samples):
    """The FQI agent of a registry setting on the game: up to 400 training worlds in
    lockstep (the game's batched engine, through its vector entry point), evaluated on the
    reference worlds.

    Parameters
    ----------
    params : dict
        A setting's parameters (`Experiment.params`); ``gamma`` may override `GAMMA`.
    budget : reproduce.budgets.Budget
        Its caps on trees and tests, and its evaluation steps.
    seed : int
    samples : int
        Samples per iteration.

    Returns
    -------
    agent : fqi.FQI
    """
    env = _make_env(params)
    return FQI(_regressor(params, env, budget, seed), env, gamma=params.get("gamma", GAMMA),
               samples_per_iteration=samples,
               resample_every=params.get("resample_every", 1),
               keep_data=params.get("keep_data", False),
               max_samples=max(params.get("max_samples", samples), samples),
               n_envs=min(400, samples), eval_seeds=_reference_seeds(env, budget), seed=seed)


def _fqi(params, budget, seed, samples, checkpoint=None):
    """Rewards per iteration (per 20,000 evaluation steps) and the random policy's; with a
    `checkpoint`, the pickled agent (its envs and random streams) after an iteration but the
    last, which a later call resumes."""
    start = time.perf_counter()
    saved = None if checkpoint is None else checkpoint.load()
    agent, earlier = ((saved["agent"], saved["seconds"]) if saved is not None
                      else (make_agent(params, budget, seed, samples), 0.0))

    def save(locals_, globals_):
        if agent.iteration < budget.iterations:
            checkpoint.save({"agent": agent,
                             "seconds": earlier + time.perf_counter() - start})

    if agent.iteration < budget.iterations:
        agent.learn(budget.iterations - agent.iteration,
                    callback=None if checkpoint is None else save)
    scale = budget.reward_scale
    env = _make_env(params)
    random_reward = evaluate(RandomPolicy(env, seed=seed), env,
                             seeds=_reference_seeds(env, budget)).total
    keys = ("n_samples", "nodes_per_tree", "t_collect", "t_fit", "t_evaluate", "t_total")
    return {"rewards": [r["reward"] * scale for r in agent.history],
            "random_reward": random_reward * scale,
            "history": [{k: r[k] for k in keys} for r in agent.history],
            "earlier_seconds": earlier}


@lru_cache(maxsize=4)
def _random_transitions(env_id, env_kwargs, n_samples, seed):
    """`n_samples` (state, action, reward) of the uniform random policy on training worlds
    (seeds below ``2**40``), shuffled later by the folds; `env_kwargs` as sorted pairs."""
    rules = gym.make(env_id, **dict(env_kwargs)).unwrapped.rules
    n_worlds = min(400, n_samples)
    worlds = envs.BatchedObjectWorld(n_worlds, **dataclasses.asdict(rules))
    rng = np.random.default_rng(seed)
    states, actions, rewards = [], [], []
    obs, _ = worlds.reset(seed=rng.integers(2**40, size=n_worlds).tolist())
    for step in range(-(-n_samples // n_worlds)):
        if step and step % rules.max_steps == 0:
            obs, _ = worlds.reset()  # lockstep worlds end their episodes together
        action = rng.integers(rules.n_actions, size=n_worlds)
        states.append(ObjectSets(obs.data.copy(), obs.offsets.copy()))
        actions.append(action)
        obs, reward, _, _, _ = worlds.step(action)
        rewards.append(reward.copy())
    return (ObjectSets.concatenate(states)[:n_samples],
            np.concatenate(actions)[:n_samples], np.concatenate(rewards)[:n_samples])


def _rmse(params, budget, seed, samples):
    """Appendix A: k-fold cross-validated RMSE of the first FQI iteration's regression
    (targets = immediate rewards), per action, averaged over the actions."""
    env = _make_env(params)
    states, actions, rewards = _random_transitions(
        params["env_id"], tuple(sorted(_env_kwargs(params).items())), budget.rmse_samples, seed)
    template = _regressor(params, env, budget, seed)
    folds = KFold(budget.rmse_folds, shuffle=True, random_state=seed)
    per_action = []
    for action in range(env.action_space.n):
        index = np.flatnonzero(actions == action)
        X, y = states[index], rewards[index]
        errors = []
        for train, test in folds.split(index):
            model = clone(template).fit(X[train], y[train])
            errors.append(float(np.sqrt(np.mean((model.predict(X[test]) - y[test]) ** 2))))
        per_action.append(errors)
    per_action = np.array(per_action)
    return {"fold_rmse": per_action.mean(axis=0).tolist(),
            "action_rmse": per_action.mean(axis=1).tolist(),
            "n_samples": len(rewards)}


def _dqn(params, budget, seed, samples):
    """stable-baselines3 DQN with as many env steps as one FQI run of the budget."""
    steps = budget.dqn_steps or budget.iterations * samples
    result = train_dqn(params["env_id"], total_timesteps=steps, n_bins=params["n_bins"],
                       gamma=GAMMA, eval_seeds=_reference_seeds(_make_env(params), budget),
                       seed=seed)
    return {"reward": result.reward * budget.reward_scale, "total_timesteps": steps,
            "train_seconds": result.train_seconds, "eval_seconds": result.eval_seconds}


def _sb3(params, budget, seed, samples):
    """A stable-baselines3 ``DQN`` or ``PPO`` run, its reward on the reference worlds at
    ``params["checkpoints"]`` evenly spaced points of training (the last at the end).

    ``params``: ``algo`` ("DQN" or "PPO"), ``observation`` ("grid": `fqi.GridObservation`
    counts with ``n_bins``; "objects": `envs.PaddedObjects` of ``max_objects`` rows through
    `fqi.SetEncoder`, with ``attention``), ``hyperparams`` (the algorithm's keyword
    arguments; ``n_envs`` training envs; ``normalize``, rl-zoo3's key: train on rewards
    scaled by a running estimate of the return's spread, `VecNormalize` on rewards only,
    where rl-zoo3 also scales observations, since these hold padding rows and a presence
    mask), ``step_scale`` (the share of one FQI run's environment steps it gets).
    """
    import torch
    from stable_baselines3 import DQN, PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.logger import Logger
    from stable_baselines3.common.vec_env import VecNormalize

    from fqi import SetEncoder   # imports torch: only here

    steps = round((budget.dqn_steps or budget.iterations * samples) * params["step_scale"])
    hyperparams = dict(params["hyperparams"])
    n_envs = hyperparams.pop("n_envs", 1)
    normalize = hyperparams.pop("normalize", False)
    if params["observation"] == "grid":
        def wrap(env):
            return GridObservation(env, n_bins=params["n_bins"])
    else:
        def wrap(env):
            return envs.PaddedObjects(env, max_objects=params["max_objects"])
        hyperparams["policy_kwargs"] = {
            **hyperparams.get("policy_kwargs", {}), "features_extractor_class": SetEncoder,
            "features_extractor_kwargs": {"attention": params["attention"]}}
    algo = {"DQN": DQN, "PPO": PPO}[params["algo"]]
    train_env = make_vec_env(lambda: wrap(_make_env(params)), n_envs=n_envs, seed=seed)
    if normalize:  # the evaluation plays the raw env and counts raw rewards
        gamma = hyperparams.get("gamma", inspect.signature(algo).parameters["gamma"].default)
        train_env = VecNormalize(train_env, norm_obs=False, norm_reward=True, gamma=gamma)
    model = algo("MlpPolicy", train_env, seed=seed, device="cpu", **hyperparams)
    model.set_logger(Logger(None, []))  # SB3's default logger makes a folder per run
    eval_env = _make_env(params)
    eval_wrapper = wrap(eval_env)    # pads or counts the evaluation's observations
    policy = _WrappedPolicy(model, eval_wrapper)
    reference = _reference_seeds(eval_wrapper, budget)
    due = [round(steps * (k + 1) / params["checkpoints"]) for k in range(params["checkpoints"])]
    curve, eval_seconds = [], [0.0]

    def checkpoint(model_steps):
        start = time.perf_counter()
        total = evaluate(policy, eval_env, seeds=reference).total
        curve.append([int(model_steps), total * budget.reward_scale])
        eval_seconds[0] += time.perf_counter() - start

    class Checkpoints(BaseCallback):
        def _on_step(self):
            if len(curve) < len(due) - 1 and self.num_timesteps >= due[len(curve)]:
                checkpoint(self.num_timesteps)
            return True

    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # on 2 shared cores the default pool ran 12x slower (measured)
    try:
        start = time.perf_counter()
        model.learn(total_timesteps=steps, callback=Checkpoints())
        checkpoint(model.num_timesteps)
        train_seconds = time.perf_counter() - start - eval_seconds[0]
    finally:
        torch.set_num_threads(threads)
    train_env.close()
    return {"reward": curve[-1][1], "curve": curve, "total_timesteps": int(model.num_timesteps),
            "train_seconds": train_seconds, "eval_seconds": eval_seconds[0]}


def _policy(params, budget, seed, samples):
    """The score of a reference policy that does not learn, on the reference worlds:
    ``params["policy"]`` is "planner" (`envs.LookaheadPlanner` with ``depth`` and ``width``:
    the ceiling, it plays with the simulator), "greedy" (`envs.GreedyPolicy`, scripted) or
    "random" (uniform, action seed `seed`). Played through `fqi.evaluate`, as the learners."""
    if params["policy"] not in ("planner", "greedy", "random"):
        raise ValueError(f"unknown reference policy {params['policy']!r}")
    env = _make_env(params)
    reference = _reference_seeds(env, budget)
    env.close()
    worlds = gym.make_vec(params["env_id"], num_envs=len(reference), **_env_kwargs(params))
    if params["policy"] == "planner":
        planner = envs.LookaheadPlanner(**{k: params[k] for k in ("depth", "width")
                                           if k in params})
        policy = _PlannerPolicy(planner, worlds)
    elif params["policy"] == "greedy":
        policy = envs.GreedyPolicy(worlds)
    else:
        policy = RandomPolicy(worlds, seed=seed)
    result = evaluate(policy, worlds, seeds=reference)
    worlds.close()
    player = repr(planner) if params["policy"] == "planner" else type(policy).__name__
    return {"reward": result.total * budget.reward_scale, "player": player,
            "episode_returns": result.returns.tolist()}


class _PlannerPolicy:
    """`envs.LookaheadPlanner` behind ``predict``: it plans from the state of `worlds`
    (the vector env being evaluated), not from the observations."""

    def __init__(self, planner, worlds):
        self.planner, self.worlds = planner, worlds

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return self.planner.act(self.worlds), None


class _WrappedPolicy:
    """A model trained on an observation wrapper's output, playing from object sets (the
    wrapper's ``observation`` applied to each)."""

    def __init__(self, model, wrapper):
        self.model, self.wrapper = model, wrapper

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        sets = [observation[i] for i in range(len(observation))]
        batch = np.stack([self.wrapper.observation(s) for s in sets])
        return self.model.predict(batch, deterministic=deterministic)[0], None


def _attention(params, budget, seed, samples):
    """A short FQI run; per action, the most informative tests on each object type and the
    share of test usage per type, and a busy reference view to draw them on."""
    agent = make_agent(params, budget, seed, samples).learn(budget.attention_iterations)
    n_types = _make_env(params).unwrapped.n_types
    world_seed, observation = _busy_reference_view(params)
    actions = []
    for forest in agent.q_functions_:
        tests = np.concatenate([_tree_tests(tree.tree_) for tree in forest.estimators_])
        tests = tests[np.argsort(-tests[:, 7], kind="stable")]
        top = np.concatenate([tests[tests[:, 4] == t][:_TOP_TESTS] for t in range(n_types)])
        usage = np.bincount(tests[:, 4].astype(int), weights=tests[:, 6],
                            minlength=n_types)
        share = usage / usage.sum() if usage.sum() else usage  # a tree without tests
        actions.append({"tests": top.tolist(), "type_usage": share.tolist()})
    return {"world_seed": world_seed, "observation": observation.tolist(),
            "q_values": agent.q_values(observation).tolist(),
            "reward": agent.history[-1]["reward"] * budget.reward_scale,
            "test_columns": ["xmin", "xmax", "ymin", "ymax", "type", "threshold",
                             "n_node_samples", "variance_reduction", "effect"],
            "actions": actions}


def _tree_tests(tree):
    """Inner nodes of a `boxtrees.BoxTree` as rows ``[xmin, xmax, ymin, ymax, type,
    threshold, n_node_samples, weighted variance reduction, effect]``: the effect is the Q
    value of the node's right child (at least ``threshold`` objects in the box) minus its
    left child's, positive when the objects in the box attract the agent (the thesis's blue
    boxes), negative when they repel it (red)."""
    inner = np.flatnonzero(tree.children_left >= 0)
    left, right = tree.children_left[inner], tree.children_right[inner]
    w, imp = tree.weighted_n_node_samples, tree.impurity
    reduction = w[inner] * imp[inner] - w[left] * imp[left] - w[right] * imp[right]
    effect = tree.value[right] - tree.value[left]
    return np.column_stack([tree.box[inner], tree.object_type[inner], tree.threshold[inner],
                            tree.n_node_samples[inner], reduction, effect]).astype(np.float64)


def _busy_reference_view(params):
    """The first reference world (never trained on) whose starting view holds the most
    object types, then the most objects: its seed and observation."""
    env = _make_env(params)
    best = None
    for world_seed in envs.reference_worlds(_ATTENTION_CANDIDATES):
        obs, _ = env.reset(seed=world_seed)
        key = (len(np.unique(obs[:, 2])), len(obs))
        if best is None or key > best[0]:
            best = (key, world_seed, obs)
    env.close()
    return best[1], best[2]
