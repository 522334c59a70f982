"""Named budgets: how many seeds, iterations, samples and evaluation steps a run gets.

A budget's name is part of every cache path (``<out>/runs/<budget>/...``), so runs of
different budgets never mix.
"""
from dataclasses import dataclass, field

__all__ = ["Budget", "BUDGETS", "EVAL_REFERENCE_STEPS"]

# Rewards are reported per 20,000 evaluation steps (the thesis's 400 episodes of 50 steps).
EVAL_REFERENCE_STEPS = 20_000


@dataclass(frozen=True)
class Budget:
    """Sizes of every unit of work at one level of effort.

    Parameters
    ----------
    name : str
        Folder name under ``<out>/runs/``.
    seeds : int
        Runs per setting (seeds ``0 .. seeds - 1``).
    iterations : int
        FQI iterations per run.
    samples : int
        Transitions collected per FQI iteration (experiments may scale it, e.g. the sword
        game's 40,000).
    eval_steps : int
        Greedy evaluation steps after each iteration (a multiple of 50); rewards are
        rescaled to 20,000 steps in every table and plot.
    rmse_samples, rmse_folds : int
        Random-policy transitions and cross-validation folds of the appendix's RMSE study.
    dqn_steps : int or None
        DQN environment steps; None: as many as the FQI run (iterations x samples).
    attention_iterations : int
        FQI iterations of the run whose Q-forest the attention figure draws.
    max_trees, max_tests : int or None
        Caps on the forests' M and K (None: the thesis's values).
    control_scale : float, default=1.0
        Multiplies the environment steps of the runs on gymnasium's tasks and on the real
        games (``control`` and ``games`` units), whose settings give them at full size.
    game_frames : int, default=None
        Caps the frames of an Atari episode of the ``games`` units (None: ALE's 108,000).
    overrides : dict of str to dict
        Experiment name -> parameters replacing its settings' at this budget (applied to
        every setting of the experiment alike, so its comparison stays fair).
    """

    name: str
    seeds: int
    iterations: int
    samples: int
    eval_steps: int
    rmse_samples: int
    rmse_folds: int
    dqn_steps: int = None
    attention_iterations: int = 3
    max_trees: int = None
    max_tests: int = None
    control_scale: float = 1.0
    game_frames: int = None
    overrides: dict = field(default_factory=dict)

    @property
    def reward_scale(self):
        """Factor turning an evaluation total into a reward per 20,000 steps."""
        return EVAL_REFERENCE_STEPS / self.eval_steps


_QUICK_ITERATIONS = 4
BUDGETS = {
    "full": Budget("full", seeds=5, iterations=20, samples=20_000, eval_steps=20_000,
                   rmse_samples=20_000, rmse_folds=10, attention_iterations=10),
    # Two seeds (sd bands, noise-aware verdicts) of every experiment in about 7.5 min on 2
    # cores (`make bench` runs two at a time; 10 min with its set-up). The tuned baselines'
    # steps follow the FQI run's, and they evaluate once per FQI iteration, as at the full
    # budget (evaluating 20 times, they took 9 of the 24 min that 5 x 4,000 samples took).
    # The treasure game's global view holds ~360 objects per state (local view ~40); with
    # the thesis's M=30, K=500 its run cost 9x the local view's, so at this budget all four
    # views get smaller forests.
    "quick": Budget("quick", seeds=2, iterations=_QUICK_ITERATIONS, samples=2_000,
                    eval_steps=8_000, rmse_samples=5_000, rmse_folds=3, attention_iterations=3,
                    control_scale=0.2,
                    overrides={"treasure": {"n_estimators": 10, "n_tests": 200},
                               "baselines": {"checkpoints": _QUICK_ITERATIONS}}),
    # for the tests: every experiment end to end in seconds
    "tiny": Budget("tiny", seeds=1, iterations=2, samples=200, eval_steps=50,
                   rmse_samples=200, rmse_folds=2, dqn_steps=100, attention_iterations=1,
                   max_trees=2, max_tests=10, control_scale=0.01, game_frames=800),
}
