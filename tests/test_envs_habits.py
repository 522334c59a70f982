"""gymnasium habits on the ObjectWorld envs: the registered episode limit, and the partial
reset of the batched env (``reset(options={"reset_mask": mask})``) against gymnasium's own
vector env of single envs."""
import gymnasium as gym
import numpy as np
import pytest

import envs

IDS = {"ObjectWorld-v0": {}, "ObjectWorldSword-v0": {"sword": True},
       "ObjectWorldTreasure-v0": {"treasure": True}}


def _time_limits(env):
    """The limits of the `TimeLimit` wrappers around `env`, outermost first."""
    limits = []
    while env is not env.unwrapped:
        if isinstance(env, gym.wrappers.TimeLimit):
            limits.append(env._max_episode_steps)
        env = env.env
    return limits


def _play(env, seeds, actions):
    """Every step's ``(obs, reward, terminated, truncated)`` of `env`, one episode per seed
    and a reset after the last, each episode played until truncated."""
    record = []
    for seed in seeds:
        obs, _ = env.reset(seed=seed)
        record.append((obs,))
        truncated, t = False, 0
        while not truncated:
            obs, reward, terminated, truncated, _ = env.step(int(actions[t]))
            record.append((obs, reward, terminated, truncated))
            t += 1
    return record


def _assert_same_play(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x[0], y[0])
        assert x[1:] == y[1:]


# ------------------------------------------------------------------ the registered limit
@pytest.mark.parametrize("env_id", IDS)
def test_gymnasium_sees_the_registered_episode_limit(env_id):
    """The ids declare the default limit; a length given to ``make_vec`` in either keyword
    wins over it (gymnasium hands the registered one to the vector entry point)."""
    assert gym.spec(env_id).max_episode_steps == envs.WorldRules().max_steps == 50
    made = gym.make(env_id)
    assert _time_limits(made) == [50] and made.spec.max_episode_steps == 50
    assert made.unwrapped.spec.max_episode_steps == 50
    assert gym.make_vec(env_id, num_envs=2).spec.max_episode_steps == 50
    for length in ({"max_steps": 70}, {"max_episode_steps": 70},
                   {"max_steps": 70, "max_episode_steps": 70}):
        worlds = gym.make_vec(env_id, num_envs=3, **length)
        assert isinstance(worlds, envs.BatchedObjectWorld)
        assert worlds.rules.max_steps == 70 and worlds.spec.max_episode_steps == 70
        assert gym.make_vec(worlds.spec).rules == worlds.rules
        worlds.reset(seed=0)
        truncations = [worlds.step(np.zeros(3, dtype=int))[3].all() for _ in range(70)]
        assert truncations == [False] * 69 + [True]


@pytest.mark.parametrize("env_id", IDS)
@pytest.mark.parametrize("make_kwargs, length", [
    ({}, 50),
    ({"max_steps": 20}, 20),
    ({"max_steps": 70, "max_episode_steps": 70}, 70),
])
def test_make_plays_the_env_s_own_episodes(env_id, make_kwargs, length):
    """``gymnasium.make`` adds a `TimeLimit` that truncates on the env's own step or never:
    the episodes are those of the env built directly, and so are a remake's."""
    rules = {**IDS[env_id], "max_steps": length}
    actions = np.random.default_rng(0).integers(4, size=length)
    expected = _play(envs.ObjectWorldEnv(**rules), [3, None], actions)
    assert [len(step) == 4 and step[3] for step in expected].count(True) == 2
    made = gym.make(env_id, **make_kwargs)
    assert made.unwrapped.rules.max_steps == length
    limits = _time_limits(made)
    assert limits and all(limit >= length for limit in limits)
    _assert_same_play(_play(made, [3, None], actions), expected)
    _assert_same_play(_play(gym.make(made.spec), [3, None], actions), expected)


# ------------------------------------------------------------------ the partial reset
def _reference(n, rules):
    """gymnasium's own vector env of `n` single envs (next-step autoreset, as ours)."""
    return gym.vector.SyncVectorEnv([lambda: envs.ObjectWorldEnv(**rules)] * n)


def _assert_same_observations(obs, reference_obs):
    assert len(obs) == len(reference_obs)
    for i, expected in enumerate(reference_obs):
        np.testing.assert_array_equal(obs[i], expected)


@pytest.mark.parametrize("rules", [{"max_steps": 6}, {"max_steps": 9, "sword": True},
                                   {"max_steps": 7, "treasure": True, "view": "minimap"}])
def test_masked_reset_plays_as_gymnasium_s_vector_env(rules):
    """Partial resets (int, sequence and no seeds), then steps through autoresets of worlds
    at different steps of their episodes: world for world what gymnasium's `SyncVectorEnv`
    of single envs gives."""
    n = 5
    worlds, reference = envs.BatchedObjectWorld(n, **rules), _reference(n, rules)
    rng = np.random.default_rng(1)
    _assert_same_observations(worlds.reset(seed=3)[0], reference.reset(seed=3)[0])
    resets = [
        (np.array([False, True, False, False, True]), 40),
        (np.array([True, False, False, False, False]), [None, None, 7, 8, None]),
        (np.array([False, False, True, True, False]), None),
        (np.array([False, True, True, False, True]), [9, 10, 11, 12, 13]),
    ]
    for mask, seed in resets:
        for _ in range(rng.integers(1, 2 * rules["max_steps"])):
            actions = rng.integers(worlds.rules.n_actions, size=n)
            obs, *flags, info = worlds.step(actions)
            reference_obs, *reference_flags, _ = reference.step(actions)
            _assert_same_observations(obs, reference_obs)
            for ours, theirs in zip(flags, reference_flags):
                np.testing.assert_array_equal(ours, theirs)
            assert info == {}
        obs, info = worlds.reset(seed=seed, options={"reset_mask": mask})
        reference_obs, _ = reference.reset(seed=seed, options={"reset_mask": mask.copy()})
        _assert_same_observations(obs, reference_obs)
        assert info == {}
    assert len(set(worlds._engine.t.tolist())) > 1  # the worlds ended up out of step


def test_masked_reset_keeps_the_other_worlds_and_records_the_seeds():
    worlds, twin = envs.BatchedObjectWorld(4), envs.BatchedObjectWorld(4)
    for env in (worlds, twin):
        env.reset(seed=[5, 6, 7, 8])
        env.step(np.array([1, 2, 3, 0]))
    mask = np.array([False, True, False, True])
    obs, _ = worlds.reset(seed=20, options={"reset_mask": mask})
    np.testing.assert_array_equal(obs[1], envs.ObjectWorldEnv().reset(seed=21)[0])
    np.testing.assert_array_equal(obs[3], envs.ObjectWorldEnv().reset(seed=23)[0])
    assert worlds.np_random_seed == (5, 21, 7, 23)
    for _ in range(10):
        actions = np.array([0, 1, 2, 3])
        ours, theirs = worlds.step(actions), twin.step(actions)
        for i in (0, 2):  # the worlds not reset go on as if nothing happened
            np.testing.assert_array_equal(ours[0][i], theirs[0][i])
            assert ours[1][i] == theirs[1][i]
    worlds.reset(options={"reset_mask": np.array([True, False, False, False])})
    assert worlds.np_random_seed == (5, 21, 7, 23)  # no seed: the generator goes on


def test_planner_plans_worlds_out_of_step_as_it_plans_each_alone():
    worlds = envs.BatchedObjectWorld(3, max_steps=8)
    singles = [envs.ObjectWorldEnv(max_steps=8) for _ in range(3)]
    planner = envs.LookaheadPlanner(depth=3, width=4)
    worlds.reset(seed=[1, 2, 3])
    for env, seed in zip(singles, [1, 2, 3]):
        env.reset(seed=seed)
    for step in range(10):
        if step == 2:
            worlds.reset(seed=[None, 9, None], options={"reset_mask": np.array([0, 1, 0], bool)})
            singles[1].reset(seed=9)
        actions = planner.act(worlds)
        assert actions.tolist() == [planner.act(env) for env in singles]
        _, _, _, truncated, _ = worlds.step(actions)
        for env, action, done in zip(singles, actions, truncated):
            assert env.step(int(action))[3] == done
            if done:
                env.reset()
        if truncated.any():  # the autoreset step: the truncated worlds' actions are ignored
            for env, action, done in zip(singles, actions, truncated):
                if not done:
                    env.step(int(action))
            worlds.step(actions)


@pytest.mark.parametrize("mask, error, match", [
    (np.ones(3, dtype=bool), ValueError, r"shape \(4,\), one bool per world; got shape \(3,\)"),
    (np.ones((4, 1), dtype=bool), ValueError, r"got shape \(4, 1\)"),
    (np.array([1, 0, 1, 0]), TypeError, "must be bools, got dtype int64"),
    (np.zeros(4, dtype=bool), ValueError, "resets no world"),
])
def test_bad_reset_masks(mask, error, match):
    worlds = envs.BatchedObjectWorld(4)
    worlds.reset(seed=0)
    with pytest.raises(error, match=match):
        worlds.reset(options={"reset_mask": mask})


def test_partial_reset_needs_random_worlds_reset_before():
    mask = np.array([True, False])
    with pytest.raises(RuntimeError, match="call reset"):
        envs.BatchedObjectWorld(2).reset(options={"reset_mask": mask})
    worlds = envs.BatchedObjectWorld(2)
    worlds.reset(seed=0)
    with pytest.raises(ValueError, match="options\\['objects'\\] places the objects"):
        worlds.reset(options={"reset_mask": mask, "objects": [[1, 0, envs.MONEY]]})
    worlds.reset(seed=0, options={"objects": [[1, 0, envs.MONEY]]})
    with pytest.raises(ValueError, match="hold the objects of options\\['objects'\\]"):
        worlds.reset(options={"reset_mask": mask})
    with pytest.raises(ValueError, match="the only keys 'objects' and 'reset_mask'"):
        worlds.reset(options={"mask": mask})
    worlds.reset(options={"reset_mask": np.ones(2, dtype=bool)})  # every world: allowed
    worlds.reset(options={"reset_mask": mask})
