import pytest
from benchmarks.reproduce.cli import main


@pytest.fixture(scope="session")
def tiny_run(tmp_path_factory):
    """Every default experiment run at the tiny budget, once for all the tests: its output
    folder and report."""
    out = tmp_path_factory.mktemp("run_all")
    report = main(["--budget", "tiny", "--out", str(out), "--no-progress"])
    return out, report
