"""One CSV row per FQI iteration."""
import csv
from pathlib import Path

__all__ = ["CSVLogger"]


class CSVLogger:
    """Append records (dicts with the same keys) to a CSV file, one row each.

    The header is written when the file is new or empty; each row is flushed at once, so
    the file is complete up to the last finished iteration even if training is interrupted.

    Parameters
    ----------
    path : str or path-like
    """

    def __init__(self, path):
        self.path = Path(path)

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
