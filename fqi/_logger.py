"""One CSV row per FQI iteration."""
import csv
import os
from pathlib import Path

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

    def __init__(self, path):
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

    def write(self, record):
        """Append one record as a row."""
        new = not self.path.exists() or self.path.stat().st_size == 0
        with self.path.open("a", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(record))
            if new:
                writer.writeheader()
            writer.writerow(record)

    def __repr__(self):
        return f"CSVLogger({str(self.path)!r})"
