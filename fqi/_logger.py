"""FQI's logs: one CSV row per iteration (`CSVLogger`), and the key-value logger that
stable-baselines3 callbacks write to (`_KeyValueLogger`, the default of `FQI.logger`)."""
from __future__ import annotations

import csv
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

__all__ = ["CSVLogger"]


class CSVLogger:
    """Append records (dicts with the same keys) to a CSV file, one row each.

    The header is written when the file is new or empty; each row is flushed at once, so
    the file is complete up to the last finished iteration even if training is interrupted.

    Parameters
    ----------
    path : str or path-like
        The CSV file, checked at once: its directory must exist (FileNotFoundError), the
        file (or its directory, for a new file) must be writable (PermissionError), and it
        must not be a directory (IsADirectoryError).
    """

    def __init__(self, path: str | os.PathLike[str]) -> None:
        if not isinstance(path, (str, os.PathLike)):
            raise TypeError(f"the log path must be a str or path-like, got {path!r}")
        self.path = Path(path)
        if self.path.is_dir():
            raise IsADirectoryError(f"the log path {self.path} is a directory, not a file")
        directory = self.path.parent
        if not directory.is_dir():
            raise FileNotFoundError(f"the directory {directory} of the log path {self.path} "
                                    f"does not exist")
        target = self.path if self.path.exists() else directory
        if not os.access(target, os.W_OK):
            raise PermissionError(f"the log path {self.path} is not writable ({target} is "
                                  f"read-only)")

    def write(self, record: Mapping[str, Any]) -> None:
        """Append one record as a row."""
        new = not self.path.exists() or self.path.stat().st_size == 0
        with self.path.open("a", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(record))
            if new:
                writer.writeheader()
            writer.writerow(record)

    def __repr__(self) -> str:
        return f"CSVLogger({str(self.path)!r})"


class _KeyValueLogger:
    """The part of ``stable_baselines3.common.logger.Logger`` that callbacks use, in memory
    and writing nowhere: `FQI.logger` until `FQI.set_logger` gives a real one.

    ``record`` sets a value, ``record_mean`` averages the values given since the last
    ``dump``, and ``dump`` clears them (as SB3's logger does after writing them).
    """

    def __init__(self):
        self.name_to_value, self.name_to_count, self.name_to_excluded = {}, {}, {}

    def record(self, key, value, exclude=None):
        """Set `key` to `value` until the next `dump`."""
        self.name_to_value[key] = value
        self.name_to_excluded[key] = exclude

    def record_mean(self, key, value, exclude=None):
        """Average `value` into `key` (None is ignored) until the next `dump`."""
        if value is None:
            return
        count = self.name_to_count.get(key, 0)
        mean = self.name_to_value.get(key, 0.0)
        self.name_to_value[key] = mean + (value - mean) / (count + 1)
        self.name_to_count[key] = count + 1
        self.name_to_excluded[key] = exclude

    def dump(self, step=0):
        """Clear the recorded values (they are written nowhere)."""
        self.name_to_value.clear()
        self.name_to_count.clear()
        self.name_to_excluded.clear()

    def get_dir(self):
        """None: this logger has no directory."""
        return None

    def close(self):
        """Nothing to close."""
