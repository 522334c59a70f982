import os

import pytest

# Let scikit-learn's array-API estimator checks run instead of skipping (must precede scipy).
os.environ.setdefault("SCIPY_ARRAY_API", "1")


def run_in_fork(check, timeout=60):
    """Call ``check()`` in a forked child; whether it returned True there. A child that
    hangs (say, on threads it did not inherit) is killed and fails the calling test."""
    import signal
    import time

    time.sleep(0.2)  # let the parent's worker threads go idle, as they are between calls
    reader, writer = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(reader)
        ok = False
        try:
            ok = bool(check())
        finally:  # never back into the parent's pytest, whatever happened
            os.write(writer, b"1" if ok else b"0")
            os._exit(0)
    os.close(writer)
    deadline = time.monotonic() + timeout
    while os.waitpid(pid, os.WNOHANG) == (0, 0):
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            pytest.fail("the forked child hung")
        time.sleep(0.05)
    answer = os.read(reader, 1)
    os.close(reader)
    return answer == b"1"


def reference_leaf(tree, objects):
    """Walk one tree in plain NumPy, reading only its exported node arrays: an object
    (``[f_1, ..., f_d, type]``) is inside a box when every attribute lies strictly between
    its bounds."""
    import numpy as np

    objects = np.asarray(objects, dtype=np.float32).reshape(-1, tree.box.shape[1] // 2 + 1)
    d = objects.shape[1] - 1
    node = 0
    while tree.children_left[node] != -1:
        box = tree.box[node].reshape(d, 2)
        mine = objects[objects[:, d] == tree.object_type[node], :d]
        inside = ((mine > box[:, 0]) & (mine < box[:, 1])).all(axis=1)
        go_left = inside.sum() < tree.threshold[node]
        node = tree.children_left[node] if go_left else tree.children_right[node]
    return node


# The engine as the thesis ran it (fqi.make_box_forest): fixed boxes of half-width 1 in the
# data's units, neither refined nor grown on bootstrap samples. The engine's own tests pin it;
# the estimators' defaults are measured elsewhere (tests/test_boxtrees_defaults.py).
THESIS_TREE = dict(test_type="fixed", test_width=1.0, relative_width=False, refine_tests=False)
THESIS_FOREST = dict(THESIS_TREE, bootstrap=False)


@pytest.fixture
def random_transitions():
    """A factory of random FQI transitions: ``(n, n_features, n_actions, seed)``, normal
    states, next states and rewards, uniform actions, 20 % of them terminal."""
    import numpy as np

    from fqi._collect import _Transitions

    def make(n, n_features, n_actions, seed=0):
        rng = np.random.default_rng(seed)
        return _Transitions(rng.normal(size=(n, n_features)), rng.integers(n_actions, size=n),
                            rng.normal(size=n), rng.normal(size=(n, n_features)),
                            rng.random(n) < 0.2)

    return make


@pytest.fixture
def cartpole_fqi():
    """A factory of small FQI agents on CartPole-v1 (rounds of 500 steps from 4 envs, 5
    backups a round, 3 leaf backups, 5 Extra-Trees, no evaluation, seed 0); its keyword
    arguments are more FQI parameters."""
    from sklearn.ensemble import ExtraTreesRegressor

    from fqi import FQI

    def make(**params):
        settings = dict(samples_per_iteration=500, resample_every=5, leaf_backups=3,
                        n_envs=4, eval_episodes=0, seed=0)
        return FQI(ExtraTreesRegressor(n_estimators=5, min_samples_leaf=2), "CartPole-v1",
                   **{**settings, **params})

    return make


@pytest.fixture(scope="session")
def tiny_run(tmp_path_factory):
    """Every default experiment of the reproduction run at the tiny budget, once for all the
    tests (tests/benchmarks/): its output folder and report. Under pytest-xdist the first
    worker to ask runs it into the workers' common folder, and each worker gets its own copy
    (some tests delete and rerun runs of it)."""
    from benchmarks.reproduce.cli import main

    out = tmp_path_factory.mktemp("run_all")
    if "PYTEST_XDIST_WORKER" not in os.environ:
        return out, main(["--budget", "tiny", "--out", str(out), "--no-progress"])
    import shutil

    from filelock import FileLock

    shared = tmp_path_factory.getbasetemp().parent / "run_all"
    with FileLock(f"{shared}.lock"):
        if not (shared / "REPORT.md").is_file():  # written last, so the run is whole
            shutil.rmtree(shared, ignore_errors=True)
            main(["--budget", "tiny", "--out", str(shared), "--no-progress"])
    shutil.copytree(shared, out, dirs_exist_ok=True)
    return out, out / "REPORT.md"
