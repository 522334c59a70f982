"""Command line of ``benchmarks/run_all.py``."""
import argparse
import time

from .budgets import BUDGETS
from .registry import EXPERIMENTS, REGISTRY
from .report import write_outputs
from .runner import plan, run

__all__ = ["main", "parse_seeds"]


def parse_seeds(text):
    """``"3"`` -> seeds 0, 1, 2; ``"0,2"`` -> 0 and 2; ``"2-4"`` -> 2, 3, 4."""
    try:
        if "," in text:
            return [int(s) for s in text.split(",") if s]
        if "-" in text:
            low, high = (int(s) for s in text.split("-"))
            return list(range(low, high + 1))
        return list(range(int(text)))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--seeds takes a count (3), a list (0,2,4) or a range (0-4); got {text!r}") from None


def _experiments(text):
    if text is None:
        return list(EXPERIMENTS)
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in REGISTRY]
    if unknown:
        raise argparse.ArgumentTypeError(
            f"unknown experiment(s) {', '.join(unknown)}; known: {', '.join(REGISTRY)}")
    return [REGISTRY[n] for n in names]


def _parser():
    parser = argparse.ArgumentParser(
        prog="run_all.py",
        description="Reproduce the thesis's experiments (figures A.1-A.5, 3.1-3.6, 3.8-3.10) "
                    "and the extras (kept data, DQN, attention); write one PNG per figure, "
                    "the raw runs and REPORT.md. Finished runs are cached and skipped, so "
                    "an interrupted run resumes where it stopped.")
    mode = parser.add_mutually_exclusive_group()
    quick = BUDGETS["quick"]
    mode.add_argument("--quick", action="store_const", const="quick", dest="budget",
                      help=f"reduced budget ({quick.seeds} seeds, {quick.iterations} iterations x "
                           f"{quick.samples:,} samples), ~9 min on 2 cores")
    mode.add_argument("--budget", choices=sorted(BUDGETS),
                      help="named budget (default: full, the thesis's)")
    parser.set_defaults(budget="full")
    parser.add_argument("--only", type=_experiments, default=None, metavar="NAME[,NAME]",
                        help=f"run only these experiments ({', '.join(REGISTRY)})")
    parser.add_argument("--seeds", type=parse_seeds, default=None,
                        help="seeds: a count (3), a list (0,2,4) or a range (0-4); default: "
                             "the budget's")
    parser.add_argument("--out", default="results", help="output folder (default: results)")
    parser.add_argument("--jobs", type=int, default=1,
                        help="parallel runs (default 1: each run already uses every core)")
    parser.add_argument("--report-only", action="store_true",
                        help="run nothing; rebuild figures and REPORT.md from cached runs")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    return parser


def main(argv=None):
    """Run the selected experiments, then write figures, raw numbers and the report.

    Parameters
    ----------
    argv : list of str, default=None
        Command-line arguments (None: ``sys.argv[1:]``).

    Returns
    -------
    report : pathlib.Path
        The written REPORT.md.
    """
    args = _parser().parse_args(argv)
    budget = BUDGETS[args.budget]
    experiments = args.only or list(EXPERIMENTS)
    start = time.perf_counter()
    units = plan(experiments, budget, args.out, args.seeds)
    done = [] if args.report_only else run(units, budget, args.jobs, not args.no_progress)
    elapsed = time.perf_counter() - start
    # a report-only invocation ran nothing: its header says so by omitting the timing
    report = write_outputs(experiments, budget, args.out, args.seeds,
                           None if args.report_only else elapsed, len(done))
    print(f"\n{len(done)} runs in {elapsed / 60:.1f} min; report: {report}")
    return report
