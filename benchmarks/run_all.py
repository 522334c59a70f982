"""Reproduce every experiment of the thesis, with plots and a report, in one command.

    python -m benchmarks.run_all --quick --jobs 2 # every experiment, reduced budget, ~7 min
    python benchmarks/run_all.py --quick --jobs 2 # the same, run as a script
    python -m benchmarks.run_all                  # the thesis's budgets (many hours; resumable)
    python -m benchmarks.run_all --only representations,dqn --out docs/results
    python -m benchmarks.run_all --report-only    # rebuild figures and REPORT.md from the cache
    python -m benchmarks.run_all --dask-local 2   # the runs on a local Dask cluster of 2 workers
    python -m benchmarks.run_all --scheduler tcp://host:8786   # ... on a Dask cluster

Writes under ``--out`` (default ``results/``): one PNG per figure, ``runs/`` (one JSON per
finished run, reused by later invocations), one CSV of raw numbers per experiment,
``summary.json`` and ``REPORT.md``. The experiments are the registry in
``benchmarks/reproduce/registry.py``. On a Dask cluster this machine still writes every
result (the workers need the project installed, but no shared file system); see
``docs/reproduction.md``. Exit status: 2 for an invalid argument, 1 if ``--out`` cannot be
written, the cluster cannot run the units, or a run was skipped after crashing 3 times (the
report counts it as missing), 130 on Ctrl-C (an interrupt is no crash; finished runs stay
cached).
"""
if __package__:  # python -m benchmarks.run_all, or imported
    from .reproduce.cli import main
else:  # python benchmarks/run_all.py: the same main, imported from the package
    import sys
    from pathlib import Path

    _ROOT = Path(__file__).resolve().parents[1]
    if sys.path and Path(sys.path[0] or ".").resolve() == _ROOT / "benchmarks":
        sys.path[0] = str(_ROOT)  # the script's folder would shadow top-level names
    else:
        sys.path.insert(0, str(_ROOT))
    from benchmarks.run_all import main

if __name__ == "__main__":
    main()
