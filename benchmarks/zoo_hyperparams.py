"""rl-zoo3's tuned DQN and PPO hyperparameters, the one copy the benchmarks share.

From rl-zoo3 2.9.2, ``rl_zoo3/hyperparams/dqn.yml`` and ``ppo.yml`` (policy ``"MlpPolicy"``;
their ``n_timesteps`` in `ZOO_STEPS`; PPO's linear schedules of CartPole-v1 as constants):
`bench_control.py` and the registry's ``control_*`` experiments train with them as they are,
and the baselines' searches of `benchmarks/reproduce/registry.py` start from them with their
own discount factors; `SMALL_TASK_DQN` adapts LunarLander-v2's DQN settings to the game (the
``dqn`` unit kind trains with it, and the searches start from it).
"""
import copy

__all__ = ["ZOO_DQN", "ZOO_PPO", "ZOO_STEPS", "SMALL_TASK_DQN", "without_gamma",
           "ATARI_DQN", "ATARI_PPO", "HIGHWAY_DQN", "HIGHWAY_PPO"]

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


ZOO_PPO = {
    "CartPole-v1": {"n_envs": 8, "n_steps": 32, "batch_size": 256, "gae_lambda": 0.8,
                    "gamma": 0.98, "n_epochs": 20, "ent_coef": 0.0, "learning_rate": 1e-3,
                    "clip_range": 0.2},
    "LunarLander-v2": {"n_envs": 16, "n_steps": 1024, "batch_size": 64, "gae_lambda": 0.98,
                       "gamma": 0.999, "n_epochs": 4, "ent_coef": 0.01},
    "MountainCar-v0": {"normalize": True, "n_envs": 16, "n_steps": 16, "gae_lambda": 0.98,
                       "gamma": 0.99, "n_epochs": 4, "ent_coef": 0.0},
    "Acrobot-v1": {"normalize": True, "n_envs": 16, "n_steps": 256, "gae_lambda": 0.94,
                   "gamma": 0.99, "n_epochs": 4, "ent_coef": 0.0},
}
# gymnasium's LunarLander-v3 is rl-zoo3's LunarLander-v2 with its bugs fixed: the same settings
ZOO_DQN["LunarLander-v3"] = ZOO_DQN["LunarLander-v2"]
ZOO_PPO["LunarLander-v3"] = ZOO_PPO["LunarLander-v2"]
# rl-zoo3's training budgets (environment steps)
ZOO_STEPS = {
    "DQN": {"CartPole-v1": 50_000, "Acrobot-v1": 100_000, "MountainCar-v0": 120_000,
            "LunarLander-v3": 100_000},
    "PPO": {"CartPole-v1": 100_000, "Acrobot-v1": 1_000_000, "MountainCar-v0": 1_000_000,
            "LunarLander-v3": 1_000_000},
}


def without_gamma(env_id, table=None):
    """The settings of `env_id` in `table` (default: `ZOO_DQN`) less the discount factor,
    for a caller that sets its own (a new dict, in the same order)."""
    table = ZOO_DQN if table is None else table
    return {key: value for key, value in table[env_id].items() if key != "gamma"}


# rl-zoo3's LunarLander-v2 settings for 400,000 steps of the game, less its discount factor:
# learning_starts 1000 and one gradient step per 4 env steps, where rl-zoo3 has 0 and -1 (a
# gradient step per env step), to keep the CPU cost bounded. rl-zoo3 gives Acrobot-v1 the
# same settings, but bench_control.py trains Acrobot-v1 with rl-zoo3's unchanged.
SMALL_TASK_DQN = {**without_gamma("LunarLander-v2"), "learning_starts": 1000,
                  "gradient_steps": 1}


# rl-zoo3's settings for every Atari game (``atari`` in dqn.yml and ppo.yml; PPO's linear
# schedules of the learning rate and the clip range as their initial values), less its
# image pipeline (AtariWrapper, 4 stacked frames, CnnPolicy): the games benchmark
# (kinds/games.py) feeds the objects to `fqi.SetEncoder` instead.
ATARI_DQN = {
    "learning_rate": 1e-4, "buffer_size": 100_000, "learning_starts": 100_000,
    "batch_size": 32, "target_update_interval": 1000, "train_freq": 4, "gradient_steps": 1,
    "exploration_fraction": 0.1, "exploration_final_eps": 0.01,
}
ATARI_PPO = {"n_envs": 8, "n_steps": 128, "n_epochs": 4, "batch_size": 256,
             "learning_rate": 2.5e-4, "clip_range": 0.1, "vf_coef": 0.5, "ent_coef": 0.01}
# highway-env's own stable-baselines3 scripts for highway-fast-v0 (scripts/sb3_highway_dqn.py
# and sb3_highway_ppo.py, 20,000 steps each; PPO on 6 envs)
HIGHWAY_DQN = {
    "learning_rate": 5e-4, "buffer_size": 15_000, "learning_starts": 200, "batch_size": 32,
    "gamma": 0.8, "train_freq": 1, "gradient_steps": 1, "target_update_interval": 50,
    "policy_kwargs": {"net_arch": [256, 256]},
}
HIGHWAY_PPO = {"n_envs": 6, "n_steps": 128, "batch_size": 64, "n_epochs": 10,
               "learning_rate": 5e-4, "gamma": 0.8,
               "policy_kwargs": {"net_arch": {"pi": [256, 256], "vf": [256, 256]}}}
