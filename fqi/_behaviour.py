"""The data's behaviour model: which actions a fixed data set supports at a state (FQI's
``support_threshold``, the constraint of its offline backups and of its greedy policy)."""
import numpy as np
from gymnasium import spaces
from sklearn.ensemble import ExtraTreesClassifier

from boxtrees import BoxExtraTreesClassifier

from ._calls import _regressor_calls
from ._observations import _view_bounds
from ._q_function import _seeded_clone

__all__ = []

_TREES = 30
# A leaf of the default classifier on feature vectors holds at least this many transitions:
# a next state is most often a state of the data itself, which a tree grown out puts in a
# leaf of its own action alone (on CartPole's uniformly random data, 96% of the next states
# then had one action with no share at all).
_MIN_SAMPLES_LEAF = 5
# A box forest has no least leaf size: its nodes of fewer transitions than this are leaves
# (on 3,000 uniformly random steps of three actions over object sets, tests/test_fqi_offline's
# NearestType, every action was supported at 87% of the next states with 100, at 42% with
# the forest's default 30).
_MIN_SAMPLES_SPLIT_SETS = 100


def _default_classifier(observation_space):
    """The behaviour classifier FQI fits when given none: 30 Extra-Trees, with leaves of at
    least `_MIN_SAMPLES_LEAF` transitions on feature vectors
    (``sklearn.ensemble.ExtraTreesClassifier``), or a `boxtrees.BoxExtraTreesClassifier`
    drawing its tests in the view of object sets, splitting nodes of at least
    `_MIN_SAMPLES_SPLIT_SETS`."""
    if isinstance(observation_space, spaces.Box):
        return ExtraTreesClassifier(n_estimators=_TREES, min_samples_leaf=_MIN_SAMPLES_LEAF)
    return BoxExtraTreesClassifier(n_estimators=_TREES,
                                   min_samples_split=_MIN_SAMPLES_SPLIT_SETS,
                                   view_bounds=_view_bounds(observation_space))


class _Support:
    """A classifier fitted on a data set's ``(state -> action)``: the share of each action
    the data take near a state, and the actions it supports there.

    Parameters
    ----------
    model : classifier
        Fitted; ``predict_proba`` gives its classes' shares (``classes_`` order).
    n_actions : int
    """

    def __init__(self, model, n_actions):
        self.model, self.n_actions = model, n_actions

    @classmethod
    def fit(cls, classifier, data, n_actions, rng):
        """A clone of `classifier` (its ``random_state`` parameters drawn from `rng`) fitted
        on the states and actions of `data` (a `_Transitions`)."""
        model = _seeded_clone(classifier, rng)
        try:
            with _regressor_calls():
                model = model.fit(data.states, data.actions)
        except (TypeError, ValueError) as exc:
            raise type(exc)(f"the behaviour classifier {classifier!r} failed to fit the "
                            f"data's states and actions ({type(exc).__name__}: {exc}); pass "
                            f"a classifier that takes these observations as "
                            f"support_classifier, or support_threshold=None") from exc
        return cls(model, n_actions)

    def shares(self, batch):
        """Each action's share at each observation of `batch`, shape ``(n, n_actions)``
        (0 for an action the data never take)."""
        with _regressor_calls(len(batch)):
            proba = np.asarray(self.model.predict_proba(batch), dtype=float)
        classes = np.asarray(self.model.classes_)
        if proba.shape != (len(batch), len(classes)) or not np.isfinite(proba).all():
            raise ValueError(f"the behaviour classifier {self.model!r} gave shares of shape "
                             f"{proba.shape} for {len(batch)} observations of its "
                             f"{len(classes)} classes; predict_proba must give one finite "
                             f"row per observation")
        shares = np.zeros((len(batch), self.n_actions))
        shares[:, classes.astype(np.intp)] = proba
        return shares

    def supported(self, batch, threshold):
        """Whether each action is supported at each observation of `batch`: its share at
        least `threshold` times the largest there (BCQ's relative threshold); shape ``(n,
        n_actions)``, at least one action per observation."""
        shares = self.shares(batch)
        return shares >= threshold * shares.max(axis=1, keepdims=True)

