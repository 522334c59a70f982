"""The ObjectWorld rules, the gymnasium API, rendering, wrappers and bad input."""
import copy
import hashlib
import tracemalloc

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import envs
from envs import ENEMY, GRASS, MONEY, WALL

IDS = ["ObjectWorld-v0", "ObjectWorldSword-v0", "ObjectWorldTreasure-v0"]
UP, RIGHT, DOWN, LEFT, SWIPE_UP, SWIPE_RIGHT = 0, 1, 2, 3, 4, 5


def scripted(objects, **rules):
    """A noise-free env with static enemies whose world holds exactly `objects`."""
    rules = {"move_noise": 0.0, "enemy_speed": 0.0, **rules}
    env = envs.ObjectWorldEnv(**rules)
    obs, _ = env.reset(seed=0, options={"objects": np.array(objects, dtype=float).reshape(-1, 3)})
    return env, obs


def of_type(obs, kind):
    return obs[obs[:, 2] == kind, :2]


# --------------------------------------------------------------------------- gymnasium API
@pytest.mark.parametrize("env_id", IDS)
def test_check_env_every_id(env_id):
    check_env(gym.make(env_id, render_mode="rgb_array").unwrapped)


@pytest.mark.parametrize("view", envs.VIEWS)
def test_check_env_every_treasure_view(view):
    check_env(gym.make("ObjectWorldTreasure-v0", view=view, render_mode="rgb_array").unwrapped)


def test_spaces_and_type_constants():
    assert (envs.MONEY, envs.WALL, envs.GRASS, envs.ENEMY) == (0, 1, 2, 3)
    assert {envs.MONEY_MARKER, envs.TREASURE_MARKER, envs.ARROW} == {4, 5, 6}
    assert gym.make("ObjectWorld-v0").action_space == gym.spaces.Discrete(4)
    assert gym.make("ObjectWorldSword-v0").action_space == gym.spaces.Discrete(8)
    sizes = {view: gym.make("ObjectWorldTreasure-v0", view=view).unwrapped.n_types
             for view in envs.VIEWS}
    assert sizes == {"local": 4, "global": 4, "minimap": 6, "arrow": 7}
    space = envs.ObjectWorldEnv().observation_space
    assert isinstance(space, gym.spaces.Sequence) and space.stack
    assert space.feature_space.shape == (3,) and space.feature_space.dtype == np.float32


def test_episode_truncates_after_max_steps_and_reset_draws_new_world():
    env = envs.ObjectWorldEnv()
    first, _ = env.reset(seed=1)
    for t in range(50):
        obs, reward, terminated, truncated, _ = env.step(t % 4)
        assert obs.dtype == np.float32 and obs.ndim == 2 and obs.shape[1] == 3
        assert isinstance(reward, float) and not terminated
        assert truncated == (t == 49)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(0)
    second, _ = env.reset()
    assert not np.array_equal(first, second)
    assert np.array_equal(first, env.reset(seed=1)[0])


def test_world_seeds_reproduce_and_differ():
    a, b = envs.ObjectWorldEnv(), envs.ObjectWorldEnv()
    assert np.array_equal(a.reset(seed=7)[0], b.reset(seed=7)[0])
    assert not np.array_equal(a.reset(seed=7)[0], b.reset(seed=8)[0])
    actions = [1, 1, 0, 3, 2, 2, 1]
    assert [a.step(x)[1:4] for x in actions] == [b.step(x)[1:4] for x in actions]


def test_np_random_seed_is_the_reset_seed():
    env = gym.make("ObjectWorld-v0")
    env.reset(seed=5)
    assert env.np_random_seed == 5 == env.unwrapped.np_random_seed
    env.reset()
    assert env.np_random_seed == 5  # continuing the generator keeps the seed
    worlds = gym.make_vec("ObjectWorld-v0", num_envs=3)
    worlds.reset(seed=5)
    assert worlds.np_random_seed == 5  # world i has seed 5 + i, as in gymnasium's vector envs


def test_spec_carries_the_episode_limit():
    env = gym.make("ObjectWorld-v0")
    assert env.spec.max_episode_steps == 50 == env.unwrapped.spec.max_episode_steps
    longer = gym.make("ObjectWorldSword-v0", max_steps=70, max_episode_steps=70)
    assert longer.spec.max_episode_steps == 70 == longer.unwrapped.spec.max_episode_steps
    remade = gym.make(longer.spec)  # adds the TimeLimit at the env's own limit again
    assert remade.spec.max_episode_steps == 70 and remade.unwrapped.rules.max_steps == 70
    for env in (longer, remade):
        env.reset(seed=2)
        truncations = [env.step(t % 8)[3] for t in range(70)]
        assert truncations == [False] * 69 + [True]
    shorter = gym.make("ObjectWorld-v0", max_steps=20)  # its TimeLimit at 50 is never reached
    assert shorter.spec.max_episode_steps == 50 and shorter.unwrapped.spec.max_episode_steps == 20
    assert envs.ObjectWorldEnv().spec is None


def test_reference_worlds_are_fixed_and_disjoint_from_training_seeds():
    seeds = envs.reference_worlds(400)
    assert seeds == envs.reference_worlds(400) and len(set(seeds)) == 400
    assert min(seeds) == envs.REFERENCE_SEED_START >= 2**32
    assert envs.reference_worlds(3) == seeds[:3]


# --------------------------------------------------------------------------- rules
def test_money_is_collected_once_and_removed():
    env, obs = scripted([[1, 0, MONEY]])
    assert len(of_type(obs, MONEY)) == 1
    obs, reward, *_ = env.step(RIGHT)
    assert reward == 100.0 and len(of_type(obs, MONEY)) == 0
    assert env.step(LEFT)[1] == 0.0 and env.step(RIGHT)[1] == 0.0


def test_money_on_the_path_is_collected_without_landing_on_it():
    env, _ = scripted([[0.5, 0.55, MONEY]])  # 0.55 from the path, 0.74 from either end
    assert env.step(RIGHT)[1] == 100.0


def test_wall_blocks_and_costs_50():
    env, before = scripted([[1.3, 0, WALL], [0, 5, GRASS]])
    after, reward, *_ = env.step(RIGHT)
    assert reward == -50.0
    np.testing.assert_array_equal(after, before)  # the agent did not move
    assert env.step(UP)[1] == 0.0  # other directions are free


def test_wall_blocks_the_whole_move_so_money_behind_it_stays():
    env, _ = scripted([[0.4, 0, MONEY], [1.0, 0, WALL]])
    obs, reward, *_ = env.step(RIGHT)
    assert reward == -50.0 and len(of_type(obs, MONEY)) == 1


def test_grass_does_nothing():
    env, _ = scripted([[1, 0, GRASS]])
    obs, reward, *_ = env.step(RIGHT)
    assert reward == 0.0
    np.testing.assert_allclose(of_type(obs, GRASS), [[0.0, 0.0]], atol=1e-6)


def test_enemy_contact_costs_300_and_removes_it():
    env, _ = scripted([[1, 0, ENEMY], [1, 0.2, ENEMY], [0, 4, ENEMY]])
    obs, reward, *_ = env.step(RIGHT)
    assert reward == -600.0
    np.testing.assert_allclose(of_type(obs, ENEMY), [[-1, 4]], atol=1e-6)


def test_enemies_in_view_chase_slower_than_the_agent_and_others_wait():
    env, obs = scripted([[5, 0, ENEMY], [0, -15, ENEMY]], enemy_speed=0.2,
                        view="global")
    obs, reward, *_ = env.step(LEFT)
    near, far = of_type(obs, ENEMY)
    np.testing.assert_allclose(near, [6 - 0.2, 0], atol=1e-6)  # gap grew by 1 - 0.2
    np.testing.assert_allclose(far, [1, -15], atol=1e-6)  # outside the view: static
    assert reward == 0.0


def test_enemy_reaching_the_agent_hurts():
    env, _ = scripted([[0, 2.0, ENEMY]], enemy_speed=0.7)
    rewards = [env.step(RIGHT if t % 2 else LEFT)[1] for t in range(4)]
    assert rewards.count(-300.0) == 1 and rewards[-1] == 0.0


def test_move_noise_is_uniform_within_a_tenth():
    env = envs.ObjectWorldEnv(n_money=0, n_walls=0, n_grass=0, n_enemies=0)
    steps = []
    for seed in range(8):
        obs, _ = env.reset(seed=seed, options={"objects": [[0, 9, GRASS]]})
        for _ in range(5):
            new, *_ = env.step(RIGHT)
            steps.append(of_type(obs, GRASS)[0] - of_type(new, GRASS)[0])
            obs = new
    noise = np.array(steps) - [1.0, 0.0]
    assert np.abs(noise).max() <= 0.1 + 1e-6
    assert noise.std(axis=0).min() > 0.03  # really random, on both coordinates


@pytest.mark.parametrize("enemies, expected, left", [
    ([[0, 2, ENEMY]], 300.0, 0),
    ([[0.5, 1.5, ENEMY], [-0.5, 2.5, ENEMY]], -900.0, 2),
    ([[0.4, 1.2, ENEMY], [1.0, 2.0, ENEMY], [-1.0, 2.9, ENEMY]], -900.0, 3),
    ([], -750.0, 0),
    ([[0, 3.3, ENEMY], [1.7, 1, ENEMY], [0, -2, ENEMY]], -750.0, 3),  # all outside the square
])
def test_swipe_rewards(enemies, expected, left):
    env, _ = scripted(enemies + [[0, 2, WALL]], sword=True)
    obs, reward, *_ = env.step(SWIPE_UP)
    assert reward == expected
    assert len(of_type(obs, ENEMY)) == left
    assert len(of_type(obs, WALL)) == 1  # walls are not hit, the agent did not move


def test_swipe_directions():
    env, _ = scripted([[2, 0, ENEMY]], sword=True)
    assert env.step(SWIPE_UP)[1] == -750.0
    assert env.step(SWIPE_RIGHT)[1] == 300.0


def test_border_walls_hold_the_agent_in():
    env = envs.ObjectWorldEnv(n_money=0, n_walls=0, n_grass=0, n_enemies=0, max_steps=50)
    obs, _ = env.reset(seed=3)
    rewards = []
    for _ in range(45):
        obs, reward, *_ = env.step(RIGHT)
        rewards.append(reward)
    walls = of_type(obs, WALL)
    assert len(walls) > 10 and np.allclose(walls[:, 0], walls[0, 0])  # one straight border
    assert 0.6 <= walls[0, 0] <= 1.8  # stopped just before it
    assert rewards[:28] == [0.0] * 28 and rewards[-10:] == [-50.0] * 10


def test_view_is_clipped_to_ten_units():
    env, obs = scripted([[9.9, -9.9, GRASS], [10.2, 0, GRASS], [0, -10.4, MONEY]])
    np.testing.assert_allclose(obs, [[9.9, -9.9, GRASS]], atol=1e-6)
    env = envs.ObjectWorldEnv()
    env.reset(seed=0)
    for t in range(50):
        obs = env.step(t % 4)[0]
        assert np.abs(obs[:, :2]).max() <= 10.0


def test_global_view_sees_every_object():
    env = envs.ObjectWorldEnv(view="global")
    obs, _ = env.reset(seed=0)
    n_border = 4 * 60
    assert len(obs) == n_border + 40 + 30 + 30 + 13
    assert np.abs(obs[:, :2]).max() > 25


def test_treasure_stack_lies_near_a_border():
    env = envs.ObjectWorldEnv(treasure=True, view="global", n_money=0)
    for seed in range(5):
        obs, _ = env.reset(seed=seed)
        coins = of_type(obs, MONEY)  # the agent starts at the centre: world coordinates
        assert len(coins) == 20
        centre = coins.mean(axis=0)
        assert np.linalg.norm(coins - centre, axis=1).max() <= 2.0
        assert abs(np.abs(centre).max() - 27.0) <= 1.0  # 3 units inside one side


def test_minimap_markers_disappear_once_the_cell_is_visited():
    env = envs.ObjectWorldEnv(treasure=True, view="minimap", move_noise=0.0)
    obs, _ = env.reset(seed=0, options={"objects": [[15, 0, MONEY]]})
    east = (20 - 0) / 6  # the east cell's centre, world shrunk 6 times into the view
    markers = of_type(obs, envs.MONEY_MARKER)
    assert len(markers) >= 1 and len(of_type(obs, envs.TREASURE_MARKER)) == 1
    assert np.any(np.all(np.isclose(markers, [east, 0], atol=1e-5), axis=1))
    assert not np.any(np.all(np.isclose(markers, [0, 0], atol=1e-5), axis=1))  # start cell
    for _ in range(11):
        obs = env.step(RIGHT)[0]
    markers = of_type(obs, envs.MONEY_MARKER)
    assert not np.any(np.isclose(markers[:, 0], (20 - 11) / 6, atol=1e-5) & (markers[:, 1] == 0))
    assert len(of_type(obs, MONEY)) == 1  # left the money, yet the marker went


def test_treasure_marker_goes_when_its_cell_is_visited():
    env = envs.ObjectWorldEnv(treasure=True, view="minimap", n_enemies=0, n_walls=0,
                              n_grass=0, n_money=0, max_steps=50)
    obs, _ = env.reset(seed=4)
    mark = of_type(obs, envs.TREASURE_MARKER)[0]
    direction = np.argmax([mark[1], mark[0], -mark[1], -mark[0]])  # walk toward it
    for _ in range(25):
        obs = env.step(direction)[0]
    assert len(of_type(obs, envs.TREASURE_MARKER)) == 0


def test_arrow_points_at_the_treasure():
    arrow_env = envs.ObjectWorldEnv(treasure=True, view="arrow", n_money=0)
    global_env = envs.ObjectWorldEnv(treasure=True, view="global", n_money=0)
    for seed in range(5):
        obs, _ = arrow_env.reset(seed=seed)
        world, _ = global_env.reset(seed=seed)  # same seed: same treasure
        for action in [0, 1, 1, 2]:
            obs, world = arrow_env.step(action)[0], global_env.step(action)[0]
        (arrow,) = of_type(obs, envs.ARROW)
        goal = of_type(world, MONEY).mean(axis=0)
        assert np.linalg.norm(arrow) == pytest.approx(9.0, rel=1e-5)
        cosine = arrow @ goal / (np.linalg.norm(arrow) * np.linalg.norm(goal))
        assert cosine > 0.998


def _legs(t):
    """Ten steps up, ten right, ten down, ten left, and again."""
    return (t // 10) % 4


def _legs_and_swipes(t):
    return 4 + t % 4 if t % 5 == 0 else _legs(t)


def _east_then_legs(t):
    return RIGHT if t < 30 else _legs(t)


# Transitions as the code behind the committed results played them: a digest of every
# observation and reward (and of the next reset's observation), and each episode's total
# reward. Any change to a world's generator stream (layout, move noise, clearance redraws,
# where the next episode starts) changes them. Seed 4 redraws objects near the start; 600
# steps span several chunks of noise.
PINNED = [
    ({}, 3, 2, _legs, "dfbe9133527b1918", [-900.0, -600.0]),
    ({}, 4, 2, _legs, "ffa2ff35db16d2f5", [-800.0, -500.0]),
    ({"sword": True}, 9, 1, _legs_and_swipes, "a1e28a2216949774", [-7650.0]),
    ({"treasure": True}, 5, 2, _east_then_legs, "b4bfe12e37ffff27", [-50.0, -50.0]),
    ({"max_steps": 600}, 3, 1, _legs, "f5ea5ce39ae92e7b", [-800.0]),
]


@pytest.mark.parametrize("rules, seed, n_episodes, policy, digest, totals", PINNED)
def test_transitions_are_pinned(rules, seed, n_episodes, policy, digest, totals):
    env = envs.ObjectWorldEnv(**rules)
    played = hashlib.sha256()
    episode_totals = []
    obs, _ = env.reset(seed=seed)
    for _ in range(n_episodes):
        played.update(obs.tobytes())
        total = 0.0
        for t in range(env.rules.max_steps):
            obs, reward, _, truncated, _ = env.step(policy(t))
            played.update(obs.tobytes() + np.float64(reward).tobytes())
            total += reward
        assert truncated
        episode_totals.append(total)
        obs, _ = env.reset()
    played.update(obs.tobytes())
    assert (played.hexdigest()[:16], episode_totals) == (digest, totals)


@pytest.mark.parametrize("bit_generator", [np.random.PCG64, np.random.MT19937])
def test_move_noise_is_the_stream_after_the_layout_episode_after_episode(monkeypatch,
                                                                         bit_generator):
    # Small chunks, so that an episode spans several; MT19937 cannot jump and skips by drawing.
    monkeypatch.setattr(envs._engine, "_NOISE_CHUNK", 7)
    env = envs.ObjectWorldEnv(n_money=0, n_walls=0, n_grass=0, n_enemies=0, max_steps=30)
    env.np_random = np.random.Generator(bit_generator(7))
    stream = copy.deepcopy(env.np_random)  # no layout draws: the noise comes first
    noise = []
    for _ in range(2):
        obs, _ = env.reset(options={"objects": [[0, 3, GRASS]]})
        for t in range(30):
            new, *_ = env.step(RIGHT if t % 2 else LEFT)
            noise.append(of_type(obs, GRASS)[0] - of_type(new, GRASS)[0] - [1 if t % 2 else -1, 0])
            obs = new
    np.testing.assert_allclose(noise, 0.1 * (2 * stream.random((60, 2)) - 1), atol=1e-5)


@pytest.mark.parametrize("bit_generator", [np.random.PCG64, np.random.PCG64DXSM,
                                           np.random.MT19937, np.random.Philox])
def test_skipping_uniforms_leaves_the_generator_as_drawing_them_would(bit_generator):
    rng = np.random.Generator(bit_generator(3))
    rng.integers(10, dtype=np.uint32)  # may buffer half of a 64-bit draw
    drawn = copy.deepcopy(rng)
    envs._engine._skip_uniforms(rng, 3 * envs._engine._SKIP_BLOCK + 5)
    drawn.random(3 * envs._engine._SKIP_BLOCK + 5)
    for draw in (lambda g: g.integers(2**32, size=3, dtype=np.uint32), lambda g: g.random(3)):
        np.testing.assert_array_equal(draw(rng), draw(drawn))


def _peak_bytes(call):
    """Peak memory that ``call()`` allocates (numpy's arrays included)."""
    tracemalloc.start()
    try:
        call()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_memory_does_not_grow_with_max_steps():
    env = envs.ObjectWorldEnv(max_steps=10**6)  # the episode's noise alone would take 16 MB
    assert _peak_bytes(lambda: env.reset(seed=0)) < 1_000_000
    for t in range(256):
        env.step(t % 4)
    assert _peak_bytes(lambda: env.step(0)) < 1_000_000  # draws the next chunk of noise


def test_rng_draws_do_not_depend_on_the_view():
    seen = [envs.ObjectWorldEnv(treasure=True, view=v).reset(seed=2)[0] for v in envs.VIEWS]
    local = seen[0]
    for obs in seen[1:]:
        keep = np.isin(obs[:, 2], [MONEY, WALL, GRASS, ENEMY]) & (np.abs(obs[:, :2]) <= 10).all(1)
        np.testing.assert_array_equal(np.sort(obs[keep], axis=0), np.sort(local, axis=0))


# --------------------------------------------------------------------------- rendering
@pytest.mark.parametrize("render_view", ["world", "local"])
def test_render_draws_objects_agent_and_view(render_view):
    env = envs.ObjectWorldEnv(render_mode="rgb_array", render_view=render_view)
    env.reset(seed=0)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert 400 <= frame.shape[0] == frame.shape[1] <= 600
    colours = {tuple(c) for c in frame.reshape(-1, 3)}
    for kind in (MONEY, WALL, ENEMY):
        assert envs._render._STYLE[kind][0] in colours
    assert envs._render._VIEW_COLOUR in colours and envs._render._AGENT[0] in colours
    env.step(1)
    assert not np.array_equal(frame, env.render())


@pytest.mark.parametrize("render_view", ["world", "local"])
def test_render_of_a_batch_is_one_frame_per_world(render_view):
    worlds = gym.make_vec("ObjectWorld-v0", num_envs=2, render_mode="rgb_array",
                          render_view=render_view)
    worlds.reset(seed=3)
    worlds.step(np.array([1, 2]))
    frames = worlds.render()
    assert isinstance(frames, tuple) and len(frames) == 2
    for i, frame in enumerate(frames):
        env = envs.ObjectWorldEnv(render_mode="rgb_array", render_view=render_view)
        env.reset(seed=3 + i)
        env.step([1, 2][i])
        np.testing.assert_array_equal(frame, env.render())
    assert not np.array_equal(frames[0], frames[1])


@pytest.mark.parametrize("make", [envs.ObjectWorldEnv,
                                  lambda **kwargs: envs.BatchedObjectWorld(2, **kwargs)],
                         ids=["single", "batched"])
def test_render_without_mode_warns_and_before_reset_raises(make):
    env = make()
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="render_mode"):
        assert env.render() is None
    with pytest.raises(RuntimeError, match="reset"):
        make(render_mode="rgb_array").render()


# --------------------------------------------------------------------------- wrappers, policy
def test_padded_objects_round_trip():
    env = envs.PaddedObjects(envs.ObjectWorldEnv(), max_objects=128)
    inner = env.unwrapped
    obs, _ = env.reset(seed=0)
    raw = inner._engine.observation[0]
    assert obs.shape == (128, 4) and env.observation_space.contains(obs)
    (stripped,) = envs.strip_padding(obs)
    np.testing.assert_array_equal(stripped, raw)
    assert obs[len(raw):].sum() == 0.0 and (obs[:len(raw), 3] == 1).all()
    batch = envs.strip_padding(np.stack([obs, obs]))
    assert len(batch) == 2 and np.array_equal(batch[1], raw)


def test_padded_objects_keeps_the_nearest_when_full():
    env = envs.PaddedObjects(envs.ObjectWorldEnv(move_noise=0.0), max_objects=2)
    obs, _ = env.reset(seed=0, options={"objects": [[5, 5, GRASS], [1, 0, GRASS], [0, 2, MONEY]]})
    np.testing.assert_array_equal(envs.strip_padding(obs)[0], [[1, 0, GRASS], [0, 2, MONEY]])


@pytest.mark.filterwarnings("ignore:.*different from the unwrapped version")
def test_padded_objects_is_remade_from_its_spec_and_passes_check_env():
    env = envs.PaddedObjects(gym.make("ObjectWorldTreasure-v0", view="arrow"), max_objects=24)
    remade = gym.make(env.spec)
    assert isinstance(remade, envs.PaddedObjects) and remade.max_objects == 24
    assert remade.unwrapped.rules == env.unwrapped.rules
    np.testing.assert_array_equal(remade.reset(seed=4)[0], env.reset(seed=4)[0])
    check_env(env)


def test_greedy_policy_beats_random_play():
    worlds = envs.BatchedObjectWorld(40, sword=True)
    policy = envs.GreedyPolicy(worlds)
    totals = []
    for greedy in (False, True):
        obs, _ = worlds.reset(seed=100)
        rng = np.random.default_rng(0)
        total = 0.0
        for _ in range(50):
            actions = policy.predict(obs)[0] if greedy else rng.integers(8, size=40)
            obs, rewards, *_ = worlds.step(actions)
            total += rewards.sum()
        totals.append(total)
    assert totals[0] < -200_000 and totals[1] > 0
    single = envs.ObjectWorldEnv(sword=True)
    obs, _ = single.reset(seed=100)
    assert policy.predict(obs)[0] == policy.predict(worlds.reset(seed=100)[0])[0][0]




# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("action", [4, -1, np.int64(7), np.array(-2)])
def test_out_of_range_action_is_a_value_error(action):
    env = envs.ObjectWorldEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="invalid action"):
        env.step(action)


@pytest.mark.parametrize("action", [1.0, 1.5, "up", None, np.array([1]), True, np.bool_(False),
                                    np.float32(2.0)])
def test_non_integer_action_is_a_type_error(action):
    env = envs.ObjectWorldEnv()
    env.reset(seed=0)
    with pytest.raises(TypeError, match=r"invalid action .*expected an int in \[0, 4\)"):
        env.step(action)


@pytest.mark.parametrize("action", [2, np.int64(2), np.int32(2), np.array(2)])
def test_integer_actions_of_any_kind_step_alike(action):
    env = envs.ObjectWorldEnv()
    env.reset(seed=3)
    expected = envs.ObjectWorldEnv()
    expected.reset(seed=3)
    obs, reward, *_ = env.step(action)
    want_obs, want_reward, *_ = expected.step(2)
    assert reward == want_reward
    np.testing.assert_array_equal(obs, want_obs)


def test_sword_actions_need_the_sword():
    env = envs.ObjectWorldEnv(sword=True)
    env.reset(seed=0)
    env.step(7)
    with pytest.raises(ValueError, match=r"\[0, 8\)"):
        env.step(8)


@pytest.mark.parametrize("rules, match", [
    ({"view": "birdseye"}, "unknown view"),
    ({"view": "arrow"}, "treasure=True"),
    ({"n_money": -1}, "n_money must be >= 0"),
    ({"n_enemies": -3}, "n_enemies must be >= 0"),
    ({"max_steps": 0}, "max_steps must be >= 1"),
    ({"size_w": float("nan")}, "size_w must be a finite number"),
    ({"size_w": float("inf")}, "size_w must be a finite number"),
    ({"contact_radius": 0.3}, "contact_radius"),
    ({"enemy_speed": -0.1}, "enemy_speed"),
    ({"view_size": 0}, "view_size"),
])
def test_out_of_range_rules_are_value_errors(rules, match):
    with pytest.raises(ValueError, match=match):
        envs.ObjectWorldEnv(**rules)
    with pytest.raises(ValueError, match=match):
        envs.BatchedObjectWorld(2, **rules)


@pytest.mark.parametrize("rules, match", [
    ({"n_walls": 2.5}, "n_walls must be an int, got 2.5"),
    ({"n_money": 1.5}, "n_money must be an int, got 1.5"),
    ({"n_money": 40.0}, "n_money must be an int, got 40.0"),
    ({"n_enemies": True}, "n_enemies must be an int, got True"),
    ({"max_steps": "50"}, "max_steps must be an int, got '50'"),
    ({"n_treasure": None}, "n_treasure must be an int, got None"),
    ({"sword": "yes"}, "sword must be a bool"),
    ({"treasure": 1}, "treasure must be a bool"),
    ({"size_w": "30"}, "size_w must be a finite number, got '30'"),
    ({"enemy_speed": True}, "enemy_speed must be a finite number, got True"),
    ({"view_size": None}, "view_size must be a finite number, got None"),
])
def test_rules_of_the_wrong_type_are_type_errors(rules, match):
    with pytest.raises(TypeError, match=match):
        envs.WorldRules(**rules)
    with pytest.raises(TypeError, match=match):
        envs.ObjectWorldEnv(**rules)
    with pytest.raises(TypeError, match=match):
        envs.BatchedObjectWorld(2, **rules)


def test_integral_rules_of_numpy_types_are_accepted():
    rules = envs.WorldRules(n_money=np.int64(5), max_steps=np.int32(7), sword=np.bool_(True),
                            size_w=np.float32(20.0))
    assert (rules.n_money, rules.max_steps, rules.sword, rules.size_w) == (5, 7, True, 20.0)
    assert type(rules.n_money) is int and type(rules.size_w) is float


def test_unknown_rule_is_a_type_error():
    with pytest.raises(TypeError, match="n_coins"):
        envs.ObjectWorldEnv(n_coins=3)


@pytest.mark.parametrize("kwargs, match", [
    ({"render_mode": "human"}, "render_mode"),
    ({"render_view": "minimap"}, "render_view"),
])
def test_bad_render_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        envs.ObjectWorldEnv(**kwargs)
    with pytest.raises(ValueError, match=match):
        gym.make_vec("ObjectWorld-v0", num_envs=2, **kwargs)


@pytest.mark.parametrize("options, match", [
    ({"objects": [[0, 1]]}, r"shape \(k, 3\)"),
    ({"objects": [[0, 1, 7]]}, "types"),
    ({"objects": [[0, 99, 0]]}, "outside"),
    ({"objects": [[0, np.nan, 0]]}, "NaN"),
    ({"objects": "wall"}, "numeric"),
    ({"layout": []}, "only key"),
])
def test_bad_reset_options(options, match):
    with pytest.raises(ValueError, match=match):
        envs.ObjectWorldEnv().reset(seed=0, options=options)


GOOD_ROWS = [[1.0, 0.0, MONEY], [0.0, 2.0, WALL]]


@pytest.mark.parametrize("observation, error, match", [
    (np.zeros((3, 2)), ValueError, r"\(n, 3\) array .* got shape \(3, 2\)"),
    (np.zeros(6), ValueError, r"got shape \(6,\)"),
    (np.zeros((2, 4, 3)), ValueError, r"RaggedBatch for several worlds\), got shape \(2, 4, 3\)"),
    ([[0.0, 1.0, MONEY], [np.nan, 0.0, WALL]], ValueError, "NaN or infinite"),
    ([[0.0, np.inf, MONEY]], ValueError, "NaN or infinite"),
    ([[0.0, 1.0, 9]], ValueError, "type id 9.0; the types of this game are the ints 0 to 3"),
    ([[0.0, 1.0, 0.5]], ValueError, "type id 0.5"),
    ([[0.0, 1.0], [2.0, 3.0, 0.0]], ValueError, "ragged sequence"),
    (np.array([["a", "b", "c"]]), TypeError, "must hold numbers"),
    (None, TypeError, "must hold numbers"),
    (envs.RaggedBatch(np.array([[0, 1, MONEY], [np.nan, 0, WALL]]), [0, 1, 2]), ValueError,
     "observation.data contains NaN"),
])
def test_greedy_policy_rejects_bad_observations(observation, error, match):
    policy = envs.GreedyPolicy(envs.ObjectWorldEnv())
    assert policy.predict(np.array(GOOD_ROWS))[0] in range(4)
    assert policy.predict(np.empty((0, 3)))[0] in range(4)
    with pytest.raises(error, match=match):
        policy.predict(observation)


def test_greedy_policy_rejects_a_batch_with_bad_offsets():
    class Batch:  # duck-typed, like boxtrees.ObjectSets
        data = np.array(GOOD_ROWS, dtype=np.float32)
        offsets = np.array([0, 3])
    with pytest.raises(ValueError, match="offsets"):
        envs.GreedyPolicy(envs.ObjectWorldEnv()).predict(Batch())


def test_bad_wrapper_input():
    with pytest.raises(ValueError, match="max_objects"):
        envs.PaddedObjects(envs.ObjectWorldEnv(), 0)
    with pytest.raises(ValueError, match="max_objects"):
        envs.PaddedObjects(envs.ObjectWorldEnv(), -4)
    for max_objects in (8.0, 2.5, True, "8", None):
        with pytest.raises(TypeError, match="max_objects must be a positive int"):
            envs.PaddedObjects(envs.ObjectWorldEnv(), max_objects)
    with pytest.raises(ValueError, match="Sequence"):
        envs.PaddedObjects(gym.make("CartPole-v1"), 8)
    with pytest.raises(ValueError, match="valid"):
        envs.strip_padding(np.zeros((8, 2)))
    with pytest.raises(ValueError, match="valid"):
        envs.strip_padding(np.zeros(4))
    with pytest.raises(ValueError, match="non-negative"):
        envs.reference_worlds(-1)
    for n in (2.0, 1.5, True, "4", None):
        with pytest.raises(TypeError, match="n must be a non-negative int"):
            envs.reference_worlds(n)


# --------------------------------------------------------------------------- the policy's env
@pytest.mark.parametrize("make_env", [
    lambda: gym.make("CartPole-v1"),
    lambda: gym.vector.SyncVectorEnv([lambda: envs.ObjectWorldEnv()] * 2),
    lambda: gym.make_vec("ObjectWorld-v0", num_envs=2, vectorization_mode="sync"),
    lambda: envs.WorldRules(),
    lambda: None,
    lambda: "ObjectWorld-v0",
])
def test_greedy_policy_needs_an_objectworld_env(make_env):
    env = make_env()
    with pytest.raises(TypeError, match="GreedyPolicy plays an ObjectWorldEnv or a "
                                        "BatchedObjectWorld .*got "):
        envs.GreedyPolicy(env)


@pytest.mark.parametrize("make_env", [
    lambda: envs.ObjectWorldEnv(sword=True),
    lambda: gym.make("ObjectWorldSword-v0"),
    lambda: envs.PaddedObjects(envs.ObjectWorldEnv(sword=True), 8),
    lambda: envs.BatchedObjectWorld(2, sword=True),
    lambda: gym.make_vec("ObjectWorldSword-v0", num_envs=2),
])
def test_greedy_policy_takes_objectworld_envs_wrapped_or_not(make_env):
    assert envs.GreedyPolicy(make_env()).rules == envs.WorldRules(sword=True)


# --------------------------------------------------------------------------- symmetry
def test_move_frame_turns_each_move_up_and_keeps_distances():
    directions = np.array([[0, 1], [1, 0], [0, -1], [-1, 0]] * 2, dtype=np.float32)
    np.testing.assert_array_equal(envs.move_frame(directions, np.arange(8)),
                                  np.tile([0.0, 1.0], (8, 1)))
    points = np.random.default_rng(0).normal(size=(40, 2)).astype(np.float32)
    actions = np.arange(40) % 4
    turned = envs.move_frame(points, actions)
    np.testing.assert_array_equal(np.linalg.norm(turned, axis=1), np.linalg.norm(points, axis=1))
    # four quarter turns come back where they started
    again = points
    for _ in range(4):
        again = envs.move_frame(again, np.ones(40, dtype=int))
    np.testing.assert_array_equal(again, points)
    assert envs.move_frame(np.empty((0, 2)), np.empty(0, dtype=int)).shape == (0, 2)


def test_in_move_frame_turns_each_observation_by_its_own_action():
    data = np.float32([[1, 2, 0], [3, -4, 3], [-1, 0, 1], [5, 5, 2]])
    batch = envs.RaggedBatch(data, [0, 2, 2, 4])
    turned = envs.in_move_frame(batch, [1, 0, 3])
    assert isinstance(turned, envs.RaggedBatch)
    np.testing.assert_array_equal(turned.offsets, batch.offsets)
    np.testing.assert_array_equal(turned.data, [[-2, 1, 0], [4, 3, 3], [0, 1, 1], [5, -5, 2]])
    np.testing.assert_array_equal(batch.data, data)      # the input is left as it was
    with pytest.raises(ValueError, match="one action per observation"):
        envs.in_move_frame(batch, [1, 0])


@pytest.mark.parametrize("positions, actions, problem", [
    (np.zeros((3, 3)), np.zeros(3, dtype=int), "must be \\(n, 2\\)"),
    (np.zeros((3, 2)), np.zeros(2, dtype=int), "must be \\(n, 2\\)"),
    (np.zeros((1, 2)), np.array([8]), "range\\(8\\)"),
    (np.zeros((1, 2)), np.array([-1]), "range\\(8\\)"),
    (np.zeros((1, 2)), np.array([1.5]), "integers"),
])
def test_move_frame_refuses_bad_input(positions, actions, problem):
    with pytest.raises(ValueError, match=problem):
        envs.move_frame(positions, actions)


@pytest.mark.parametrize("quarter_turns", [1, 2, 3])
@pytest.mark.parametrize("enemy_speed", [0.0, 0.2])
def test_a_turned_world_plays_the_turned_moves_alike(quarter_turns, enemy_speed):
    """What `move_frame` relies on: a world turned by quarter turns, played with the moves
    turned alike, gives the turned observations and the same rewards."""
    rng = np.random.default_rng(quarter_turns)
    n = 300
    objects = np.column_stack([rng.uniform(-27, 27, size=(n, 2)), rng.integers(0, 4, n)])
    objects = objects[np.linalg.norm(objects[:, :2], axis=1) > 2].astype(np.float32)
    turn = np.full(len(objects), quarter_turns)
    turned = np.column_stack([envs.move_frame(objects[:, :2], turn), objects[:, 2]])
    env, obs = scripted(objects, enemy_speed=enemy_speed)
    turned_env, turned_obs = scripted(turned, enemy_speed=enemy_speed)
    rewards = []
    for move in rng.integers(0, 4, 7).repeat(7):     # straight runs, to meet objects
        expected = np.column_stack([envs.move_frame(obs[:, :2], np.full(len(obs), quarter_turns)),
                                    obs[:, 2]])
        np.testing.assert_array_equal(np.unique(turned_obs, axis=0), np.unique(expected, axis=0))
        obs, reward, *_ = env.step(move)
        turned_obs, turned_reward, *_ = turned_env.step((move - quarter_turns) % 4)
        assert turned_reward == reward
        rewards.append(reward)
    assert np.count_nonzero(rewards) >= 2, rewards    # the walk met objects
