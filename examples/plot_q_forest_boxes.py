"""
The boxes a Q-forest learns
===========================

In the ObjectWorld game (``ObjectWorld-v0``) the agent sees the objects around it as rows
``[dx, dy, type]``, positions relative to itself in a view square of half-side 10: coins
(+100), walls (-50), grass (no effect) and enemies (-300, they chase the agent). Fitted
Q-iteration (:class:`fqi.FQI`) learns one box forest per action as its Q-function; each
node of a tree asks "are there at least ``z`` objects of this type in this box?".

After a short run we draw the most informative tests of one tree: the boxes whose splits
reduce the variance of the Q-targets the most (:meth:`boxtrees.BoxTree.split_gains`).
"""

import gymnasium as gym
import matplotlib.pyplot as plt
import numpy as np

import envs  # registers ObjectWorld-v0
from fqi import FQI, make_box_forest

# %%
# A short run
# -----------
# :func:`fqi.make_box_forest` is the thesis's forest (fixed boxes of half-width 1, drawn
# in the view square that it reads from the observation space), here with 20 trees.
# ``gamma=0.5`` is the thesis's discount for this game. Each of the 6 iterations
# collects 2,000 new transitions (``resample_every=1``) with the greedy policy of the
# last Q-function, 20 % of the actions at random (the first iteration plays at random:
# there is no Q-function yet), adds them to those kept so far, and fits the Q-function
# anew on all of them. After each iteration the greedy policy plays 20 evaluation
# episodes of 50 steps on fixed worlds.
env_id = "ObjectWorld-v0"
forest = make_box_forest(env_id, n_estimators=20, n_jobs=2)
agent = FQI(forest, env_id, gamma=0.5, samples_per_iteration=2_000,
            resample_every=1, exploration_initial_eps=0.2,
            exploration_final_eps=0.2, eval_episodes=20, seed=0)
agent.learn(n_iterations=6)
for record in agent.history:   # mean return of the evaluation episodes
    print(f"iteration {record['iteration']}: {record['mean_return']:6.1f}")

# %%
# The tests of one tree
# ---------------------
# A fitted tree is a :class:`boxtrees.BoxTree`: flat arrays indexed by node. Node ``i``
# counts the objects of type ``object_type[i]`` inside ``box[i]`` (``xmin, xmax, ymin,
# ymax``) and sends the state right when there are at least ``threshold[i]`` of them.
# We keep the 8 nodes with the largest split gains in the first tree of the Q-function of
# the action "up".
action = envs.ACTION_NAMES.index("up")
tree = agent.q_functions_[action].estimators_[0].tree_
gains = tree.split_gains()
top = np.argsort(gains)[::-1][:8]
for node in top:
    print(f"node {node:4d}: {envs.TYPE_NAMES[tree.object_type[node]]:6s} "
          f"x in ({tree.box[node, 0]:5.1f}, {tree.box[node, 1]:5.1f}), "
          f"y in ({tree.box[node, 2]:5.1f}, {tree.box[node, 3]:5.1f}), "
          f"at least {tree.threshold[node]:.0f}, gain {gains[node]:.3g}")

# %%
# Drawing them
# ------------
# Each box is drawn in its type's colour over the agent's view, zoomed on the boxes (the
# agent is the black dot at the centre, "up" is up). A solid box *attracts*: states
# with the objects in it (the node's right child) have the higher Q-value for "up"; a
# dashed box *repels*. The wider the line, the larger the gain.
fig, ax = plt.subplots(figsize=(5.5, 5.5))
for node in top:
    xmin, xmax, ymin, ymax = tree.box[node]
    kind = tree.object_type[node]
    left, right = tree.children_left[node], tree.children_right[node]
    attracts = tree.value[right] > tree.value[left]
    ax.add_patch(plt.Rectangle(
        (xmin, ymin), xmax - xmin, ymax - ymin, fill=False,
        edgecolor=np.array(envs.TYPE_COLOURS[kind]) / 255,
        linestyle="-" if attracts else "--",
        lw=1 + 4 * gains[node] / gains[top[0]]))
ax.plot(0, 0, "o", color="black", ms=8)
for kind in sorted(set(tree.object_type[top])):   # a legend of the types
    ax.plot([], [], color=np.array(envs.TYPE_COLOURS[kind]) / 255, lw=3,
            label=envs.TYPE_NAMES[kind])
ax.legend(loc="upper right", fontsize="small")
reach = min(10, np.ceil(np.abs(tree.box[top]).max()) + 1)  # zoom on them
ax.set(xlim=(-reach, reach), ylim=(-reach, reach), aspect="equal",
       xlabel="dx", ylabel="dy",
       title=f"Top tests of a tree of Q(s, up), {tree.node_count} nodes")
fig.tight_layout()

# %%
# The view these boxes are read from
# ----------------------------------
# The same frame as the agent sees it: the rows of one observation, drawn with the game's
# own renderer (``render_view="local"``).
world = gym.make(env_id, render_mode="rgb_array", render_view="local")
observation, _ = world.reset(seed=1)
action, _ = agent.predict(observation)
print(f"{len(observation)} objects in view; the greedy action: "
      f"{envs.ACTION_NAMES[int(action)]}")
fig, ax = plt.subplots(figsize=(4, 4))
ax.imshow(world.render())
ax.set_axis_off()
fig.tight_layout()
