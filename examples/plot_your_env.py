"""
Fitted Q-iteration on your own environment
==========================================

:class:`fqi.FQI` runs on any gymnasium environment with a ``Discrete`` action space. With a
``Box`` observation space the Q-function's regressor sees a plain feature matrix, so any
scikit-learn regressor plugs in.

Here the environment is a walk on a line: the agent starts anywhere in ``[-5, 5]``, moves
one step left or right, pays -1 per step and stops on reaching the goal ``|x| < 1``. The
best policy walks straight to the goal, and the best value of ``x`` is minus the number of
steps it takes.
"""

import gymnasium as gym
import matplotlib.pyplot as plt
import numpy as np
from sklearn.ensemble import ExtraTreesRegressor

from fqi import FQI, evaluate


# %%
# The environment
# ---------------
# A gymnasium env needs its two spaces, ``reset`` and ``step``. ``TimeLimit`` ends the
# episodes that wander off after 30 steps (a truncation: FQI bootstraps through it).
class Walk(gym.Env):
    """Walk from a random start in [-5, 5] to the goal |x| < 1; -1 per step."""

    observation_space = gym.spaces.Box(-10, 10, shape=(1,), dtype=np.float32)
    action_space = gym.spaces.Discrete(2)  # 0: left, 1: right

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x = float(self.np_random.uniform(-5, 5))
        return np.array([self.x], dtype=np.float32), {}

    def step(self, action):
        self.x = float(np.clip(self.x + (1 if action else -1), -10, 10))
        reached = abs(self.x) < 1
        return np.array([self.x], dtype=np.float32), -1.0, reached, False, {}


env = gym.wrappers.TimeLimit(Walk(), max_episode_steps=30)

# %%
# Learning
# --------
# ``learn(total_timesteps=...)`` works as in stable-baselines3: rounds of
# ``samples_per_iteration`` environment steps, each followed by ``resample_every``
# fitted-Q backups (5 by default) on every transition kept so far. The probability of a
# random action falls from 1 to 0.05 over the first tenth of the steps. As in
# stable-baselines3, nothing is evaluated unless asked: here, after every backup, the greedy
# policy plays 10 evaluation episodes from fixed reset seeds (``eval_episodes=10``). The env
# is copied into 16 envs played side by side (``n_envs``), so the regressors predict the
# actions of 16 states at a time.
regressor = ExtraTreesRegressor(n_estimators=20, random_state=0)
agent = FQI(regressor, env, samples_per_iteration=1_000, n_envs=16, eval_episodes=10, seed=0)
agent.learn(total_timesteps=5_000)

# Each record of ``agent.history`` is one iteration. The first round's random data
# already hold the answer: each backup carries the values one step further from the
# goal, and within that round's five backups the greedy policy walks straight to the
# goal from the evaluation starts (about 3 steps), before any new data arrive.
iterations = [record["iteration"] for record in agent.history]
returns = [record["mean_return"] for record in agent.history]

fig, ax = plt.subplots(figsize=(6, 3.5))
ax.plot(iterations, returns, "o-", ms=3)
for start in iterations[::agent.resample_every]:   # a new collection round
    ax.axvline(start, color="grey", lw=0.5, ls=":")
ax.set(xlabel="iteration (fitted-Q backup; dotted: 1,000 new steps)",
       ylabel="mean return (10 episodes)", title="Evaluation after each backup")
fig.tight_layout()

# %%
# The learned Q-values
# --------------------
# ``q_values`` gives the value of each action for a batch of observations. Right is worth
# more left of the goal and left is worth more right of it; both sit near minus the number
# of steps to the goal (the discount, 0.99 by default, barely shows at these distances).
x = np.linspace(-5, 5, 201, dtype=np.float32)
q = agent.q_values(x[:, None])

fig, ax = plt.subplots(figsize=(6, 3.5))
ax.plot(x, q[:, 0], label="Q(x, left)")
ax.plot(x, q[:, 1], label="Q(x, right)")
ax.axvspan(-1, 1, color="tab:green", alpha=0.15, label="goal")
ax.set(xlabel="x", ylabel="Q-value", title="Q-values after 5,000 steps")
ax.legend()
fig.tight_layout()

# %%
# Scoring the policy
# ------------------
# :func:`fqi.evaluate` plays one greedy episode per reset seed, for any policy with a
# stable-baselines3 ``predict`` method; seeds unseen in training give a fair score.
result = evaluate(agent, env, seeds=range(1000, 1020))
print(f"mean return over 20 new episodes: {result.mean:.2f} "
      f"(longest episode: {result.lengths.max()} steps)")
