"""`SetEncoder`: a stable-baselines3 features extractor for padded object sets."""
from __future__ import annotations

import numpy as np
import numpy.typing as npt
import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from ._checks import _check_bool

__all__ = ["SetEncoder"]


class SetEncoder(BaseFeaturesExtractor):
    """Deep Sets encoder of padded objects, with an optional masked self-attention layer.

    Reads observations of shape ``(max_objects, d + 2)`` whose rows are ``[f_1, ..., f_d,
    type, valid]``, ``d >= 1`` (``envs.PaddedObjects``, or any wrapper with that layout;
    ``[dx, dy, type, valid]`` for the thesis's game): each valid object becomes
    ``[f_1 / scale_1, ..., f_d / scale_d, one-hot type]``, goes through a shared MLP (and, with
    ``attention``, one residual multi-head self-attention layer over the valid objects),
    and the set is pooled by the mean and the maximum over its valid objects, then mapped
    by an MLP to ``features_dim`` features. Padding rows take no part anywhere, so the
    features do not depend on the padding nor on the order of the objects; an empty set
    has all-zero pooled features.

    Parameters
    ----------
    observation_space : gymnasium.spaces.Box
        Of shape ``(max_objects, d + 2)``. The largest type id is read from the upper bound
        of the type column and each attribute's scale from the bounds of its column (the
        largest absolute bound; 1 where that is infinite or 0), so the encoder needs no
        knowledge of the game.
    embed_dim : int, default=64
        Width of the per-object MLP.
    features_dim : int, default=128
        Number of output features.
    attention : bool, default=False
        Add one masked self-attention layer between the object MLP and the pooling.
    n_heads : int, default=4
        Heads of the attention layer (must divide ``embed_dim``).
    scale : array-like of shape (d,), default=None
        Each attribute's scale, positive and finite, instead of the one read from the
        bounds: for spaces whose bounds are far wider than the values the game takes
        (divided by a loose bound, small moves become too small for the MLP to tell apart).

    Examples
    --------
    >>> import gymnasium as gym, envs
    >>> from stable_baselines3 import DQN
    >>> from fqi import SetEncoder
    >>> env = envs.PaddedObjects(gym.make("ObjectWorld-v0"), max_objects=64)
    >>> model = DQN("MlpPolicy", env, learning_starts=0, policy_kwargs=dict(
    ...     features_extractor_class=SetEncoder,
    ...     features_extractor_kwargs=dict(attention=True)), seed=0).learn(64)
    >>> model.policy.q_net.features_extractor.n_types
    4
    """

    def __init__(self, observation_space: spaces.Box, embed_dim: int = 64,
                 features_dim: int = 128, attention: bool = False, n_heads: int = 4,
                 scale: npt.ArrayLike | None = None) -> None:
        if not (isinstance(observation_space, spaces.Box) and len(observation_space.shape) == 2
                and observation_space.shape[1] >= 3):
            raise ValueError(f"SetEncoder needs a Box observation space of shape (max_objects, "
                             f"d + 2), rows [f_1, ..., f_d, type, valid] with d >= 1; got "
                             f"{observation_space}")
        for name, value in (("embed_dim", embed_dim), ("features_dim", features_dim),
                            ("n_heads", n_heads)):
            if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < 1:
                raise ValueError(f"{name} must be a positive int, got {value!r}")
        attention = _check_bool("attention", attention)
        if attention and embed_dim % n_heads:
            raise ValueError(f"n_heads ({n_heads}) must divide embed_dim ({embed_dim})")
        high, low = observation_space.high[0], observation_space.low[0]
        d = observation_space.shape[1] - 2
        if not (np.isfinite(high[d]) and high[d] >= 0):
            raise ValueError(f"SetEncoder reads the number of types from the upper bound of "
                             f"the type column, which must be finite and >= 0; got "
                             f"{high[d]} in {observation_space}")
        super().__init__(observation_space, features_dim)
        self.n_attributes, self.n_types = d, int(high[d]) + 1
        if scale is None:
            bounds = np.max(np.abs([low[:d], high[:d]]), axis=0).astype(np.float64)
            scale = np.where(np.isfinite(bounds) & (bounds > 0), bounds, 1.0)
        else:
            scale = _check_scale(scale, d)
        self.register_buffer("scale", torch.as_tensor(scale, dtype=torch.float32),
                             persistent=False)
        self.objects = nn.Sequential(nn.Linear(d + self.n_types, embed_dim), nn.ReLU(),
                                     nn.Linear(embed_dim, embed_dim), nn.ReLU())
        self.attention = (nn.MultiheadAttention(embed_dim, n_heads, batch_first=True)
                          if attention else None)
        self.head = nn.Sequential(nn.Linear(2 * embed_dim, features_dim), nn.ReLU())

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        d = self.n_attributes
        valid = observations[..., d + 1] > 0.5                      # (batch, max_objects)
        types = observations[..., d].round().long().clamp(0, self.n_types - 1)
        rows = torch.cat([observations[..., :d] / self.scale,
                          nn.functional.one_hot(types, self.n_types).float()], dim=-1)
        hidden = self.objects(rows)
        if self.attention is not None:
            # a set without objects attends to nothing: let it see every row, then mask
            ignore = ~valid & valid.any(dim=1, keepdim=True)
            attended, _ = self.attention(hidden, hidden, hidden, key_padding_mask=ignore,
                                         need_weights=False)
            hidden = hidden + attended
        mask = valid.unsqueeze(-1)
        count = mask.sum(dim=1).clamp(min=1)
        mean = torch.where(mask, hidden, 0.0).sum(dim=1) / count
        largest = torch.where(mask, hidden, -torch.inf).amax(dim=1)
        largest = torch.where(valid.any(dim=1, keepdim=True), largest, 0.0)
        return self.head(torch.cat([mean, largest], dim=-1))


def _check_scale(scale: npt.ArrayLike, d: int) -> np.ndarray:
    """`scale` as ``d`` positive finite floats, or a ValueError naming what is wrong."""
    try:
        values = np.asarray(scale, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"scale must be an array-like of {d} numbers, got {scale!r}") from None
    if values.shape != (d,):
        raise ValueError(f"scale must have one value per attribute, shape ({d},), got shape "
                         f"{values.shape}")
    if not (np.isfinite(values).all() and (values > 0).all()):
        raise ValueError(f"scale must be positive and finite, got {values}")
    return values
