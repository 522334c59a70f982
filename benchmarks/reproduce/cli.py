"""Command line of ``python -m benchmarks.run_all``."""
import argparse
import os
import time
from collections import Counter
from pathlib import Path

from .budgets import BUDGETS
from .cache import load_unit
from .registry import EXPERIMENTS, REGISTRY
from .report import write_outputs
from .runner import MAX_ATTEMPTS, ClusterError, cluster, plan, run

__all__ = ["main", "parse_seeds"]

# Seeds are random_state of numpy and scikit-learn: 0 .. 2**32 - 1.
_MAX_SEED = 2**32 - 1
# Each seed costs minutes per setting, so more is a typo: "100000" would otherwise plan
# millions of units, filling the memory before any ran.
_MAX_SEEDS = 1000


def parse_seeds(text):
    """``"3"`` -> seeds 0, 1, 2; ``"0,2"`` -> 0 and 2; ``"2-4"`` -> 2, 3, 4.

    Raises
    ------
    argparse.ArgumentTypeError
        If `text` is none of these, or selects no seed, a seed twice, a seed outside
        0 .. 2**32 - 1 or more than `_MAX_SEEDS` seeds.
    """
    try:
        if "," in text:
            seeds = [int(s) for s in text.split(",") if s.strip()]
        elif "-" in text:
            low, high = (int(s) for s in text.split("-"))
            seeds = range(low, high + 1)
        else:
            seeds = range(int(text))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a count (3), a list (0,2,4) or a range (0-4), got {text!r}") from None
    if not seeds:
        problem = "selects no seed"
    elif len(seeds) > _MAX_SEEDS:  # before min and max, which walk a range
        problem = f"selects {len(seeds):,} seeds, more than {_MAX_SEEDS:,}"
    elif min(seeds) < 0 or max(seeds) > _MAX_SEED:
        problem = f"selects a seed outside 0 .. {_MAX_SEED}"
    elif len(set(seeds)) < len(seeds):
        repeated = sorted(s for s, n in Counter(seeds).items() if n > 1)
        problem = f"repeats seed {', '.join(map(str, repeated))}"
    else:
        return list(seeds)
    raise argparse.ArgumentTypeError(f"{text!r} {problem}")


def _experiments(text):
    """``"a,b"`` -> the registry's experiments a and b (each once)."""
    names = list(dict.fromkeys(n.strip() for n in text.split(",") if n.strip()))
    unknown = [n for n in names if n not in REGISTRY]
    if not names or unknown:
        problem = (f"unknown experiment(s) {', '.join(unknown)}" if unknown
                   else "names no experiment")
        raise argparse.ArgumentTypeError(f"{problem}; known: {', '.join(REGISTRY)}")
    return [REGISTRY[n] for n in names]


def _count(text):
    """``"2"`` -> 2: a whole number (of parallel runs or workers), at least 1."""
    try:
        count = int(text)
    except ValueError:
        count = None
    if count is None or count < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number of 1 or more, got {text!r}")
    return count


def _address(text):
    """A Dask scheduler's address (``tcp://host:8786`` or ``host:8786``), if not blank."""
    if not text.strip():
        raise argparse.ArgumentTypeError("expected a scheduler address (tcp://host:8786)")
    return text.strip()


def _out(text):
    """The output folder `text`, if no file stands where it or a folder above it goes."""
    path = Path(text)
    existing = next((p for p in (path, *path.parents) if os.path.exists(p)), path)
    if os.path.exists(existing) and not os.path.isdir(existing):
        raise argparse.ArgumentTypeError(f"{existing} exists and is not a folder")
    return text


def _parser():
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks.run_all",
        description="Reproduce the thesis's experiments (figures A.1-A.5, 3.1-3.6, 3.8-3.10) "
                    "and the extras (kept data, DQN, attention); write one PNG per figure, "
                    "the raw runs and REPORT.md. Finished runs are cached and skipped, so "
                    "an interrupted run resumes where it stopped.")
    mode = parser.add_mutually_exclusive_group()
    quick = BUDGETS["quick"]
    mode.add_argument("--quick", action="store_const", const="quick", dest="budget",
                      help=f"reduced budget ({quick.seeds} seeds, {quick.iterations} iterations x "
                           f"{quick.samples:,} samples), ~7 min on 2 cores with --jobs 2")
    mode.add_argument("--budget", choices=sorted(BUDGETS),
                      help="named budget (default: full, the thesis's)")
    parser.set_defaults(budget="full")
    parser.add_argument("--only", type=_experiments, default=None, metavar="NAME[,NAME]",
                        help=f"run only these experiments ({', '.join(REGISTRY)})")
    parser.add_argument("--seeds", type=parse_seeds, default=None,
                        help="seeds: a count (3), a list (0,2,4) or a range (0-4); default: "
                             "the budget's")
    parser.add_argument("--out", type=_out, default="results",
                        help="output folder (default: results)")
    parser.add_argument("--jobs", type=_count, default=1,
                        help="parallel runs (default 1: each run already uses every core)")
    dask = parser.add_mutually_exclusive_group()
    dask.add_argument("--scheduler", type=_address, metavar="ADDRESS",
                      help="run on the Dask cluster of this scheduler (tcp://host:8786); its "
                           "workers need the project, the results are written here "
                           "(docs/reproduction.md)")
    dask.add_argument("--dask-local", type=_count, metavar="N",
                      help="run on a Dask cluster of N worker processes on this machine")
    nothing = parser.add_mutually_exclusive_group()
    nothing.add_argument("--report-only", action="store_true",
                         help="run nothing; rebuild figures and REPORT.md from cached runs")
    nothing.add_argument("--plan", action="store_true",
                         help="run and write nothing; print how many runs the command plans, "
                              "how many are not cached under --out and the runner's estimate "
                              "of their time")
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
    report : pathlib.Path or None
        The written REPORT.md; None with ``--plan``, which writes nothing and prints what
        the command would run (`_plan_line`).

    Raises
    ------
    SystemExit
        Status 2 for an invalid argument; 130 on an interrupt; 1 if a file under ``--out``
        cannot be written, the Dask cluster cannot run the units (not reachable, or a worker
        with other code), or (after the report) if a unit was skipped for crashing
        `MAX_ATTEMPTS` times. One line on stderr says why.
    """
    parser = _parser()
    args = parser.parse_args(argv)
    if args.jobs > 1 and (args.scheduler or args.dask_local):
        option = "--scheduler" if args.scheduler else "--dask-local"
        parser.error(f"argument --jobs: not allowed with argument {option} (the cluster's "
                     f"workers run the units)")
    budget = BUDGETS[args.budget]
    experiments = args.only or [e for e in EXPERIMENTS if not e.on_demand]
    start = time.perf_counter()
    try:
        units = plan(experiments, budget, args.out, args.seeds)
        if args.plan:
            print(_plan_line(units, budget))
            return None
        done, skipped = ([], []) if args.report_only else _run(units, budget, args)
        elapsed = time.perf_counter() - start
        # a report-only invocation ran nothing: its header says so by omitting the timing
        report = write_outputs(experiments, budget, args.out, args.seeds,
                               None if args.report_only else elapsed, len(done))
    except ClusterError as error:
        parser.exit(1, f"{parser.prog}: error: {error}\n")
    except KeyboardInterrupt:
        parser.exit(130, f"{parser.prog}: interrupted; finished runs are cached: run the "
                         f"same command to resume\n")
    except OSError as error:
        if not _under(error.filename, args.out):
            raise
        parser.exit(1, f"{parser.prog}: error: cannot write under --out {args.out}: "
                       f"{error.strerror}: {error.filename}\n")
    print(f"\n{len(done)} runs in {elapsed / 60:.1f} min; report: {report}")
    if skipped:
        parser.exit(1, f"{parser.prog}: error: {len(skipped)} run(s) skipped after crashing "
                       f"{MAX_ATTEMPTS} times (listed above); the report counts them as "
                       f"missing\n")
    return report


def _plan_line(units, budget):
    """The units planned, those not cached, and the runner's estimate of their time: the sum
    of their `Unit.cost` (seconds on 2 free cores, one run at a time) and the longest."""
    todo = [unit for unit in units if load_unit(unit) is None]
    costs = [unit.cost() / 3600 for unit in todo]
    return (f"{len(units)} runs planned at the {budget.name} budget, {len(todo)} of them not "
            f"cached: about {sum(costs):.1f} h by the runner's estimate (2 free cores, one run "
            f"at a time), the longest {max(costs, default=0.0):.1f} h")


def _run(units, budget, args):
    """`run` the units here or on the cluster the arguments name."""
    with cluster(args.scheduler, args.dask_local) as client:
        return run(units, args.jobs, not args.no_progress, client)


def _under(filename, folder):
    """Whether `filename` (of an OSError: a path, or None) lies in `folder`."""
    return isinstance(filename, (str, os.PathLike)) and \
        Path(filename).resolve().is_relative_to(Path(folder).resolve())
