"""Reproduce every experiment of the thesis, with plots and a report, in one command.

    python benchmarks/run_all.py --quick --jobs 2 # every experiment, reduced budget, ~7 min
    python benchmarks/run_all.py                  # the thesis's budgets (many hours; resumable)
    python benchmarks/run_all.py --only representations,dqn --out docs/results
    python benchmarks/run_all.py --report-only    # rebuild figures and REPORT.md from the cache
    python benchmarks/run_all.py --dask-local 2   # the runs on a local Dask cluster of 2 workers
    python benchmarks/run_all.py --scheduler tcp://host:8786   # ... on a Dask cluster

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
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.reproduce.cli import main  # noqa: E402

if __name__ == "__main__":
    main()
