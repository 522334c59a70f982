"""The file `FQI.save` writes: a joblib pickle of the agent's attributes."""
import os
import pickle

import joblib

__all__ = []

_SAVE_FORMAT = 8  # 3: exploration schedule, not epsilon; 4: tie_break; 5: leaf_backups;
#                   6: double; 7: action_input; 8: support_threshold, support_classifier


def _write_save(state, path):
    """Write the attribute dict `state` to `path`."""
    joblib.dump({"format": _SAVE_FORMAT, "state": state}, path)


def _read_save(path, required):
    """The attribute dict that `_write_save` wrote to `path`, or a ValueError saying why the
    file is not one (FileNotFoundError when it does not exist).

    Parameters
    ----------
    path : str or path-like
    required : iterable of str
        Attributes the dict must hold.
    """
    path = os.fspath(path)
    with open(path, "rb") as f:
        head = f.read(1)
    if not head:
        raise ValueError(f"{path} is empty, not an agent saved by FQI.save")
    if head != pickle.PROTO:  # joblib.dump writes an uncompressed pickle
        raise ValueError(f"{path} is not an agent saved by FQI.save (not a joblib pickle)")
    try:
        saved = joblib.load(path)
    except Exception as exc:  # unpickling damaged data can raise almost anything
        raise ValueError(f"{path} could not be read as an agent saved by FQI.save: it is "
                         f"truncated or damaged ({type(exc).__name__}: {exc})") from exc
    if not isinstance(saved, dict) or "format" not in saved:
        raise ValueError(f"{path} is a joblib pickle of a {type(saved).__name__}, not an "
                         f"agent saved by FQI.save")
    if saved["format"] != _SAVE_FORMAT:
        raise ValueError(f"{path} is an FQI save of format version {saved['format']!r}; "
                         f"this version of fqi reads version {_SAVE_FORMAT}")
    state = saved.get("state")
    missing = sorted(set(required) - set(state)) if isinstance(state, dict) else ["state"]
    if missing:
        raise ValueError(f"{path} is not an agent saved by FQI.save: it lacks "
                         f"{', '.join(missing)}")
    return state
