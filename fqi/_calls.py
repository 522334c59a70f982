"""How FQI calls its regressors: in the calling thread for the small batches of each
environment step, on kept threads for the large ones, so that no call starts threads.

A scikit-learn forest with ``n_jobs`` runs each ``fit`` and ``predict`` on a joblib
``Parallel`` whose threading backend starts a pool of threads and ends it when the call
returns: 5 to 15 ms a call, more than predicting a few observations costs. An agent predicts
once per environment step, so the pools would be started by the tens of thousands. And
scikit-learn's ``delayed`` tasks swap the process's warning filters for a copy of the
caller's around each task (``warnings.catch_warnings``), which two threads doing at once
can leave emptied (Python before 3.14 keeps one list for all threads): from then on every
task warns that ``delayed`` lacks its ``Parallel``, and no filter of the user's stops it.
Here a batch of fewer than `_SMALL_BATCH` observations is run in the calling thread
(joblib's sequential backend), and a larger one, or a fit, on a pool of threads kept for
the process (`_KeptThreadingBackend`), whose threads run scikit-learn's tasks under the
caller's scikit-learn configuration without the swap: threads share the process's filters
already.

Only joblib's default backends (loky, and threads) are replaced: a backend the user chose
(``joblib.parallel_config(backend="dask")``, say) is left as it is.
"""
import os
import threading
from contextlib import nullcontext
from functools import partial
from multiprocessing.pool import ThreadPool

from joblib import parallel_config, register_parallel_backend
from joblib._parallel_backends import LokyBackend, ThreadingBackend
from joblib.parallel import get_active_backend

from boxtrees._threads import configured

__all__ = []

# Below this many observations a call is cheaper than handing work to threads (a box
# forest does not split such a batch either: boxtrees._base._PREDICT_CHUNK_MIN x 2).
_SMALL_BATCH = 128
_KEPT = "fqi-kept-threads"

# n_jobs -> the process's kept pool
_POOLS: dict[int, ThreadPool] = {}
_POOLS_LOCK = threading.Lock()


def _forget_pools_after_fork():
    """In a forked child the parent's threads are gone (and the lock may have been held)."""
    global _POOLS_LOCK
    _POOLS.clear()
    _POOLS_LOCK = threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pools_after_fork)


class _KeptThreadingBackend(ThreadingBackend):
    """joblib's threading backend on a pool of threads kept for the process (one per
    number of threads), which a call's end leaves running for the next call; scikit-learn's
    tasks run without their swap of the warning filters (`_unswapped`)."""

    def submit(self, func, callback=None):
        items = getattr(func, "items", None)  # a joblib batch: (function, args, kwargs)
        if isinstance(items, list):
            func.items = [(_unswapped(task), args, kwargs) for task, args, kwargs in items]
        return super().submit(func, callback)

    def _get_pool(self):
        if self._pool is None:
            with _POOLS_LOCK:
                if self._n_jobs not in _POOLS:
                    _POOLS[self._n_jobs] = ThreadPool(self._n_jobs)
                self._pool = _POOLS[self._n_jobs]
        return self._pool

    def terminate(self):
        self._pool = None   # (kept for the next call)


register_parallel_backend(_KEPT, _KeptThreadingBackend)


def _unswapped(task):
    """A task of scikit-learn's ``delayed`` (its function and the caller's configuration,
    given by its ``Parallel``) as a call of its function under that configuration alone;
    any other task as it is."""
    function, config = getattr(task, "function", None), getattr(task, "config", None)
    if function is None or not isinstance(config, dict) or not config:
        return task
    return partial(configured, config, function)


def _regressor_calls(n_predicted=None):
    """The context in which FQI calls a regressor: a prediction of `n_predicted`
    observations, or a fit (None). joblib's sequential backend for a prediction of fewer
    than `_SMALL_BATCH`, else the kept threads; nothing changed when the active backend is
    not one of joblib's defaults.

    joblib's configuration belongs to a thread: enter it in the thread making the call.
    """
    backend, _ = get_active_backend()
    if type(backend) not in (LokyBackend, ThreadingBackend, _KeptThreadingBackend):
        return nullcontext()
    small = n_predicted is not None and n_predicted < _SMALL_BATCH
    return parallel_config(backend="sequential" if small else _KEPT)

