"""Long-lived thread pools, one per purpose and size, started on first use and forgotten in
a forked child (whose parent's threads are gone), and the share of the cores a call made
from one of their threads may use."""
import os
import threading
from concurrent.futures import ThreadPoolExecutor

from joblib import effective_n_jobs

__all__ = ["thread_pool", "threads_for"]

# (purpose, threads) -> the pool of this process
_POOLS: dict[tuple[str, int], ThreadPoolExecutor] = {}
_POOLS_LOCK = threading.Lock()
# in a pool's thread: `siblings`, the number of threads of that pool
_LOCAL = threading.local()


def _forget_pools_after_fork():
    """In a forked child: the parent's threads are gone, and the lock may have been held;
    the child's one thread (the forking one, maybe a pool's) belongs to no pool."""
    global _POOLS_LOCK
    _POOLS.clear()
    _POOLS_LOCK = threading.Lock()
    vars(_LOCAL).pop("siblings", None)


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pools_after_fork)


def _join_pool(n_threads):
    _LOCAL.siblings = n_threads


def thread_pool(n_threads: int, purpose: str) -> ThreadPoolExecutor:
    """The process's pool of `n_threads` threads for `purpose`, started on first use.

    Predictions are called once per environment step on batches of a few hundred samples,
    where starting threads (as a joblib ``Parallel`` call does) costs about as much as the
    work; the kernels release the GIL, so long-lived threads share a batch at no such cost.
    Pools of different purposes are distinct, so that work in one pool may wait on work in
    another (an agent's per-action predictions on a forest's own) without deadlock, but
    never on work in its own; work run in a pool's thread takes its share of the cores
    (`threads_for`).

    Parameters
    ----------
    n_threads : int
    purpose : str
        Names the pool and its threads ("boxtrees-predict" for a forest's predictions).

    Returns
    -------
    pool : concurrent.futures.ThreadPoolExecutor
    """
    key = (purpose, n_threads)
    with _POOLS_LOCK:
        if key not in _POOLS:
            _POOLS[key] = ThreadPoolExecutor(n_threads, thread_name_prefix=purpose,
                                             initializer=_join_pool, initargs=(n_threads,))
        return _POOLS[key]


def threads_for(n_jobs: int | None) -> int:
    """The threads a call with `n_jobs` may use: joblib's ``effective_n_jobs(n_jobs)``,
    divided among the threads of the pool the calling thread belongs to, if any (at least 1).

    A pool's threads already keep that many cores busy: a forest predicting in each of the 2
    threads of an agent's per-action pool, on 2 cores, predicts its whole batch in its
    caller's thread instead of splitting it with a thread of its own (4 busy threads on 2
    cores only add switching).

    Parameters
    ----------
    n_jobs : int or None
        As in joblib (-1: every core).

    Returns
    -------
    n_threads : int
        At least 1.

    Examples
    --------
    >>> from boxtrees._threads import thread_pool, threads_for
    >>> threads_for(1)
    1
    >>> thread_pool(4, "example").submit(threads_for, 8).result()
    2
    """
    return max(effective_n_jobs(n_jobs) // getattr(_LOCAL, "siblings", 1), 1)
