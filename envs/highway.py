"""highway-env's driving tasks as sets of typed objects around the ego vehicle.

Needs the optional extra ``highway`` (``pip install 'boxtrees[highway]'``). Importing `envs`
does not import highway-env; this module does, on first use.
"""
import functools

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from ._optional import missing_extra

__all__ = ["HighwayObjects"]

TYPE_NAMES = ("ego", "vehicle", "obstacle", "landmark")


@functools.cache
def _highway():
    """highway-env's abstract env, vehicle and landmark classes, imported on first use
    (which registers its ids)."""
    try:
        import highway_env  # noqa: F401 (registers the ids)
        from highway_env.envs.common.abstract import AbstractEnv
        from highway_env.vehicle.kinematics import Vehicle
        from highway_env.vehicle.objects import Landmark
    except ImportError as exc:
        raise missing_extra("envs.HighwayObjects", "highway-env", "highway", exc) from exc
    return AbstractEnv, Vehicle, Landmark


class HighwayObjects(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    """Observe a highway-env env as the set of road objects around the ego vehicle.

    Whatever the env's own observation, this wrapper returns one row per object within
    `max_distance` of the ego vehicle (the first one the agent controls), the ego vehicle
    first, ``[x, y, vx, vy, cos_h, sin_h, type]`` (``d = 6`` attributes, then the type id):

    - ``x, y``: the position in metres relative to the ego vehicle's (the road's axes; 0, 0
      for the ego vehicle);
    - ``vx, vy``: the velocity in m/s relative to the ego vehicle's; the ego vehicle's own
      velocity in its row;
    - ``cos_h, sin_h``: the heading;
    - ``type``: 0 the ego vehicle, 1 another vehicle, 2 an obstacle, 3 a landmark (a
      parking goal), as `type_names` says.

    Objects farther away are dropped, so the set's size varies. Values are clipped to the
    observation space's bounds: positions to ``max_distance``, velocities to twice
    highway-env's top speed (80 m/s).

    Parameters
    ----------
    env : gymnasium.Env
        An env of highway-env (``gymnasium.make("highway-fast-v0")``, any of its ids, any
        configuration), wrappers allowed.
    max_distance : float, default=None
        Objects within this many metres are observed (default: the env's perception
        distance, 200 m).

    Raises
    ------
    ImportError
        If highway-env is not installed (the extra ``highway``).
    TypeError
        If `env` is not a highway-env env.
    ValueError
        If `max_distance` is not a positive number.

    Attributes
    ----------
    attribute_names : tuple of str
        ``("x", "y", "vx", "vy", "cos_h", "sin_h")``, the names of the columns before the
        type.
    type_names : tuple of str
        ``("ego", "vehicle", "obstacle", "landmark")``.
    n_types : int

    Notes
    -----
    The wrapper records `max_distance` in the env's spec, so ``gymnasium.make(env.spec)`` and
    ``gymnasium.make_vec(env.spec, n, vectorization_mode="sync")`` rebuild it (`fqi.FQI`
    does), and ``gymnasium.make_vec(id, n, wrappers=[HighwayObjects])`` builds a vector of
    them. highway-env simulates slowly (tens of steps per second): prefer an
    ``"async"`` vector env to use several cores.

    Examples
    --------
    >>> import gymnasium as gym
    >>> import envs
    >>> env = envs.HighwayObjects(gym.make("highway_env:highway-fast-v0"))
    >>> obs, info = env.reset(seed=0)
    >>> obs.shape[1], obs[0, :2], obs[0, -1]        # the ego vehicle first, at the origin
    (7, array([0., 0.], dtype=float32), np.float32(0.0))
    """

    attribute_names = ("x", "y", "vx", "vy", "cos_h", "sin_h")
    type_names = TYPE_NAMES

    def __init__(self, env, max_distance=None):
        abstract_env, vehicle, _ = _highway()
        if not isinstance(env.unwrapped, abstract_env):
            raise TypeError(f"HighwayObjects needs an env of highway-env, got {env.unwrapped}")
        gym.utils.RecordConstructorArgs.__init__(self, max_distance=max_distance)
        gym.ObservationWrapper.__init__(self, env)
        distance = env.unwrapped.PERCEPTION_DISTANCE if max_distance is None else max_distance
        if (not isinstance(distance, (int, float, np.integer, np.floating))
                or isinstance(distance, bool) or not 0 < distance < np.inf):
            raise ValueError(f"max_distance must be a positive number, got {max_distance!r}")
        self.max_distance = float(distance)
        speed = 2 * vehicle.MAX_SPEED
        bound = np.array([self.max_distance] * 2 + [speed] * 2 + [1.0, 1.0], dtype=np.float32)
        self._bound = bound
        self.observation_space = spaces.Sequence(
            spaces.Box(np.append(-bound, 0).astype(np.float32),
                       np.append(bound, self.n_types - 1).astype(np.float32), dtype=np.float32),
            stack=True)

    @property
    def n_types(self):
        """Number of object types (4)."""
        return len(self.type_names)

    def observation(self, observation):
        """The rows of the ego vehicle and the objects near it (the env's own observation
        is not used).

        Returns
        -------
        rows : ndarray of float32 of shape (n, 7)
            ``[x, y, vx, vy, cos_h, sin_h, type]``, the ego vehicle first.
        """
        _, vehicle, landmark = _highway()
        env = self.env.unwrapped
        ego = env.vehicle
        near = [o for o in (*env.road.vehicles, *env.road.objects) if o is not ego
                and np.linalg.norm(o.position - ego.position) < self.max_distance]
        rows = np.zeros((1 + len(near), 7), dtype=np.float32)
        for row, o in zip(rows, (ego, *near)):
            row[:6] = (*o.position, *o.velocity, np.cos(o.heading), np.sin(o.heading))
            row[6] = (0 if o is ego else 1 if isinstance(o, vehicle)
                      else 3 if isinstance(o, landmark) else 2)
        rows[1:, :4] -= rows[0, :4]
        rows[0, :2] = 0.0
        np.clip(rows[:, :6], -self._bound, self._bound, out=rows[:, :6])
        return rows
