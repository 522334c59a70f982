"""Figures in the thesis's form: reward curves with a std band, RMSE bars, the DQN
comparison, reward against environment steps for every method, and the attention figure
(most used test boxes over a local view). Each unit kind picks its figure (`kinds`)."""
import matplotlib

matplotlib.use("Agg")
import gymnasium as gym  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Patch, Rectangle  # noqa: E402
from matplotlib.ticker import MaxNLocator, StrMethodFormatter  # noqa: E402

import envs  # noqa: E402

from .stats import last_window  # noqa: E402

__all__ = ["save", "reward_curves", "rmse_bars", "reward_bars", "versus_steps", "attention",
           "TYPE_NAMES", "ACTION_NAMES"]

# The object types' colours as the renderer draws them (RGB in 0 .. 1, for matplotlib), so
# a test box is outlined in the colour of the objects it tests in the rendered view.
_TYPE_COLOURS = {kind: tuple(c / 255 for c in rgb) for kind, rgb in envs.TYPE_COLOURS.items()}
# envs' names, as labels ("money marker", "swipe up")
TYPE_NAMES = tuple(name.replace("_", " ") for name in envs.TYPE_NAMES)
ACTION_NAMES = tuple(name.replace("_", " ") for name in envs.ACTION_NAMES)
# reference policies' lines, best first (a planner, a heuristic, random play)
_REFERENCE_COLOURS = ("black", "dimgrey", "darkgrey", "silver")
# curves whose last steps differ this many times are drawn on a log scale of steps
_LOG_STEPS = 5
# reward curves of more settings than this get a panel of their scores beside them
_CROWDED = 5


def save(fig, path):
    """Write `fig` to `path` (PNG) and free it."""
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def _title(experiment, budget, stats):
    runs = sorted({s.n_runs for s in stats.values()})
    figure = f"Fig. {experiment.figure}: " if experiment.figure != "extra" else ""
    return (f"{figure}{experiment.title}\n({budget.name} budget, "
            f"{'/'.join(map(str, runs))} run(s) per setting)")


def reward_curves(experiment, stats, budget):
    """Mean reward per iteration with a +-1 sd band over runs; iteration 0 is the random
    policy (left out for the sword game, as in the thesis: it would dwarf the curves). With
    more than `_CROWDED` settings, whose curves overlap where they level off, a panel beside
    them shows each setting's score (+-1 sd over runs) in its curve's colour, best on top."""
    crowded = len(stats) > _CROWDED
    fig, axes = plt.subplots(1, 1 + crowded, figsize=(7.5 + 4.5 * crowded, 4.5),
                             squeeze=False, width_ratios=(7.5, 4.5)[:1 + crowded])
    ax = axes[0, 0]
    if len(stats) > len(plt.rcParams["axes.prop_cycle"].by_key()["color"]):
        ax.set_prop_cycle(color=plt.get_cmap("tab20").colors)  # no colour twice
    first = 1 if experiment.env_id == "ObjectWorldSword-v0" else 0
    colours = {}
    for label, s in stats.items():
        x = np.arange(first, len(s.curve_mean))
        mean, sd = s.curve_mean[first:], s.curve_sd[first:]
        line, = ax.plot(x, mean, marker="o", markersize=3, label=f"{label} ({s.score:,.0f})")
        colours[label] = line.get_color()
        ax.fill_between(x, mean - sd, mean + sd, alpha=0.2)
    ax.axhline(0, color="grey", lw=0.6)
    ax.set_xlabel("iteration (0: random policy)" if first == 0 else "iteration")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("reward per 20,000 greedy steps")
    window = last_window(budget)
    title = f"setting (mean of last {window} it.)"
    if crowded:
        _legend_below(ax, title, ncols=2)
    else:
        ax.legend(fontsize=8, title=title, title_fontsize=8)
    ax.grid(alpha=0.3)
    if crowded:
        _score_panel(axes[0, 1], stats, colours, window)
        fig.suptitle(_title(experiment, budget, stats), fontsize=10)
    else:
        ax.set_title(_title(experiment, budget, stats), fontsize=10)
    return fig


def _legend_below(ax, title, ncols=1):
    """`ax`'s legend under it, where many entries do not hide the curves."""
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=ncols,
              title=title, title_fontsize=7)


def _score_panel(ax, stats, colours, window):
    """Each setting's score +-1 sd over runs as a dot on its own row, best on top, in the
    colour of its curve (`colours`: label -> colour)."""
    labels = sorted(stats, key=lambda label: stats[label].score)
    for row, label in enumerate(labels):
        s = stats[label]
        ax.errorbar(s.score, row, xerr=s.score_sd if s.n_runs > 1 else None, fmt="o",
                    color=colours[label], capsize=3)
    runs = {label: stats[label].n_runs for label in labels}
    ax.set_yticks(range(len(labels)), [f"{label} ({runs[label]} run{'s' * (runs[label] > 1)})"
                                       for label in labels], fontsize=7)
    ax.yaxis.tick_right()
    ax.set_xlabel(f"mean of the last {window} iterations (+-1 sd over runs)", fontsize=8)
    ax.xaxis.set_major_locator(MaxNLocator(4))
    ax.xaxis.set_major_formatter(StrMethodFormatter("{x:,.0f}"))
    ax.tick_params(axis="x", labelsize=7)
    ax.grid(axis="x", alpha=0.3)


def rmse_bars(experiment, stats, runs, budget):
    """Appendix A: mean cross-validated RMSE per setting, error bars 1 sd over folds."""
    fig, ax = plt.subplots(figsize=(6, 4))
    labels = list(stats)
    means = [stats[label].score for label in labels]
    sds = [np.std([f for r in runs[label] for f in r["result"]["fold_rmse"]])
           for label in labels]
    best = int(np.argmin(means))
    colours = ["tab:green" if i == best else "tab:blue" for i in range(len(labels))]
    ax.bar(labels, means, yerr=sds, capsize=4, color=colours)
    low = min(m - s for m, s in zip(means, sds))
    high = max(m + s for m, s in zip(means, sds))
    if high > low:  # zoom on the differences (the thesis's bars start near the lowest)
        ax.set_ylim(max(0.0, low - 0.3 * (high - low)), high + 0.1 * (high - low))
    ax.set_ylabel(f"RMSE ({budget.rmse_folds}-fold CV, mean over actions)")
    ax.set_title(_title(experiment, budget, stats), fontsize=10)
    ax.grid(axis="y", alpha=0.3)
    return fig


def reward_bars(experiment, stats, budget):
    """Bars: reward (mean +- sd over runs) and wall time per run of each setting (FQI in
    blue, the others: DQN, the searches' configurations, reference policies)."""
    fig, ax = plt.subplots(figsize=(6.5, 4))
    labels = list(stats)
    ax.bar(labels, [stats[label].score for label in labels],
           yerr=[stats[label].score_sd for label in labels], capsize=4,
           color=["tab:blue" if stats[label].kind == "fqi" else "tab:orange"
                  for label in labels])
    for i, label in enumerate(labels):
        ax.annotate(f"{stats[label].seconds / 60:.1f} min/run", (i, 0), ha="center",
                    va="bottom", fontsize=8, xytext=(0, 3), textcoords="offset points")
    ax.axhline(0, color="grey", lw=0.6)
    ax.set_ylabel("reward per 20,000 greedy steps")
    ax.set_title(_title(experiment, budget, stats), fontsize=10)
    ax.grid(axis="y", alpha=0.3)
    return fig


def versus_steps(experiment, stats, curves, budget, ylabel="reward per 20,000 greedy steps",
                 threshold=None):
    """Reward against environment steps, mean +- 1 sd over runs (`curves`: label ->
    ``(steps, mean, sd)`` of its kind's ``curve``: FQI after each iteration, the random
    policy at 0; the baselines at their checkpoints); settings without a curve (reference
    policies) as horizontal lines, and a `threshold` (a task's "solved") dotted. Steps are
    on a log scale when the curves' budgets differ `_LOG_STEPS` times or more (and no curve
    starts at 0)."""
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    references = 0
    for label, s in stats.items():
        if curves[label] is None:
            colour = _REFERENCE_COLOURS[references % len(_REFERENCE_COLOURS)]
            references += 1
            ax.axhline(s.score, ls="--", lw=1.0, color=colour)
            ax.annotate(f"{label} ({s.score:,.0f})", (0, s.score), xytext=(2, 3),
                        xycoords=("axes fraction", "data"), textcoords="offset points",
                        fontsize=7, color=colour)
            continue
        x, mean, sd = curves[label]
        ax.plot(x, mean, marker="o", markersize=3, label=f"{label} ({s.score:,.0f}, "
                f"{s.seconds / 60:.0f} min/run)")
        ax.fill_between(x, mean - sd, mean + sd, alpha=0.2)
    low, high = ax.get_ylim()
    if low < 0 < high:  # a zero line only where it is in the data's range, not to stretch it
        ax.axhline(0, color="grey", lw=0.6)
    if threshold is not None:
        ax.axhline(threshold, color="black", ls=":", lw=1.0)
        ax.annotate(f"solved ({threshold:,.0f})", (0, threshold), xytext=(2, 3),
                    xycoords=("axes fraction", "data"), textcoords="offset points",
                    fontsize=7)
    ax.set_xlabel("environment steps")
    steps = [curve[0] for curve in curves.values() if curve is not None and len(curve[0])]
    ends = [x[-1] for x in steps]
    if steps and min(x[0] for x in steps) > 0 and max(ends) >= _LOG_STEPS * min(ends):
        ax.set_xscale("log")  # budgets this far apart would squeeze the shorter curves
        ax.set_xlabel("environment steps (log scale)")
    ax.xaxis.set_major_formatter(StrMethodFormatter("{x:,.0f}"))
    ax.yaxis.set_major_formatter(StrMethodFormatter("{x:,.0f}"))
    ax.set_ylabel(ylabel)
    ax.set_title(_title(experiment, budget, stats), fontsize=10)
    _legend_below(ax, "method (final score, wall time)")
    ax.grid(alpha=0.3)
    return fig


def attention(experiment, runs, budget):
    """Per action, the most informative test boxes of the Q-forest on every object type
    (outline colour: the tested type; solid when more objects in the box raise Q, dashed when
    they lower it; line width: the test's weighted variance reduction) over the local view of
    a reference world the agent never trained on."""
    (label, records), = runs.items()
    result = records[0]["result"]
    params = experiment.params(label, budget)
    env = gym.make(params["env_id"], render_mode="rgb_array", render_view="local")
    env.reset(seed=result["world_seed"])
    image = env.render()
    extent = env.unwrapped.rules.obs_bound + 1.0  # the local render's half-side
    env.close()
    n_actions = len(result["actions"])
    cols = 4
    rows = -(-n_actions // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.3 * cols, 3.6 * rows + 0.6), squeeze=False)
    strongest = max((t[7] for a in result["actions"] for t in a["tests"]), default=1.0) or 1.0
    for action, (ax, info) in enumerate(zip(axes.flat, result["actions"])):
        ax.imshow(image, extent=(-extent, extent, -extent, extent))
        for xmin, xmax, ymin, ymax, kind, threshold, _, reduction, effect in info["tests"]:
            box = np.clip([xmin, xmax, ymin, ymax], -extent, extent)
            ax.add_patch(Rectangle((box[0], box[2]), box[1] - box[0], box[3] - box[2],
                                   fill=False, lw=0.6 + 3.0 * reduction / strongest,
                                   ls="-" if effect > 0 else "--",
                                   edgecolor=_TYPE_COLOURS[int(kind)]))
        top = np.argsort(info["type_usage"])[::-1][:2]
        usage = ", ".join(f"{TYPE_NAMES[t]} {info['type_usage'][t]:.0%}" for t in top)
        ax.set_title(f"{ACTION_NAMES[action]}: Q = {result['q_values'][action]:,.0f}\n"
                     f"tests on {usage}", fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in axes.flat[n_actions:]:
        ax.axis("off")
    types = sorted({int(t[4]) for a in result["actions"] for t in a["tests"]})
    fig.legend(handles=[Patch(edgecolor=_TYPE_COLOURS[t], fill=False, label=TYPE_NAMES[t])
                        for t in types]
               + [Patch(edgecolor="black", fill=False, ls=ls, label=what)
                  for ls, what in (("-", "attracts (more objects, higher Q)"),
                                   ("--", "repels (more objects, lower Q)"))],
               loc="lower center", ncol=len(types) + 2, fontsize=8)
    fig.suptitle(f"Most informative tests per action, {label} Q-forest after "
                 f"{budget.attention_iterations} iterations ({budget.name} budget)", fontsize=10)
    return fig
