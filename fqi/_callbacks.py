"""`FQI.learn` callbacks: stable-baselines3 `BaseCallback` objects, plain callables, lists.

stable-baselines3 is not imported: a callback object is recognised by the methods of
`stable_baselines3.common.callbacks.BaseCallback` (``CallbackList`` included), so SB3's own
callbacks and any written in its style are called as SB3 calls them, with the agent as
``model``.
"""
__all__ = []

_CALLBACK_METHODS = ("init_callback", "on_training_start", "update_locals", "on_step",
                     "on_training_end")


def _as_callback(callback):
    """`callback` as an object with the `BaseCallback` methods `learn` calls."""
    if callback is None:
        return _Callbacks([])
    if isinstance(callback, (list, tuple)):
        return _Callbacks([_as_callback(c) for c in callback])
    if all(callable(getattr(callback, name, None)) for name in _CALLBACK_METHODS):
        return callback
    if callable(callback):
        return _FunctionCallback(callback)
    raise TypeError(f"callback must be a stable-baselines3 BaseCallback (or CallbackList), a "
                    f"callable(locals_, globals_) or a list of them; got "
                    f"{type(callback).__name__}")


class _FunctionCallback:
    """A plain ``callback(locals_, globals_)``, called at every ``on_step`` (SB3's
    ``ConvertCallback``)."""

    def __init__(self, function):
        self.function = function
        self.locals, self.globals = {}, {}

    def init_callback(self, model):
        self.model = model

    def on_training_start(self, locals_, globals_):
        self.locals, self.globals = locals_, globals_

    def update_locals(self, locals_):
        self.locals.update(locals_)

    def on_step(self):
        return self.function(self.locals, self.globals)

    def on_training_end(self):
        pass


class _Callbacks:
    """Several callbacks called in order; ``on_step`` is False when any of them is."""

    def __init__(self, callbacks):
        self.callbacks = callbacks

    def init_callback(self, model):
        for callback in self.callbacks:
            callback.init_callback(model)

    def on_training_start(self, locals_, globals_):
        for callback in self.callbacks:
            callback.on_training_start(locals_, globals_)

    def update_locals(self, locals_):
        for callback in self.callbacks:
            callback.update_locals(locals_)

    def on_step(self):
        # a list, not a generator: every callback is called, as in SB3's CallbackList
        return not any([callback.on_step() is False for callback in self.callbacks])

    def on_training_end(self):
        for callback in self.callbacks:
            callback.on_training_end()
