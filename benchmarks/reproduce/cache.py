"""Finished units on disk: one JSON file each, written atomically, checked on reading.

Layout: ``<out>/runs/<budget>/<experiment>/<setting>/seed<k>.json``. A file counts as
finished only if its recorded parameters and budget equal the current ones, so a changed
registry entry or budget re-runs the unit instead of mixing results; a file that is not a
run record at all (damaged, or edited by hand) counts as missing too, and says so. Beside it,
``seed<k>.json.attempts`` counts starts that never finished (the interpreter crashed or was
killed, or the cluster worker running it died), so the runner can try such units last and
eventually give up on them. A long FQI run also leaves ``seed<k>.json.partial`` while it
runs, its state after the last iteration it saved (`Checkpoint`), and resumes from it.
"""
import json
import os
import re
import sys
import time
import uuid
from dataclasses import dataclass
from pathlib import Path

import joblib

__all__ = ["unit_path", "load_unit", "save_unit", "slug", "attempts", "mark_attempt",
           "set_attempts", "Checkpoint", "ListOf"]


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


def _record_key(unit):
    """What must match for a cached result to be reused (as JSON would give it back): the
    parameters, the samples per iteration and the budget fields the unit's kind uses."""
    budget = unit.budget
    sizes = {name: getattr(budget, name) for name in unit.kind.budget_fields}
    return json.loads(json.dumps({"params": unit.params,
                                  "budget": {"name": budget.name, "samples": unit.samples,
                                             **sizes}}))


@dataclass(frozen=True)
class ListOf:
    """Shape of a JSON list: `length` items (None: any number), each of shape `item`."""

    item: object
    length: int = None


def _record_shape(unit):
    """What the report reads from a record of `unit`, as a shape for `_misfit`."""
    return {"seed": int, "result": {"seconds": float, **unit.kind.record_shape(unit.budget)}}


def _misfit(value, shape, where=""):
    """How `value` departs from `shape`, or None if it fits.

    Parameters
    ----------
    value : object
        Parsed JSON.
    shape : dict, ListOf, int or float
        A dict: a JSON object with (at least) these keys, each of its shape; `ListOf`: a
        list; `int`: a whole
        number; `float`: any number.
    where : str
        Name of `value` in the description ("": the record).

    Returns
    -------
    problem : str or None
    """
    name = where or "the record"
    if isinstance(shape, dict):
        if not isinstance(value, dict):
            return f"{name} is not a JSON object"
        for key, item in shape.items():
            inner = f"{where}.{key}" if where else key
            problem = f"no {inner}" if key not in value else _misfit(value[key], item, inner)
            if problem:
                return problem
        return None
    if isinstance(shape, ListOf):
        if not isinstance(value, list) or shape.length not in (None, len(value)):
            return f"{name} is not a list" + ("" if shape.length is None
                                               else f" of {shape.length}")
        for i, item in enumerate(value):
            problem = _misfit(item, shape.item, f"{where}[{i}]")
            if problem:
                return problem
        return None
    if isinstance(value, bool) or not isinstance(value, int if shape is int else (int, float)):
        return f"{name} is not {'a whole number' if shape is int else 'a number'}"
    return None


_IGNORED = set()  # files already reported by `_ignore` in this process


def _ignore(path, problem, what="a run record"):
    """Say (once per file) that the file at `path` is not `what` and counts as missing."""
    if path not in _IGNORED:
        _IGNORED.add(path)
        print(f"ignoring {path}: not {what} ({problem}); it counts as missing",
              file=sys.stderr)


def load_unit(unit):
    """The cached result of `unit`, or None if missing, unreadable, made with other
    parameters or another budget, or not a run record of this unit (said on stderr).

    Parameters
    ----------
    unit : reproduce.units.Unit

    Returns
    -------
    record : dict or None
        ``{"params", "budget", "experiment", "setting", "seed", "result"}``, with every
        field the report reads.
    """
    path = unit.path
    try:
        data = path.read_bytes()
    except OSError:
        return None
    try:
        record = json.loads(data)
    except (ValueError, RecursionError):  # RecursionError: nested too deep to parse
        problem = "not readable as JSON"
    else:
        problem = _misfit(record, {"params": {}, "budget": {}})
        if problem is None:
            if {"params": record["params"], "budget": record["budget"]} != _record_key(unit):
                return None  # a record of other parameters: stale, not damaged
            problem = _misfit(record, _record_shape(unit)) or (
                None if record["seed"] == unit.seed else f"it records seed {record['seed']}")
    if problem is None:
        return record
    _ignore(path, problem)
    return None


def save_unit(unit, result):
    """Write a unit's result atomically (temporary file in the same folder, then rename),
    so an interrupted run never leaves a half-written file that looks finished, with what
    `load_unit` checks; clear its attempt count and its checkpoint.

    Parameters
    ----------
    unit : reproduce.units.Unit
    result : dict
        JSON-ready output of `reproduce.units.run_unit`.
    """
    record = {"experiment": unit.experiment, "setting": unit.label, "seed": unit.seed,
              **_record_key(unit), "result": result}
    _write_atomically(unit.path, lambda f: json.dump(record, f, indent=1, allow_nan=True),
                      "w")
    _attempts_path(unit.path).unlink(missing_ok=True)
    _checkpoint_path(unit.path).unlink(missing_ok=True)


def _write_atomically(path, write, mode):
    """Call ``write(f)`` on a temporary file beside `path` (opened with `mode`), then rename
    it to `path`: readers see the old file or the whole new one, never a part. The file
    gets the permissions of any new file (the umask's), not `tempfile`'s owner-only ones."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        with open(tmp, mode.replace("w", "x")) as f:
            write(f)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _checkpoint_path(path):
    return Path(f"{path}.partial")


class Checkpoint:
    """The saved state of an unfinished unit: ``<result path>.partial``, a compressed joblib
    pickle, kept until `save_unit` writes the unit's result.

    It holds the unit's record key (parameters, samples, budget fields), its seed and the
    `code` that saved it, and serves only that unit run by that code: any other counts as
    missing, and is replaced at the next save. Loading unpickles the file: keep the cache
    trusted. Saves come at most every `interval` seconds (the first one `interval` after
    construction), so short runs spend nothing on them. A start that saved its progress
    is no crash: a save sets the unit's count of unfinished starts back to what it was when
    the checkpoint was made. A save that fails (a full disk, say) is said once on stderr,
    and the run goes on without it.

    Parameters
    ----------
    unit : reproduce.units.Unit
    code : dict
        What else the state depends on: library versions and a digest of the project's
        sources (`runner._environment`).
    """

    interval = 60.0

    def __init__(self, unit, code):
        self._result = unit.path
        self.path = _checkpoint_path(unit.path)
        self._key = {**_record_key(unit), "seed": unit.seed, "code": code}
        self._attempts = attempts(unit.path)
        self._saved = time.monotonic()
        self._failed = False

    def load(self):
        """The state last saved for this unit by this code, or None: none saved, one of
        another unit or code, or a file that cannot be read (said on stderr)."""
        try:
            with open(self.path, "rb") as f:
                saved = joblib.load(f)
        except FileNotFoundError:
            return None
        except Exception as exc:  # unpickling damaged data can raise almost anything
            _ignore(self.path, f"{type(exc).__name__}: {exc}", "a readable checkpoint")
            return None
        if not isinstance(saved, dict) or set(saved) != {"key", "state"}:
            _ignore(self.path, "another kind of pickle", "a checkpoint")
            return None
        return saved["state"] if saved["key"] == self._key else None

    def save(self, state):
        """Replace the saved state by `state` (any picklable object), atomically, if the last
        save is `interval` seconds old; returns whether it saved."""
        if time.monotonic() - self._saved < self.interval:
            return False
        saved = {"key": self._key, "state": state}
        try:
            _write_atomically(self.path, lambda f: joblib.dump(saved, f, compress=3), "wb")
        except Exception as exc:  # the checkpoint is a convenience: the run goes on
            if not self._failed:
                self._failed = True
                print(f"could not save the checkpoint {self.path} "
                      f"({type(exc).__name__}: {exc}); the run goes on without",
                      file=sys.stderr)
            return False
        self._saved = time.monotonic()
        set_attempts(self._result, self._attempts)
        return True


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


def set_attempts(path, count):
    """Set the unit's count of unfinished starts to `count`: back to the count before an
    interrupted start (an interrupt is no crash), or up by the workers of a cluster that
    died running the unit."""
    if count:
        _attempts_path(path).write_text(str(count))
    else:
        _attempts_path(path).unlink(missing_ok=True)
