"""Long-lived thread pools, one per purpose and size, started on first use and forgotten in
a forked child (whose parent's threads are gone); tasks run side by side in the calling
thread and a pool's, each under the calling thread's scikit-learn configuration; and the
share of the cores a call made from one of those threads may use."""
import os
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor, wait
from functools import lru_cache, partial
from typing import Any, TypeVar

from joblib import effective_n_jobs
from joblib.parallel import get_active_backend
from sklearn import config_context, get_config

__all__ = ["configured", "side_by_side", "thread_pool", "threads_for"]

T = TypeVar("T")

# (purpose, threads) -> the pool of this process
_POOLS: dict[tuple[str, int], ThreadPoolExecutor] = {}
_POOLS_LOCK = threading.Lock()
# in a thread running tasks side by side: `siblings`, the number of threads that run them
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
    _LOCAL.siblings = n_threads + 1     # (the pool's threads work beside the calling one)


def thread_pool(n_threads: int, purpose: str) -> ThreadPoolExecutor:
    """The process's pool of `n_threads` threads for `purpose`, started on first use.

    Predictions are called once per environment step on batches of a few hundred samples,
    where starting threads (as a joblib ``Parallel`` call does) costs about as much as the
    work; the kernels release the GIL, so long-lived threads share a batch at no such cost.
    Pools of different purposes are distinct, so that work in one pool may wait on work in
    another (an agent's per-action predictions on a forest's own) without deadlock, but
    never on work in its own. A pool's threads work beside the calling thread
    (`side_by_side`): work run in one of them takes a share of the cores, one of ``n_threads
    + 1`` (`threads_for`).

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


def side_by_side(tasks: Sequence[Callable[[], T]], purpose: str,
                 n_threads: int | None = None) -> list[T]:
    """The results of the callables `tasks`, run side by side on `n_threads` threads: the
    first task in the calling thread (which would otherwise only wait), each other one in a
    thread of the pool of `purpose` of ``n_threads - 1`` threads (`thread_pool`); each runs
    as one of `n_threads` siblings (`threads_for`), under the calling thread's scikit-learn
    configuration (``sklearn.get_config()``, which belongs to a thread).

    Returns only when every task has finished, even when one failed (the first failure is
    then raised): no task outlives the call, so none writes into what the caller frees.

    Parameters
    ----------
    tasks : sequence of callables
        Each called with no argument.
    purpose : str
        The pool's (see `thread_pool`).
    n_threads : int, default=len(tasks)
        At least ``len(tasks)``: one pool serves calls of fewer tasks too.

    Returns
    -------
    results : list
        Their results, in the order of `tasks`.

    Examples
    --------
    >>> from boxtrees._threads import side_by_side, threads_for
    >>> side_by_side([lambda: threads_for(-1), lambda: 2 + 2], "example")[1]
    4
    """
    n_threads = len(tasks) if n_threads is None else n_threads
    if n_threads < len(tasks):
        raise ValueError(f"{len(tasks)} tasks side by side need as many threads, not {n_threads}")
    if n_threads == 1:
        return [tasks[0]()]
    pool, others = thread_pool(n_threads - 1, purpose), []
    outside = getattr(_LOCAL, "siblings", None)
    config = get_config()
    try:
        for task in tasks[1:]:      # one by one: a failed submit still waits for the others
            others.append(pool.submit(partial(configured, config, task)))
        _LOCAL.siblings = n_threads
        first = tasks[0]()
    finally:
        if outside is None:
            vars(_LOCAL).pop("siblings", None)
        else:
            _LOCAL.siblings = outside
        wait(others)
    return [first] + [future.result() for future in others]


def configured(config: dict[str, Any], function: Callable[..., T], *args: Any,
               **kwargs: Any) -> T:
    """``function(*args, **kwargs)`` under the scikit-learn configuration `config` (a
    ``sklearn.get_config()`` of another thread: the configuration belongs to a thread)."""
    with config_context(**config):
        return function(*args, **kwargs)


def threads_for(n_jobs: int | None) -> int:
    """The threads a call with `n_jobs` may use: joblib's ``effective_n_jobs(n_jobs)``,
    divided among the threads running tasks side by side with the calling one, if any (at
    least 1).

    Those threads already keep that many cores busy: a forest predicting in each of the 2
    threads of an agent's per-action tasks, on 2 cores, predicts its whole batch in its
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
    >>> thread_pool(3, "example").submit(threads_for, 8).result()
    2
    """
    if n_jobs == 1:
        return 1
    backend, backend_n_jobs = get_active_backend()
    return max(_effective_n_jobs(n_jobs, backend.__class__, backend_n_jobs)
               // getattr(_LOCAL, "siblings", 1), 1)


@lru_cache(maxsize=64)
def _effective_n_jobs(n_jobs, backend_type, backend_n_jobs):
    """joblib's ``effective_n_jobs(n_jobs)`` under an active backend of that type and
    default: the same whenever they are (it counts the cores from the control groups'
    files, as much time as predicting a sample)."""
    return effective_n_jobs(n_jobs)
