"""`BatchedObjectWorld` gives exactly the transitions of the single env, and its API."""
import gymnasium as gym
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import envs

VARIANTS = [
    {},
    {"sword": True},
    {"treasure": True},
    {"treasure": True, "view": "global"},
    {"treasure": True, "view": "minimap"},
    {"treasure": True, "view": "arrow"},
    {"sword": True, "enemy_speed": 0.9, "n_enemies": 60, "size_w": 12.5, "view_size": 4.0},
]


def _variant_id(rules):
    return ",".join(f"{k}={v}" for k, v in rules.items()) or "default"


@pytest.mark.parametrize("rules", VARIANTS, ids=_variant_id)
def test_batched_equals_single_step_by_step(rules):
    n, seeds = 6, [11, 12, 13, 14, 15, 10**12]
    worlds = envs.BatchedObjectWorld(n, **rules)
    singles = [envs.ObjectWorldEnv(**rules) for _ in range(n)]
    obs, _ = worlds.reset(seed=seeds)
    expected = [env.reset(seed=s)[0] for env, s in zip(singles, seeds)]
    rng = np.random.default_rng(0)
    greedy = envs.GreedyPolicy(worlds)
    n_steps = 0
    for episode in range(3):  # the second and third episodes continue the generators
        for t in range(50):
            for i in range(n):
                np.testing.assert_array_equal(obs[i], expected[i])
            if episode == 1:  # a sensible policy visits other situations than random play
                actions = greedy.predict(obs)[0]
            else:
                actions = rng.integers(worlds.single_action_space.n, size=n)
            obs, rewards, terminated, truncated, _ = worlds.step(actions)
            for i, env in enumerate(singles):
                expected[i], reward, term, trunc, _ = env.step(actions[i])
                assert (rewards[i], terminated[i], truncated[i]) == (reward, term, trunc)
            n_steps += 1
        assert truncated.all()
        obs, _ = worlds.reset()
        expected = [env.reset()[0] for env in singles]
    assert n_steps == 150


@pytest.mark.parametrize("rules", [{}, {"treasure": True, "view": "minimap"}], ids=_variant_id)
def test_batched_equals_single_across_chunks_of_noise(monkeypatch, rules):
    monkeypatch.setattr(envs._engine, "_NOISE_CHUNK", 5)  # 23 steps: chunks 5, ..., 5, 3
    n, seeds = 3, [4, 8, 31]
    worlds = envs.BatchedObjectWorld(n, max_steps=23, **rules)
    singles = [envs.ObjectWorldEnv(max_steps=23, **rules) for _ in range(n)]
    obs, _ = worlds.reset(seed=seeds)
    expected = [env.reset(seed=s)[0] for env, s in zip(singles, seeds)]
    actions = np.random.default_rng(1).integers(worlds.rules.n_actions, size=(2, 23, n))
    for episode in actions:  # the second episode continues the generators
        for batch in episode:
            for i in range(n):
                np.testing.assert_array_equal(obs[i], expected[i])
            obs, rewards, *_ = worlds.step(batch)
            for i, env in enumerate(singles):
                expected[i], reward, *_ = env.step(batch[i])
                assert rewards[i] == reward
        obs, _ = worlds.reset()
        expected = [env.reset()[0] for env in singles]


def test_make_vec_builds_the_batched_engine():
    worlds = gym.make_vec("ObjectWorldSword-v0", num_envs=3, n_enemies=5)
    assert isinstance(worlds, envs.BatchedObjectWorld) and worlds.num_envs == 3
    assert worlds.rules.sword and worlds.rules.n_enemies == 5
    obs, _ = worlds.reset(seed=0)
    np.testing.assert_array_equal(obs[2], gym.make("ObjectWorldSword-v0", n_enemies=5)
                                  .reset(seed=2)[0])


def test_make_vec_spec_carries_the_limit_and_remakes_the_env():
    worlds = gym.make_vec("ObjectWorldSword-v0", num_envs=3, max_steps=7)
    assert worlds.spec.max_episode_steps == 7 and worlds.spec.kwargs["num_envs"] == 3
    remade = gym.make_vec(worlds.spec)  # gymnasium passes max_episode_steps=7 to the entry
    assert isinstance(remade, envs.BatchedObjectWorld) and remade.rules == worlds.rules
    np.testing.assert_array_equal(remade.reset(seed=1)[0].data, worlds.reset(seed=1)[0].data)
    assert gym.make_vec("ObjectWorld-v0", num_envs=2).spec.max_episode_steps == 50
    assert gym.make_vec("ObjectWorld-v0", num_envs=2, max_episode_steps=9).rules.max_steps == 9
    with pytest.raises(ValueError, match="max_episode_steps=9 and max_steps=8 disagree"):
        gym.make_vec("ObjectWorld-v0", num_envs=2, max_episode_steps=9, max_steps=8)


def test_np_random_seed_follows_gymnasium_vector_envs():
    worlds = envs.BatchedObjectWorld(3)
    first, _ = worlds.reset()  # fresh entropy, recorded as the seed
    seed = worlds.np_random_seed
    np.testing.assert_array_equal(envs.BatchedObjectWorld(3).reset(seed=seed)[0].data,
                                  first.data)
    worlds.reset(seed=5)
    assert worlds.np_random_seed == 5
    worlds.reset()
    assert worlds.np_random_seed == 5  # continuing the generators keeps it
    worlds.reset(seed=[7, 3, 9])
    assert worlds.np_random_seed == (7, 3, 9)
    assert worlds.np_random.random() == np.random.default_rng([7, 3, 9]).random()
    assert worlds.np_random_seed == (7, 3, 9)  # reading np_random keeps it


def test_int_seed_gives_world_i_seed_plus_i():
    worlds = envs.BatchedObjectWorld(3)
    obs, _ = worlds.reset(seed=40)
    for i in range(3):
        np.testing.assert_array_equal(obs[i], envs.ObjectWorldEnv().reset(seed=40 + i)[0])


def test_worlds_do_not_depend_on_their_neighbours():
    small, _ = envs.BatchedObjectWorld(2).reset(seed=[5, 6])
    large, _ = envs.BatchedObjectWorld(50).reset(seed=[5] + list(range(100, 148)) + [6])
    np.testing.assert_array_equal(small[0], large[0])
    np.testing.assert_array_equal(small[1], large[49])


def test_observation_is_a_ragged_batch():
    worlds = envs.BatchedObjectWorld(5)
    obs, info = worlds.reset(seed=0)
    assert isinstance(obs, envs.RaggedBatch) and info == {}
    assert obs.data.dtype == np.float32 and obs.data.flags.c_contiguous
    assert obs.data.shape == (obs.offsets[-1], 3) and obs.offsets.dtype == np.intp
    assert len(obs) == 5 and [len(o) for o in obs] == obs.sizes.tolist()
    np.testing.assert_array_equal(obs[-1], obs[4])
    np.testing.assert_array_equal(np.concatenate(list(obs)), obs.data)
    assert worlds.observation_space.contains(tuple(obs))
    assert all(worlds.single_observation_space.contains(o) for o in obs)
    with pytest.raises(IndexError):
        obs[5]


@pytest.mark.parametrize("rules", [{}, {"treasure": True, "view": "arrow"}], ids=_variant_id)
def test_observations_lie_in_the_observation_space(rules):
    worlds = envs.BatchedObjectWorld(4, max_steps=2, **rules)
    space = worlds.observation_space
    obs, _ = worlds.reset(seed=0)
    assert space.contains(obs) and obs in space
    for _ in range(3):  # the last step autoresets
        obs = worlds.step(np.array([0, 1, 2, 3]))[0]
        assert space.contains(obs)
    assert space.contains(space.sample())
    assert not space.contains(envs.BatchedObjectWorld(3, **rules).reset(seed=0)[0])
    far = obs.data.copy()
    far[0, 0] = 1e3  # beyond the view
    assert not space.contains(envs.RaggedBatch(far, obs.offsets))
    assert space == gym.vector.utils.batch_space(worlds.single_observation_space, 4)


def test_vector_env_attributes():
    worlds = envs.BatchedObjectWorld(7, sword=True, view_size=8.0)
    assert isinstance(worlds, gym.vector.VectorEnv)
    assert worlds.num_envs == 7 and worlds.n_types == 4 and worlds.view_size == 8.0
    assert worlds.single_action_space == gym.spaces.Discrete(8)
    assert worlds.action_space.shape == (7,)
    assert worlds.metadata["autoreset_mode"] == gym.vector.AutoresetMode.NEXT_STEP


def test_step_after_truncation_autoresets_next_step():
    worlds = envs.BatchedObjectWorld(3, max_steps=4)
    worlds.reset(seed=1)
    for _ in range(4):
        _, rewards, _, truncated, _ = worlds.step(np.ones(3, dtype=int))
    assert truncated.all()
    obs, rewards, terminated, truncated, _ = worlds.step(np.ones(3, dtype=int))
    assert not truncated.any() and not terminated.any() and (rewards == 0).all()
    fresh = [env.reset(seed=1 + i)[0] for i, env in enumerate(
        [envs.ObjectWorldEnv(max_steps=4) for _ in range(3)])]
    singles = [envs.ObjectWorldEnv(max_steps=4) for _ in range(3)]
    for i, env in enumerate(singles):
        env.reset(seed=1 + i)
        np.testing.assert_array_equal(obs[i], env.reset()[0])  # continued generator
    assert not np.array_equal(obs[0], fresh[0])
    assert worlds.step(np.ones(3, dtype=int))[1].shape == (3,)


def test_rewards_and_flags_types():
    worlds = envs.BatchedObjectWorld(4)
    worlds.reset(seed=0)
    _, rewards, terminated, truncated, info = worlds.step(np.array([0, 1, 2, 3]))
    assert rewards.dtype == np.float64 and rewards.shape == (4,)
    assert terminated.dtype == bool and truncated.dtype == bool and info == {}


def test_layout_option_applies_to_every_world():
    worlds = envs.BatchedObjectWorld(3, move_noise=0.0)
    obs, _ = worlds.reset(seed=0, options={"objects": [[1, 0, envs.MONEY]]})
    _, rewards, *_ = worlds.step(np.array([1, 1, 3]))
    assert rewards.tolist() == [100.0, 100.0, 0.0]


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("actions, error, match", [
    (np.zeros(3, dtype=int), ValueError, r"shape \(4,\)"),
    (np.zeros((4, 1), dtype=int), ValueError, r"shape \(4,\)"),
    (0, ValueError, r"shape \(4,\)"),
    (np.zeros(4), TypeError, "actions must be ints, got dtype float64"),
    (np.ones(4, dtype=bool), TypeError, "actions must be ints, got dtype bool"),
    (np.array(["0"] * 4), TypeError, "actions must be ints"),
    (np.array([0, 1, 2, 4]), ValueError, "invalid action 4"),
    (np.array([0, -1, 2, 3]), ValueError, "invalid action -1"),
])
def test_bad_actions(actions, error, match):
    worlds = envs.BatchedObjectWorld(4)
    worlds.reset(seed=0)
    with pytest.raises(error, match=match):
        worlds.step(actions)


@pytest.mark.parametrize("seed, error, match", [
    ([1, 2], ValueError, "2 entries for 3 worlds"),
    ([1, 2, -3], ValueError, "non-negative"),
    ([1, 2, 3.5], TypeError, "non-negative ints, got 3.5"),
    ([1, 2, True], TypeError, "non-negative ints, got True"),
    (-1, ValueError, "non-negative"),
    ("abc", TypeError, "non-negative ints, got 'a'"),
    (2.5, TypeError, "sequence of 3 ints"),
    (True, TypeError, "sequence of 3 ints"),
])
def test_bad_seeds(seed, error, match):
    with pytest.raises(error, match=match):
        envs.BatchedObjectWorld(3).reset(seed=seed)


@pytest.mark.parametrize("n_worlds", [0, -2])
def test_too_few_worlds_is_a_value_error(n_worlds):
    with pytest.raises(ValueError, match="n_worlds must be >= 1"):
        envs.BatchedObjectWorld(n_worlds)


@pytest.mark.parametrize("n_worlds", [2.0, 1.5, True, "2", None])
def test_n_worlds_not_an_int_is_a_type_error(n_worlds):
    with pytest.raises(TypeError, match="n_worlds must be an int"):
        envs.BatchedObjectWorld(n_worlds)


def test_step_before_reset():
    with pytest.raises(RuntimeError, match="reset"):
        envs.BatchedObjectWorld(2).step(np.zeros(2, dtype=int))
    with pytest.raises(RuntimeError, match="reset"):
        envs.ObjectWorldEnv().step(0)


def test_ragged_batch_validates():
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        envs.RaggedBatch(np.zeros((2, 2)), [0, 2])
    with pytest.raises(ValueError, match="offsets"):
        envs.RaggedBatch(np.zeros((2, 3)), [0, 3])
    with pytest.raises(TypeError, match="ints"):
        envs.RaggedBatch(np.zeros((2, 3)), [0, 2])[0.5]


# --------------------------------------------------------------------------- random rules
@settings(max_examples=30, deadline=None)
@given(data=st.data())
def test_batched_equals_single_for_random_rules(data):
    treasure = data.draw(st.booleans())
    rules = {
        "sword": data.draw(st.booleans()),
        "treasure": treasure,
        "view": data.draw(st.sampled_from(envs.VIEWS if treasure else ("local", "global"))),
        "size_w": data.draw(st.floats(6.0, 40.0)),
        "n_money": data.draw(st.integers(0, 60)),
        "n_walls": data.draw(st.integers(0, 60)),
        "n_grass": data.draw(st.integers(0, 20)),
        "n_enemies": data.draw(st.integers(0, 40)),
        "enemy_speed": data.draw(st.floats(0.0, 1.5)),
        "contact_radius": data.draw(st.floats(0.5, 1.5)),
        "view_size": data.draw(st.floats(2.0, 12.0)),
        "max_steps": data.draw(st.integers(1, 12)),
        "n_treasure": data.draw(st.integers(0, 25)),
    }
    n = data.draw(st.integers(1, 4))
    seed = data.draw(st.integers(0, 2**32))
    worlds = envs.BatchedObjectWorld(n, **rules)
    singles = [envs.ObjectWorldEnv(**rules) for _ in range(n)]
    obs, _ = worlds.reset(seed=seed)
    expected = [env.reset(seed=seed + i)[0] for i, env in enumerate(singles)]
    actions = np.random.default_rng(seed).integers(worlds.rules.n_actions,
                                                   size=(rules["max_steps"], n))
    for batch in actions:
        for i in range(n):
            np.testing.assert_array_equal(obs[i], expected[i])
            assert worlds.single_observation_space.contains(obs[i])
        obs, rewards, _, truncated, _ = worlds.step(batch)
        for i, env in enumerate(singles):
            expected[i], reward, _, trunc, _ = env.step(batch[i])
            assert (rewards[i], truncated[i]) == (reward, trunc)
        assert (np.abs(worlds._engine.agent) < rules["size_w"]).all()  # the border holds
    assert truncated.all()
