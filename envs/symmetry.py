"""The game's symmetry under quarter turns: positions and observations seen in the frame of a
move, where the move points up."""
import numpy as np

from ._rules import _DIRECTIONS, ACTION_NAMES
from .batched import RaggedBatch

__all__ = ["move_frame", "in_move_frame"]

# The turn that takes move k's unit direction (dx, dy) to up's, (0, 1): the rotation whose
# cosine is dy and sine dx
_TURN_SIN, _TURN_COS = _DIRECTIONS.T.astype(np.float32)


def move_frame(positions, actions):
    """Agent-relative positions seen in the frame of a move: turned by quarter turns so that
    the move points up.

    The game is symmetric under quarter turns of the world (a square with the agent at its
    centre, objects spawned uniformly, isotropic noise and contacts): turning a state and
    its move together gives a state-move pair that plays out alike. So ``Q(s, a)`` is ``Q(s',
    up)`` for ``s'`` the state seen in the frame of move ``a``, and one model of moving up,
    learned from the transitions of all four moves, gives every move's value (`in_move_frame`
    turns whole observations so, for FQI's ``action_input``). A swipe ``a + 4`` is turned as
    move ``a``: it points the same way.

    Parameters
    ----------
    positions : array-like of shape (n, 2)
        Agent-relative ``[dx, dy]`` of objects (the first two columns of observation rows).
    actions : array-like of int of shape (n,)
        The action of each position's observation, in ``range(8)``.

    Returns
    -------
    turned : ndarray of shape (n, 2), float32
        Exact: a quarter turn only swaps and negates coordinates.

    Raises
    ------
    ValueError
        If the shapes do not match or an action is outside ``range(8)``.

    Examples
    --------
    >>> import numpy as np
    >>> from envs import move_frame
    >>> directions = [[0, 1], [1, 0], [0, -1], [-1, 0]]   # up, right, down, left
    >>> move_frame(directions, [0, 1, 2, 3]).tolist()
    [[0.0, 1.0], [0.0, 1.0], [0.0, 1.0], [0.0, 1.0]]
    """
    positions = np.asarray(positions, dtype=np.float32)
    actions = np.asarray(actions)
    if positions.ndim != 2 or positions.shape[1] != 2 or actions.shape != positions.shape[:1]:
        raise ValueError(f"positions must be (n, 2) and actions (n,); got {positions.shape} "
                         f"and {actions.shape}")
    if not np.issubdtype(actions.dtype, np.integer) and actions.size:
        raise ValueError(f"actions must be integers, got dtype {actions.dtype}")
    if actions.size and (actions.min() < 0 or actions.max() >= len(ACTION_NAMES)):
        raise ValueError(f"actions must lie in range({len(ACTION_NAMES)})")
    k = actions.astype(np.intp) % 4
    c, s = _TURN_COS[k], _TURN_SIN[k]
    x, y = positions[:, 0], positions[:, 1]
    return np.stack([c * x - s * y, s * x + c * y], axis=1)


def in_move_frame(observations, actions):
    """A batch of observations, each turned into the frame of its action (`move_frame`).

    This is the encoding that gives FQI one model of moving up for the four moves:
    ``FQI(regressor, "ObjectWorld-v0", action_input=envs.in_move_frame)`` fits one
    regressor on every transition, each observation turned so that its move points up,
    and values move ``a`` in state ``s`` as that regressor's value of ``s`` turned into
    ``a``'s frame. The regressor then learns from four times the transitions it would
    learn from as one of four per-move regressors.

    Parameters
    ----------
    observations : RaggedBatch or boxtrees.ObjectSets
        Anything with ``data``, rows ``[dx, dy, type]``, and ``offsets``, one set per
        observation.
    actions : array-like of int of shape (n_observations,)
        The action of each observation, in ``range(8)``.

    Returns
    -------
    turned : RaggedBatch
        The same sets, their positions turned.

    Raises
    ------
    ValueError
        If there is not one action per observation, or `move_frame` refuses them.

    Examples
    --------
    >>> import numpy as np
    >>> from envs import RaggedBatch, in_move_frame
    >>> obs = RaggedBatch(np.float32([[1, 2, 0], [3, -4, 3], [-1, 0, 1]]), [0, 2, 3])
    >>> in_move_frame(obs, [1, 3]).data.tolist()    # right, then left, turned up
    [[-2.0, 1.0, 0.0], [4.0, 3.0, 3.0], [0.0, 1.0, 1.0]]
    """
    offsets = np.asarray(observations.offsets)
    actions = np.asarray(actions)
    if actions.shape != (len(offsets) - 1,):
        raise ValueError(f"actions must hold one action per observation: {len(offsets) - 1} "
                         f"observations, actions of shape {actions.shape}")
    turned = np.array(observations.data, dtype=np.float32)
    turned[:, :2] = move_frame(turned[:, :2], np.repeat(actions, np.diff(offsets)))
    return RaggedBatch(turned, offsets)
