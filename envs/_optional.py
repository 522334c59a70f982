"""The error raised when an optional package of an env is not installed."""

__all__ = []


def missing_extra(what, packages, extra, exc):
    """An ImportError saying that `what` needs `packages`, installed by the extra `extra`.

    Parameters
    ----------
    what : str
        The class or function that needs them (``"envs.AtariObjects"``).
    packages : str
        What is missing, for the reader (``"OCAtari and ALE (ocatari, ale-py)"``).
    extra : str
        The extra of ``boxtrees`` that installs them.
    exc : ImportError
        The failed import, whose message is quoted.

    Returns
    -------
    error : ImportError

    Examples
    --------
    >>> error = missing_extra("envs.HighwayObjects", "highway-env", "highway",
    ...                       ImportError("No module named 'highway_env'"))
    >>> str(error).endswith("pip install 'boxtrees[highway]'")
    True
    """
    return ImportError(f"{what} needs {packages}, which is not installed ({exc}): "
                       f"pip install 'boxtrees[{extra}]'")
