"""The Q-function of an FQI iteration: one fitted clone of the regressor per action."""
import warnings

import numpy as np
from joblib import effective_n_jobs
from sklearn.base import clone

from boxtrees._threads import thread_pool

__all__ = []


class _QFunction:
    """``Q_n``: a regressor per action, fitted at iteration `iteration`.

    Parameters
    ----------
    models : list of regressors
        One per action, fitted.
    iteration : int
        The iteration that fitted them (named in errors).
    """

    def __init__(self, models, iteration):
        self.models, self.iteration = models, iteration

    @classmethod
    def fit(cls, regressor, data, targets, n_actions, rng, previous, iteration):
        """A clone of `regressor` per action, fitted on the transitions with that action;
        each clone's ``random_state`` parameters (nested ones too) drawn from `rng`. An action
        absent from the data keeps its `previous` model (with a warning), or is an error
        without one."""
        models = []
        for action in range(n_actions):
            mask = data.actions == action
            if not mask.any():
                if previous is None:
                    raise ValueError(f"no transition with action {action} in the data; "
                                     f"collect more samples per iteration")
                warnings.warn(f"no transition with action {action} in the data; keeping its "
                              f"previous Q-function", RuntimeWarning, stacklevel=4)
                models.append(previous.models[action])
                continue
            model = clone(regressor)
            seed = int(rng.integers(2**31 - 1))
            model.set_params(**{key: seed for key in model.get_params()
                                if key == "random_state" or key.endswith("__random_state")})
            models.append(model.fit(data.states[mask], targets[mask]))
        return cls(models, iteration)

    def values(self, batch, n_jobs=1):
        """``Q(s, a)`` of every action for the observations of `batch`, shape ``(n,
        n_actions)``, predicted in up to `n_jobs` threads (one action each) and checked to be
        one finite value per observation."""
        n_threads = min(effective_n_jobs(n_jobs), len(self.models))
        if n_threads == 1:
            predictions = [model.predict(batch) for model in self.models]
        else:
            predictions = thread_pool(n_threads, "fqi-actions").map(
                lambda model: model.predict(batch), self.models)
        q = np.empty((len(batch), len(self.models)))
        for action, prediction in enumerate(predictions):
            q[:, action] = _checked_prediction(
                prediction, len(batch), lambda: f"iteration {self.iteration}'s Q-function of "
                f"action {action} ({self.models[action]!r})")
        return q


def _checked_prediction(prediction, n, describe):
    """`prediction` for `n` observations, as floats of shape ``(n,)``, after checking there
    are `n` of them and all are finite; ``describe()`` names the model in the error."""
    prediction = np.asarray(prediction, dtype=np.float64)
    bad = ~np.isfinite(prediction)
    if prediction.size == n and not bad.any():
        return prediction.reshape(n)
    model = describe()
    if prediction.size != n:
        raise ValueError(f"{model} predicted an array of size {prediction.size} for "
                         f"{n} observations; a regressor must predict one value per "
                         f"observation")
    raise ValueError(f"{model} predicted non-finite Q-values (NaN or inf) for {bad.sum()} "
                     f"of {n} observations; a regressor must predict finite values")
