"""`PaddedObjects` makes the game usable by stable-baselines3."""
import gymnasium as gym
import numpy as np
import pytest

import envs

sb3 = pytest.importorskip("stable_baselines3")
from stable_baselines3.common.env_checker import check_env  # noqa: E402


# The (max_objects, 4) layout is deliberate (rows are objects); MlpPolicy flattens it.
@pytest.mark.filterwarnings("ignore:Your observation  has an unconventional shape")
@pytest.mark.parametrize("env_id", ["ObjectWorld-v0", "ObjectWorldSword-v0"])
def test_padded_objects_passes_sb3_check_env(env_id):
    check_env(envs.PaddedObjects(gym.make(env_id), 128), warn=True)


def test_dqn_trains_on_padded_objects():
    env = envs.PaddedObjects(gym.make("ObjectWorld-v0"), 128)
    model = sb3.DQN("MlpPolicy", env, learning_starts=100, train_freq=4, buffer_size=1000,
                    policy_kwargs={"net_arch": [32]}, seed=0, device="cpu")
    model.learn(total_timesteps=300)
    assert model.num_timesteps == 300 and model._n_updates > 0
    obs, _ = env.reset(seed=0)
    action, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(int(action))
    assert np.isfinite(model.q_net(model.q_net.obs_to_tensor(obs)[0]).detach().numpy()).all()
