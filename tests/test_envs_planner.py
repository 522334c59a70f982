"""`LookaheadPlanner`: beats the greedy heuristic, is exact and deterministic, leaves the
world alone; the engine's copies of worlds; its leg model; bad input."""
import itertools

import gymnasium as gym
import numpy as np
import pytest

import envs
from envs import ENEMY, MONEY
from envs.planner import _coin_legs, _foe_legs

GAMES = {"4 actions": {}, "sword": {"sword": True}}


def greedy_totals(rules, seeds):
    worlds = envs.BatchedObjectWorld(len(seeds), **rules)
    obs, _ = worlds.reset(seed=seeds)
    policy = envs.GreedyPolicy(worlds)
    total = np.zeros(len(seeds))
    for _ in range(worlds.rules.max_steps):
        obs, rewards, _, _, _ = worlds.step(policy.predict(obs)[0])
        total += rewards
    return total


# --------------------------------------------------------------------------- playing strength
@pytest.mark.parametrize("game", GAMES)
def test_never_worse_than_greedy_at_a_small_depth(game):
    seeds = envs.reference_worlds(8)
    worlds = envs.BatchedObjectWorld(len(seeds), **GAMES[game])
    _, rewards = envs.LookaheadPlanner(depth=2, width=4).play(worlds, seed=seeds)
    planned, greedy = rewards.sum(axis=0), greedy_totals(GAMES[game], seeds)
    assert (planned >= greedy).all(), (planned, greedy)
    assert planned.sum() > 1.2 * greedy.sum()


def test_exhaustive_search_plays_the_best_ending():
    # Over the last 3 steps a depth-3 search keeping every sequence sees all 64 endings and
    # the rewards exactly (move noise included), so it earns the best of them.
    seed = envs.reference_worlds(3)[2]
    env = envs.ObjectWorldEnv()
    actions, rewards = envs.LookaheadPlanner(depth=3, width=16).play(env, seed=seed)
    endings = np.array(list(itertools.product(range(4), repeat=3)))
    worlds = envs.BatchedObjectWorld(len(endings))
    worlds.reset(seed=[seed] * len(endings))
    for action in actions[:-3]:
        worlds.step(np.full(len(endings), action))
    earned = sum(worlds.step(endings[:, t])[1] for t in range(3))
    assert rewards[-3:].sum() == earned.max()
    assert earned.max() > earned.min()  # the ending mattered


@pytest.mark.parametrize("rules", [{"n_money": 0}, {"sword": True, "n_enemies": 0},
                                   {"sword": True, "n_money": 0}],
                         ids=["no money", "sword, no enemies", "sword, no money"])
def test_plays_worlds_short_of_targets(rules):
    seeds = [1, 2, 3]
    worlds = envs.BatchedObjectWorld(len(seeds), **rules)
    _, rewards = envs.LookaheadPlanner(depth=2, width=4).play(worlds, seed=seeds)
    assert (rewards >= 0).all()  # no wall, enemy or swipe into air
    assert (rewards.sum(axis=0) >= greedy_totals(rules, seeds)).all()


# --------------------------------------------------------------------------- exactness
@pytest.mark.parametrize("chunk", [None, 7], ids=["one chunk", "chunks of 7 steps"])
def test_planning_does_not_change_the_world(monkeypatch, chunk):
    # In chunks of 7 steps, the search's copies draw the later chunks of move noise.
    if chunk:
        monkeypatch.setattr(envs._engine, "_NOISE_CHUNK", chunk)
    played, replayed = envs.ObjectWorldEnv(sword=True), envs.ObjectWorldEnv(sword=True)
    actions, rewards = envs.LookaheadPlanner(depth=3, width=4).play(played, seed=5)
    replayed.reset(seed=5)
    assert [replayed.step(a)[1] for a in actions] == rewards.tolist()
    np.testing.assert_array_equal(played.reset()[0], replayed.reset()[0])  # same next world


def test_deterministic_for_a_seed_and_alike_single_and_batched():
    seeds, rules = [21, 22], {"sword": True, "max_steps": 20}
    planner = envs.LookaheadPlanner(depth=2, width=3)
    worlds = envs.BatchedObjectWorld(len(seeds), **rules)
    first = planner.play(worlds, seed=seeds)
    again = envs.LookaheadPlanner(depth=2, width=3).play(worlds, seed=seeds)
    np.testing.assert_array_equal(first[0], again[0])
    np.testing.assert_array_equal(first[1], again[1])
    for i, seed in enumerate(seeds):
        actions, rewards = planner.play(envs.ObjectWorldEnv(**rules), seed=seed)
        np.testing.assert_array_equal(actions, first[0][:, i])
        np.testing.assert_array_equal(rewards, first[1][:, i])


def test_act_reads_a_wrapped_env_and_counts_its_simulated_steps():
    env = gym.make("ObjectWorld-v0")
    env.reset(seed=3)
    planner = envs.LookaheadPlanner(depth=4, width=8)
    assert planner.act(env) in range(4)
    assert planner.simulated_steps == 4 + 16 + 32 + 32  # 4 * min(width, 4**level) per level


@pytest.mark.parametrize("rules", [{"sword": True}, {"treasure": True, "view": "minimap"}],
                         ids=["sword", "minimap"])
def test_engine_copies_step_like_their_originals(monkeypatch, rules):
    monkeypatch.setattr(envs._engine, "_NOISE_CHUNK", 7)  # copies draw later chunks of noise
    worlds = envs.BatchedObjectWorld(2, **rules)
    fresh = envs.BatchedObjectWorld(2, **rules)  # never copied
    twin = envs.BatchedObjectWorld(1, **rules)  # replays world 1, then a copy's other actions
    worlds.reset(seed=[7, 8])
    fresh.reset(seed=[7, 8])
    twin.reset(seed=[8])
    rng = np.random.default_rng(0)
    n_actions = worlds.rules.n_actions
    for _ in range(20):
        actions = rng.integers(n_actions, size=2)
        worlds.step(actions)
        fresh.step(actions)
        twin.step(actions[1:])
    which = [1, 0, 1]
    copies = worlds._engine.take(np.array(which))
    for _ in range(29):
        actions = rng.integers(n_actions, size=2)
        other = rng.integers(n_actions, size=1)  # the second copy of world 1
        copy_rewards, _ = copies.step(np.concatenate([actions[[1, 0]], other]))
        expected = [worlds.step(actions), twin.step(other)]
        np.testing.assert_array_equal(copy_rewards[:2], expected[0][1][[1, 0]])
        assert copy_rewards[2] == expected[1][1][0]
        data, offsets = copies.observation
        for j, obs in enumerate([expected[0][0][1], expected[0][0][0], expected[1][0][0]]):
            np.testing.assert_array_equal(data[offsets[j]:offsets[j + 1]], obs)
        np.testing.assert_array_equal(expected[0][1], fresh.step(actions)[1])  # untouched
    np.testing.assert_array_equal(worlds.reset()[0].data, fresh.reset()[0].data)


# --------------------------------------------------------------------------- the leg model
def fewest_steps(rules, objects, reward, length):
    """Fewest steps after which any action sequence of `length` earned `reward` (inf: none)."""
    rules = {"move_noise": 0.0, "enemy_speed": 0.0, **rules}
    n_actions = envs.WorldRules(**rules).n_actions
    sequences = np.array(list(itertools.product(range(n_actions), repeat=length)))
    worlds = envs.BatchedObjectWorld(len(sequences), **rules)
    worlds.reset(seed=0, options={"objects": objects})
    first = np.full(len(sequences), np.inf)
    for t in range(length):
        got = worlds.step(sequences[:, t])[1] == reward
        first = np.where(got & np.isinf(first), t + 1, first)
    return first.min()


@pytest.mark.parametrize("offset", [(3.3, 0.2), (2.5, 2.5), (-1.7, 3.4), (0.4, -4.6)])
def test_coin_legs_count_the_fewest_moves_to_a_coin(offset):
    steps, _, _ = _coin_legs(0.0, 0.0, *offset, envs.WorldRules().contact_radius)
    # Sequences as long as the model says: a shorter way or none would show.
    assert steps == fewest_steps({}, [[*offset, MONEY]], 100.0, int(steps))


@pytest.mark.parametrize("offset", [(4.2, 0.3), (2.0, 2.9), (-4.1, -1.0), (0.5, -0.7)])
def test_foe_legs_count_the_fewest_steps_to_swipe_an_enemy(offset):
    steps, _, _ = _foe_legs(0.0, 0.0, *offset, envs.WorldRules().swipe_size)
    assert steps == fewest_steps({"sword": True}, [[*offset, ENEMY]], 300.0, int(steps))


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kwargs, error, match", [
    ({"depth": 0}, ValueError, "depth must be >= 1"),
    ({"depth": 2.0}, TypeError, "depth must be an int"),
    ({"depth": 1.5}, TypeError, "depth must be an int, got 1.5"),
    ({"route_width": "50"}, TypeError, "route_width must be an int"),
    ({"width": True}, TypeError, "width must be an int"),
    ({"width": -3}, ValueError, "width must be >= 1"),
    ({"route_width": 0}, ValueError, "route_width must be >= 1"),
    ({"discount": 0.0}, ValueError, r"discount must lie in \(0, 1\]"),
    ({"discount": 1.5}, ValueError, r"discount must lie in \(0, 1\]"),
    ({"discount": float("nan")}, ValueError, r"discount must lie in \(0, 1\]"),
    ({"discount": "0.9"}, TypeError, "discount must be a number"),
])
def test_bad_parameters_are_clear_errors(kwargs, error, match):
    with pytest.raises(error, match=match):
        envs.LookaheadPlanner(**kwargs)


def test_act_needs_a_reset_objectworld_mid_episode():
    planner = envs.LookaheadPlanner(depth=1, width=1)
    with pytest.raises(TypeError, match="plays an ObjectWorldEnv or a BatchedObjectWorld"):
        planner.act(gym.make("CartPole-v1"))
    with pytest.raises(RuntimeError, match="call env.reset"):
        planner.act(envs.ObjectWorldEnv())
    worlds = envs.BatchedObjectWorld(2, max_steps=3)
    planner.play(worlds, seed=0)
    with pytest.raises(RuntimeError, match="the episode is over"):
        planner.act(worlds)


@pytest.mark.parametrize("make_env", [
    lambda: gym.make("CartPole-v1"),
    lambda: gym.vector.SyncVectorEnv([lambda: envs.ObjectWorldEnv()] * 2),
    lambda: None,
])
def test_act_and_play_need_an_objectworld_env(make_env):
    planner = envs.LookaheadPlanner(depth=1, width=1)
    env = make_env()
    with pytest.raises(TypeError, match="plays an ObjectWorldEnv or a BatchedObjectWorld"):
        planner.act(env)
    with pytest.raises(TypeError, match="plays an ObjectWorldEnv or a BatchedObjectWorld"):
        planner.play(env, seed=0)
