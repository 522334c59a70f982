"""rl-zoo3's tuned DQN hyperparameters, the one copy the benchmarks share.

From rl-zoo3 2.9.2, ``rl_zoo3/hyperparams/dqn.yml`` (policy ``"MlpPolicy"``; its
``n_timesteps`` is left to each user, which sets its own budget): `bench_control.py` trains
DQN with them as they are, and the baselines' searches of `benchmarks/reproduce/registry.py`
start from them with their own discount factors; `SMALL_TASK_DQN` adapts LunarLander-v2's to the
game (the ``dqn`` unit kind trains with it, and the searches start from it).
"""
import copy

__all__ = ["ZOO_DQN", "SMALL_TASK_DQN", "without_gamma"]

_LUNARLANDER = {
    "learning_rate": 6.3e-4, "batch_size": 128, "buffer_size": 50_000,
    "learning_starts": 0, "gamma": 0.99, "target_update_interval": 250,
    "train_freq": 4, "gradient_steps": -1, "exploration_fraction": 0.12,
    "exploration_final_eps": 0.1, "policy_kwargs": {"net_arch": [256, 256]},
}
ZOO_DQN = {
    "CartPole-v1": {
        "learning_rate": 2.3e-3, "batch_size": 64, "buffer_size": 100_000,
        "learning_starts": 1000, "gamma": 0.99, "target_update_interval": 10,
        "train_freq": 256, "gradient_steps": 128, "exploration_fraction": 0.16,
        "exploration_final_eps": 0.04, "policy_kwargs": {"net_arch": [256, 256]},
    },
    "LunarLander-v2": _LUNARLANDER,
    "Acrobot-v1": copy.deepcopy(_LUNARLANDER),  # rl-zoo3 tunes both alike
    "MountainCar-v0": {
        "learning_rate": 4e-3, "batch_size": 128, "buffer_size": 10_000,
        "learning_starts": 1000, "gamma": 0.98, "target_update_interval": 600,
        "train_freq": 16, "gradient_steps": 8, "exploration_fraction": 0.2,
        "exploration_final_eps": 0.07, "policy_kwargs": {"net_arch": [256, 256]},
    },
}


def without_gamma(env_id):
    """The settings of `env_id` less the discount factor, for a caller that sets its own
    (a new dict, in the same order)."""
    return {key: value for key, value in ZOO_DQN[env_id].items() if key != "gamma"}


# rl-zoo3's LunarLander-v2 settings for 400,000 steps of the game, less its discount factor:
# learning_starts 1000 and one gradient step per 4 env steps, where rl-zoo3 has 0 and -1 (a
# gradient step per env step), to keep the CPU cost bounded. rl-zoo3 gives Acrobot-v1 the
# same settings, but bench_control.py trains Acrobot-v1 with rl-zoo3's unchanged.
SMALL_TASK_DQN = {**without_gamma("LunarLander-v2"), "learning_starts": 1000,
                  "gradient_steps": 1}
