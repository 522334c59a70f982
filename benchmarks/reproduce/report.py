from pathlib import Path
def write_outputs(experiments, budget, out, seeds, elapsed, n_run):
    return Path(out) / "REPORT.md"
