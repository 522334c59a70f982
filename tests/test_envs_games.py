"""The real games as object sets: `envs.AtariObjects` (OCAtari) and `envs.HighwayObjects`
(highway-env). Each needs its optional extra; without it its tests skip, but for the error
that names the extra. highway-env simulates tens of steps per second: its tests take few."""
import importlib.util
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import envs
import envs.atari
import envs.highway

needs_ocatari = pytest.mark.skipif(importlib.util.find_spec("ocatari") is None,
                                   reason="needs the atari extra (ocatari)")
needs_highway = pytest.mark.skipif(importlib.util.find_spec("highway_env") is None,
                                   reason="needs the highway extra (highway-env)")
HIGHWAY = "highway_env:highway-fast-v0"


def play(env, n_steps, seed=0, action_seed=0):
    """Observations, rewards and flags of `n_steps` random actions after ``reset(seed)``,
    resetting after a game's end."""
    obs, _ = env.reset(seed=seed)
    env.action_space.seed(action_seed)    # after the reset, which highway-env's replaces
    trace = [obs]
    for _ in range(n_steps):
        obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        trace += [obs, reward, terminated, truncated]
        if terminated or truncated:
            trace.append(env.reset()[0])
    return trace


def assert_same(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)


def test_importing_envs_imports_neither_game_package():
    code = "import sys, envs; print('ocatari' in sys.modules, 'highway_env' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.split() == ["False", "False"]


@pytest.mark.parametrize("module, extra, make", [
    ("ocatari", "atari", lambda: envs.AtariObjects("Pong")),
    ("ocatari", "atari", lambda: envs.atari_games()),
    ("highway_env", "highway", lambda: envs.HighwayObjects(gym.make("CartPole-v1")))])
def test_a_missing_package_raises_an_import_error_naming_the_extra(monkeypatch, module, extra,
                                                                    make):
    loader = envs.highway._highway if extra == "highway" else envs.atari._ocatari
    loader.cache_clear()
    monkeypatch.setitem(sys.modules, module, None)     # an import of it raises ImportError
    for key in [k for k in sys.modules if k.startswith(f"{module}.")]:
        monkeypatch.delitem(sys.modules, key)
    try:
        with pytest.raises(ImportError, match=rf"pip install 'boxtrees\[{extra}\]'"):
            make()
    finally:
        loader.cache_clear()


# --- Atari -----------------------------------------------------------------------------

# The benchmark's games, and others: games whose OCAtari extraction overflows or indexes
# with NumPy bools on NumPy 2 without the adapter's integer RAM (Enduro, Frogger, Seaquest,
# AirRaid, MontezumaRevenge, Riverraid, FishingDerby), and crowded ones (MsPacman)
GAMES = ["Pong", "Freeway", "Boxing", "Breakout", "MsPacman", "SpaceInvaders", "Enduro",
         "Frogger", "Seaquest", "AirRaid", "MontezumaRevenge", "Riverraid", "FishingDerby"]


@needs_ocatari
@pytest.mark.parametrize("game", GAMES)
def test_atari_observations_lie_in_their_space(game):
    env = envs.AtariObjects(game)
    space = env.observation_space
    assert isinstance(space, gym.spaces.Sequence) and space.stack
    assert space.feature_space.shape == (7,)
    trace = play(env, 40)
    observations = [x for x in trace if isinstance(x, np.ndarray) and x.ndim == 2]
    assert all(space.contains(obs) for obs in observations)
    assert any(len(obs) for obs in observations)
    hud = {env.type_names.index(n) for n in env.type_names if "Score" in n or n == "Lives"}
    assert not hud & {int(t) for obs in observations for t in obs[:, -1]}


@needs_ocatari
def test_atari_games_lists_every_game_with_objects():
    games = envs.atari_games()
    assert set(GAMES) <= set(games) and "Pitfall2" not in games and len(games) >= 55
    with pytest.raises(ValueError, match="OCAtari has no objects for 'Pitfall2'"):
        envs.AtariObjects("Pitfall2")
    with pytest.raises(ValueError, match="mode must be one of"):
        envs.atari_games("pixels")
    with pytest.raises(TypeError, match="game must be a str"):
        envs.AtariObjects(3)
    with pytest.raises(ValueError, match="player must be"):
        envs.AtariObjects("Pong", player="Paddle")


@needs_ocatari
@pytest.mark.parametrize("game", ["Pong", "ALE/Pong-v5", "PongNoFrameskip-v4", "pong"])
def test_a_game_is_named_or_given_by_its_ale_id(game):
    env = envs.AtariObjects(game)
    assert env.game == "Pong" and env.action_names[0] == "NOOP"


@needs_ocatari
def test_atari_passes_gymnasiums_env_checker():
    check_env(envs.AtariObjects("Boxing", render_mode="rgb_array"), skip_render_check=False)


@needs_ocatari
def test_atari_type_ids_are_stable_across_resets_episodes_and_envs():
    env = envs.AtariObjects("Pong", max_num_frames_per_episode=120)   # 30-step episodes
    names = env.type_names
    assert names == ("Ball", "Enemy", "EnemyScore", "Player", "PlayerScore")
    assert envs.AtariObjects("Pong", hud=True).type_names == names
    assert gym.make("AtariObjects-v0", game="Pong").unwrapped.type_names == names
    player, seen = names.index("Player"), set()
    for episode in range(3):
        obs, _ = env.reset(seed=episode)
        truncated = False
        while not truncated:
            # the player's paddle, at the origin (the reference), is type "Player"
            at_origin = obs[(obs[:, 0] == 0) & (obs[:, 1] == 0)]
            assert set(at_origin[:, -1]) <= {player}
            seen |= {names[int(t)] for t in obs[:, -1]}
            obs, _, terminated, truncated, _ = env.step(2)
            assert not terminated
    assert seen == {"Ball", "Enemy", "Player"}


@needs_ocatari
def test_atari_rows_are_relative_to_the_player_on_a_hand_checked_frame():
    env = envs.AtariObjects("Pong", render_mode="rgb_array")
    env.reset(seed=0)
    for _ in range(40):
        obs, *_ = env.step(0)
    # checked on the rendered frame: the player's paddle (right) centred at (142, 103.5),
    # the ball at (62, 92), the enemy's paddle at (18, 106.5); the ball flies left and up
    names = env.type_names
    np.testing.assert_array_equal(obs, [
        [0, 0, 4, 15, 0, 0, names.index("Player")],
        [-80, -11.5, 2, 4, 4, -8, names.index("Ball")],
        [-124, 3, 4, 15, 0, -8, names.index("Enemy")],
    ])
    frame = env.render()
    for colour, row in (((92, 186, 92), obs[0]), ((236, 236, 236), obs[1]),
                        ((213, 130, 74), obs[2])):
        ys, xs = np.nonzero((frame[34:194] == colour).all(axis=-1))
        centre = np.array([xs.min() + xs.max() + 1, ys.min() + ys.max() + 1]) / 2 + (0, 34)
        assert np.abs(centre - (142, 103.5) - row[:2]).max() <= 1
    # without a player, the same centres in screen coordinates
    env = envs.AtariObjects("Pong", player=None)
    env.reset(seed=0)
    for _ in range(40):
        obs, *_ = env.step(0)
    np.testing.assert_array_equal(obs[:, :2], [[142, 103.5], [62, 92], [18, 106.5]])


@needs_ocatari
def test_atari_flags_are_gymnasiums_a_game_over_terminates_a_frame_limit_truncates():
    env = envs.AtariObjects("Pong", max_num_frames_per_episode=40)
    env.reset(seed=0)
    flags = [env.step(0)[2:4] for _ in range(10)]
    assert flags[-1] == (False, True) and not any(any(f) for f in flags[:-1])
    env = envs.AtariObjects("Boxing", frameskip=16)  # a 2-minute bout, ~450 steps
    env.reset(seed=0)
    terminated = truncated = False
    while not (terminated or truncated):
        *_, terminated, truncated, _ = env.step(0)
    assert terminated and not truncated


@needs_ocatari
def test_atari_seeding_gives_the_same_episode():
    first = play(envs.AtariObjects("Freeway"), 150, seed=3)
    assert_same(first, play(envs.AtariObjects("Freeway"), 150, seed=3))
    other = play(envs.AtariObjects("Freeway"), 150, seed=4)
    assert any(not np.array_equal(a, b) for a, b in zip(first, other))


@needs_ocatari
def test_atari_vector_env_equals_single_envs():
    seeds, actions = [5, 6], np.random.default_rng(0).integers(0, 6, (60, 2))
    vector = gym.make_vec("AtariObjects-v0", 2, vectorization_mode="sync", game="Pong")
    singles = [envs.AtariObjects("Pong") for _ in seeds]
    obs, _ = vector.reset(seed=seeds)
    for i, (env, seed) in enumerate(zip(singles, seeds)):
        np.testing.assert_array_equal(obs[i], env.reset(seed=seed)[0])
    for step in actions:
        obs, rewards, *_ = vector.step(step)
        for i, env in enumerate(singles):
            single, reward, *_ = env.step(step[i])
            np.testing.assert_array_equal(obs[i], single)
            assert rewards[i] == reward


@needs_ocatari
def test_atari_env_is_rebuilt_from_its_spec_as_it_cannot_be_copied():
    import copy

    env = envs.AtariObjects("Freeway", frameskip=2)
    with pytest.raises(TypeError, match="pickle"):
        copy.deepcopy(env)
    remade = gym.make(env.spec).unwrapped
    assert remade.game == "Freeway" and remade.spec.kwargs["frameskip"] == 2
    assert_same(play(remade, 20), play(env, 20))
    vector = gym.make_vec(env.spec, 2)
    assert vector.single_observation_space == env.observation_space


@needs_ocatari
def test_padded_atari_objects_keep_every_attribute():
    env = envs.PaddedObjects(envs.AtariObjects("Pong"), max_objects=8)
    assert env.observation_space.shape == (8, 8)
    env.reset(seed=0)
    for _ in range(40):
        padded, *_ = env.step(0)
    (rows,) = envs.strip_padding(padded)
    assert rows.shape == (3, 7) and padded[:3, -1].all() and not padded[3:].any()


# --- highway-env -----------------------------------------------------------------------

@needs_highway
@pytest.mark.parametrize("env_id, max_distance, types", [
    (HIGHWAY, None, {"ego", "vehicle"}),
    ("highway_env:merge-v1", 300, {"ego", "vehicle", "obstacle"}),   # the lane's end, 280 m
    ("highway_env:parking-v0", None, {"ego", "landmark", "obstacle"})])  # the walls
def test_highway_observations_lie_in_their_space(env_id, max_distance, types):
    env = envs.HighwayObjects(gym.make(env_id), max_distance=max_distance)
    trace = play(env, 2)
    observations = [x for x in trace if isinstance(x, np.ndarray) and x.ndim == 2]
    assert all(env.observation_space.contains(obs) for obs in observations)
    assert {env.type_names[int(t)] for obs in observations for t in obs[:, -1]} == types
    assert all(obs[0, -1] == 0 and not obs[1:, -1].__contains__(0) for obs in observations)


@needs_highway
def test_highway_rows_are_relative_to_the_ego_vehicle_on_a_hand_checked_frame():
    env = envs.HighwayObjects(gym.make(HIGHWAY), max_distance=50)
    env.reset(seed=0)
    road = env.unwrapped.road
    ego, other, far = env.unwrapped.vehicle, road.vehicles[1], road.vehicles[2]
    ego.position, ego.heading, ego.speed = np.array([100.0, 4.0]), 0.0, 25.0
    other.position, other.heading, other.speed = np.array([130.0, 8.0]), np.pi / 2, 20.0
    far.position = np.array([151.0, 4.0])
    for vehicle in road.vehicles[3:]:
        vehicle.position = np.array([-1000.0, 0.0])
    np.testing.assert_allclose(env.observation(None), [
        [0, 0, 25, 0, 1, 0, 0],            # the ego vehicle's own velocity
        [30, 4, -25, 20, 0, 1, 1],         # 30 m ahead, one lane right, driving across
    ], atol=1e-5)


@needs_highway
@pytest.mark.filterwarnings("ignore:.*is different from the unwrapped version")  # a wrapper
def test_highway_passes_gymnasiums_env_checker_and_rejects_other_envs():
    check_env(envs.HighwayObjects(gym.make(HIGHWAY)), skip_render_check=True)
    with pytest.raises(TypeError, match="needs an env of highway-env"):
        envs.HighwayObjects(gym.make("CartPole-v1"))
    with pytest.raises(ValueError, match="max_distance must be a positive number"):
        envs.HighwayObjects(gym.make(HIGHWAY), max_distance=0)


@needs_highway
def test_highway_seeding_gives_the_same_episode_and_the_vector_env_equals_single_envs():
    single = envs.HighwayObjects(gym.make(HIGHWAY))
    assert_same(play(single, 2, seed=1), play(envs.HighwayObjects(gym.make(HIGHWAY)), 2,
                                                seed=1))
    vector = gym.make_vec(single.spec, 2, vectorization_mode="sync")
    obs, _ = vector.reset(seed=[1, 2])
    np.testing.assert_array_equal(obs[0], single.reset(seed=1)[0])
    np.testing.assert_array_equal(obs[1], envs.HighwayObjects(gym.make(HIGHWAY)).reset(seed=2)[0])
    obs, *_ = vector.step(np.array([3, 1]))
    np.testing.assert_array_equal(obs[0], single.step(3)[0])
