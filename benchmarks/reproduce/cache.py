"""Finished units on disk: one JSON file each, written atomically, checked on reading.

Layout: ``<out>/runs/<budget>/<experiment>/<setting>/seed<k>.json``. A file counts as
finished only if its recorded parameters and budget equal the current ones, so a changed
registry entry or budget re-runs the unit instead of mixing results. Beside it,
``seed<k>.json.attempts`` counts starts that never finished (the interpreter crashed or was
killed), so the runner can try such units last and eventually give up on them.
"""
import json
import os
import re
import tempfile
from pathlib import Path

__all__ = ["unit_path", "load_unit", "save_unit", "slug", "attempts", "mark_attempt"]


def slug(label):
    """A file-name-safe form of a setting label (``"fixed TW=1"`` -> ``"fixed_TW-1"``)."""
    return re.sub(r"[^A-Za-z0-9.+-]+", "_", label.replace("=", "-")).strip("_")


def unit_path(out, budget, experiment, label, seed):
    """Where the unit's result lives.

    Parameters
    ----------
    out : path-like
    budget : reproduce.budgets.Budget
    experiment : str
        Name of the experiment owning the runs.
    label : str
    seed : int

    Returns
    -------
    path : pathlib.Path
    """
    return Path(out) / "runs" / budget.name / experiment / slug(label) / f"seed{seed}.json"


# The budget fields each unit kind depends on (the number of seeds is not one of them).
_BUDGET_FIELDS = {
    "fqi": ("iterations", "eval_steps", "max_trees", "max_tests"),
    "rmse": ("rmse_samples", "rmse_folds", "max_trees", "max_tests"),
    "dqn": ("iterations", "eval_steps", "dqn_steps"),
    "attention": ("attention_iterations", "eval_steps", "max_trees", "max_tests"),
}


def _record_key(params, budget, samples):
    """What must match for a cached result to be reused (as JSON would give it back): the
    parameters, the samples per iteration and the budget fields the unit's kind uses."""
    sizes = {name: getattr(budget, name) for name in _BUDGET_FIELDS[params["kind"]]}
    return json.loads(json.dumps({"params": params,
                                  "budget": {"name": budget.name, "samples": samples,
                                             **sizes}}))


def load_unit(path, params, budget, samples):
    """The cached result at `path`, or None if missing, unreadable or made with other
    parameters or another budget.

    Parameters
    ----------
    path : path-like
    params : dict
        The setting's current parameters.
    budget : Budget
    samples : int
        Samples per FQI iteration of this unit.

    Returns
    -------
    record : dict or None
        ``{"params", "budget", "experiment", "setting", "seed", "result"}``.
    """
    try:
        record = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None
    if {"params": record.get("params"), "budget": record.get("budget")} \
            != _record_key(params, budget, samples):
        return None
    return record


def save_unit(path, params, budget, samples, experiment, label, seed, result):
    """Write a unit's result atomically (temporary file in the same folder, then rename),
    so an interrupted run never leaves a half-written file that looks finished; clear its
    attempt count.

    Parameters
    ----------
    path : path-like
    params, budget, samples
        As for `load_unit`: recorded so that later loads can check them.
    experiment, label : str
    seed : int
    result : dict
        JSON-ready output of `reproduce.units.run_unit`.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    record = {"experiment": experiment, "setting": label, "seed": seed,
              **_record_key(params, budget, samples), "result": result}
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(record, f, indent=1, allow_nan=True)
        os.replace(tmp, path)
        _attempts_path(path).unlink(missing_ok=True)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _attempts_path(path):
    return Path(f"{path}.attempts")


def attempts(path):
    """How many times the unit at `path` was started without finishing."""
    try:
        return int(_attempts_path(path).read_text())
    except (OSError, ValueError):
        return 0


def mark_attempt(path):
    """Record that the unit at `path` starts (`save_unit` clears the record)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _attempts_path(path).write_text(str(attempts(path) + 1))
