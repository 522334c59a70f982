"""``attention``: the figure of the most used tests of a learned Q-forest (in the style of
the thesis's Fig. 2.2), from a short FQI run."""
import numpy as np

import envs

from .. import plots
from ..cache import ListOf
from ..stats import SettingStats
from ._base import UnitKind, _seconds, fmt
from ._game import AgentSettings, agent_cost, make_agent, make_env

__all__ = ["Attention", "TEST_COLUMNS"]

_TOP_TESTS = 4  # boxes drawn per action and object type
_CANDIDATES = 40  # reference worlds searched for a busy view to draw on
TEST_COLUMNS = ("xmin", "xmax", "ymin", "ymax", "type", "threshold", "n_node_samples",
                "variance_reduction", "effect")


class Attention(UnitKind):
    """Per action, the most informative tests on each object type and the share of test
    usage per type, and a busy reference view to draw them on."""

    name = "attention"
    Settings = AgentSettings
    budget_fields = ("attention_iterations", "eval_steps", "max_trees", "max_tests")
    one_seed = True

    def run(self, unit, checkpoint=None):
        settings, budget = unit.settings, unit.budget
        agent = make_agent(settings, budget, unit.seed, unit.samples).learn(
            n_iterations=budget.attention_iterations)
        n_types = make_env(settings).unwrapped.n_types
        world_seed, observation = _busy_reference_view(settings)
        actions = []
        for forest in agent.q_functions_:
            tests = np.concatenate([tree_tests(tree.tree_) for tree in forest.estimators_])
            tests = tests[np.argsort(-tests[:, 7], kind="stable")]
            top = np.concatenate([tests[tests[:, 4] == t][:_TOP_TESTS]
                                  for t in range(n_types)])
            usage = np.bincount(tests[:, 4].astype(int), weights=tests[:, 6],
                                minlength=n_types)
            share = usage / usage.sum() if usage.sum() else usage  # a tree without tests
            actions.append({"tests": top.tolist(), "type_usage": share.tolist()})
        return {"world_seed": world_seed, "observation": observation.tolist(),
                "q_values": agent.q_values(observation).tolist(),
                "reward": agent.history[-1]["reward"] * budget.reward_scale,
                "test_columns": list(TEST_COLUMNS), "actions": actions}

    def cost(self, unit):
        return agent_cost(unit.settings, unit.budget.attention_iterations, unit.samples)

    def record_shape(self, budget):
        return {"world_seed": int, "reward": float, "q_values": ListOf(float),
                "actions": ListOf({"tests": ListOf(ListOf(float, len(TEST_COLUMNS))),
                                   "type_usage": ListOf(float)})}

    def summarise(self, label, runs):
        return SettingStats(label, self.name, len(runs), np.nan, np.nan, np.nan,
                            seconds=_seconds(runs))

    def plot(self, experiment, stats, runs, budget):
        return plots.attention(experiment, runs, budget)

    def table(self, experiment, stats, runs):
        (label, records), = runs.items()
        result = records[0]["result"]
        n_types = len(result["actions"][0]["type_usage"])
        lines = [f"Reward of the drawn Q-function: {fmt(result['reward'])}. Share of training "
                 f"samples passing each type's tests (sample-weighted test usage), per "
                 f"action:", "",
                 "| action | " + " | ".join(plots.TYPE_NAMES[t] for t in range(n_types)) + " |",
                 "| --- |" + " --- |" * n_types]
        for action, info in enumerate(result["actions"]):
            lines.append(f"| {plots.ACTION_NAMES[action]} | "
                         + " | ".join(f"{u:.0%}" for u in info["type_usage"]) + " |")
        return lines


def tree_tests(tree):
    """Inner nodes of a `boxtrees.BoxTree` as rows of `TEST_COLUMNS`: the effect is the Q
    value of the node's right child (at least ``threshold`` objects in the box) minus its
    left child's, positive when the objects in the box attract the agent (the thesis's blue
    boxes), negative when they repel it (red)."""
    inner = np.flatnonzero(tree.children_left >= 0)
    left, right = tree.children_left[inner], tree.children_right[inner]
    effect = tree.value[right] - tree.value[left]
    return np.column_stack([tree.box[inner], tree.object_type[inner], tree.threshold[inner],
                            tree.n_node_samples[inner], tree.split_gains()[inner],
                            effect]).astype(np.float64)


def _busy_reference_view(settings):
    """The first reference world (never trained on) whose starting view holds the most
    object types, then the most objects: its seed and observation."""
    env = make_env(settings)
    best = None
    for world_seed in envs.reference_worlds(_CANDIDATES):
        obs, _ = env.reset(seed=world_seed)
        key = (len(np.unique(obs[:, 2])), len(obs))
        if best is None or key > best[0]:
            best = (key, world_seed, obs)
    env.close()
    return best[1], best[2]
