"""The set encoder for stable-baselines3: padding and object order change nothing."""
import gymnasium as gym
import numpy as np
import pytest

torch = pytest.importorskip("torch")

import envs  # noqa: E402  (registers the game)
from fqi import SetEncoder  # noqa: E402


def padded_env(max_objects=48):
    return envs.PaddedObjects(gym.make("ObjectWorld-v0"), max_objects=max_objects)


def observations(env, n=6, seed=0):
    rows = [env.reset(seed=seed + i)[0] for i in range(n)]
    rows[-1] = np.zeros_like(rows[-1])                # an empty set: padding only
    return np.stack(rows)


@pytest.mark.parametrize("attention", [False, True])
def test_padding_rows_and_the_order_of_objects_change_nothing(attention):
    torch.manual_seed(0)
    env = padded_env()
    encoder = SetEncoder(env.observation_space, embed_dim=16, features_dim=8, attention=attention)
    obs = observations(env)
    with torch.no_grad():
        base = encoder(torch.as_tensor(obs))
        # padding rows with junk coordinates and types: still padding (valid = 0)
        junk = obs.copy()
        pad = junk[..., 3] == 0
        junk[pad, :3] = np.random.default_rng(1).uniform(-9, 3, (pad.sum(), 3))
        np.testing.assert_allclose(encoder(torch.as_tensor(junk)), base, atol=1e-5)
        # the valid objects of each set in another order
        shuffled = obs.copy()
        rng = np.random.default_rng(2)
        for row in shuffled:
            n = int(row[:, 3].sum())
            row[:n] = row[rng.permutation(n)]
        np.testing.assert_allclose(encoder(torch.as_tensor(shuffled)), base, atol=1e-5)
        assert torch.isfinite(base).all() and base.shape == (len(obs), 8)
        # the objects matter: moving one changes the features
        moved = obs.copy()
        moved[0, 0, :2] += 3.0
        assert not torch.allclose(encoder(torch.as_tensor(moved))[0], base[0])


@pytest.mark.parametrize("algorithm", ["DQN", "PPO"])
def test_the_encoder_trains_with_dqn_and_ppo(algorithm):
    import stable_baselines3

    env = padded_env(32)
    kwargs = dict(learning_starts=0) if algorithm == "DQN" else dict(n_steps=32, batch_size=16)
    model = getattr(stable_baselines3, algorithm)(
        "MlpPolicy", env, seed=0, policy_kwargs=dict(
            features_extractor_class=SetEncoder,
            features_extractor_kwargs=dict(embed_dim=16, features_dim=16, attention=True)),
        **kwargs).learn(64)
    action, _ = model.predict(env.reset(seed=0)[0], deterministic=True)
    assert env.action_space.contains(int(action))


def test_a_given_scale_divides_the_attributes_in_place_of_the_bounds():
    env = padded_env()
    obs = torch.as_tensor(observations(env))
    torch.manual_seed(0)
    by_bounds = SetEncoder(env.observation_space, embed_dim=16, features_dim=8)
    torch.manual_seed(0)
    given = SetEncoder(env.observation_space, embed_dim=16, features_dim=8,
                       scale=[2.0, 0.5])
    np.testing.assert_allclose(given.scale, [2.0, 0.5])
    rescaled = obs.clone()  # the same attributes over the given scale as over the bounds'
    rescaled[..., :2] *= torch.tensor([2.0, 0.5]) / by_bounds.scale
    with torch.no_grad():
        np.testing.assert_allclose(given(rescaled), by_bounds(obs), atol=1e-5)


@pytest.mark.parametrize("kwargs, match", [
    (dict(embed_dim=0), "embed_dim"), (dict(features_dim=2.5), "features_dim"),
    (dict(attention=True, embed_dim=10, n_heads=4), "must divide"),
    (dict(scale=[1.0]), r"one value per attribute, shape \(2,\)"),
    (dict(scale=[1.0, 0.0]), "positive and finite"),
    (dict(scale=[1.0, np.nan]), "positive and finite"),
])
def test_bad_parameters_are_rejected(kwargs, match):
    with pytest.raises(ValueError, match=match):
        SetEncoder(padded_env().observation_space, **kwargs)
    with pytest.raises(ValueError, match=r"shape \(max_objects, d \+ 2\)"):
        SetEncoder(gym.spaces.Box(0, 1, (5, 2)))


def test_an_unbounded_type_column_or_a_non_bool_attention_is_rejected():
    high = np.array([[1.0, 1.0, np.inf, 1.0]] * 5, dtype=np.float32)
    with pytest.raises(ValueError, match="type column, which must be finite"):
        SetEncoder(gym.spaces.Box(-high, high))
    with pytest.raises(TypeError, match="attention must be a bool"):
        SetEncoder(padded_env().observation_space, attention=1)
    with pytest.raises(TypeError, match="scale must be an array-like of 2 numbers"):
        SetEncoder(padded_env().observation_space, scale=["near", "far"])
