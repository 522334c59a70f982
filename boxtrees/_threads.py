"""Long-lived thread pools, one per purpose and size, started on first use and forgotten in
a forked child (whose parent's threads are gone)."""
import os
import threading
from concurrent.futures import ThreadPoolExecutor

__all__ = ["thread_pool"]

# (purpose, threads) -> the pool of this process
_POOLS: dict[tuple[str, int], ThreadPoolExecutor] = {}
_POOLS_LOCK = threading.Lock()


def _forget_pools_after_fork():
    """In a forked child: the parent's threads are gone, and the lock may have been held."""
    global _POOLS_LOCK
    _POOLS.clear()
    _POOLS_LOCK = threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pools_after_fork)


def thread_pool(n_threads: int, purpose: str = "boxtrees-predict") -> ThreadPoolExecutor:
    """The process's pool of `n_threads` threads for `purpose`, started on first use.

    Predictions are called once per environment step on batches of a few hundred samples,
    where starting threads (as a joblib ``Parallel`` call does) costs about as much as the
    work; the kernels release the GIL, so long-lived threads share a batch at no such cost.
    Pools of different purposes are distinct, so that work in one pool may wait on work in
    another (an agent's per-action predictions on a forest's own) without deadlock.

    Parameters
    ----------
    n_threads : int
    purpose : str, default="boxtrees-predict"
        Names the pool and its threads.

    Returns
    -------
    pool : concurrent.futures.ThreadPoolExecutor
    """
    key = (purpose, n_threads)
    with _POOLS_LOCK:
        if key not in _POOLS:
            _POOLS[key] = ThreadPoolExecutor(n_threads, thread_name_prefix=purpose)
        return _POOLS[key]
