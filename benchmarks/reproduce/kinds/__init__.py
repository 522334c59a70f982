"""The unit kinds, one module each: what a unit runs, costs and records, and how a
setting's runs are summarised, drawn and tabled (see `UnitKind`).

Every public module of this package is imported here, and each `UnitKind` subclass with a
``name`` registers itself in `KINDS`: a new kind is a new module, nothing else.
"""
import importlib
import pkgutil

from ._base import KINDS, GameSettings, UnitKind

__all__ = ["KINDS", "UnitKind", "GameSettings"]

for _module in pkgutil.iter_modules(__path__):
    if not _module.name.startswith("_"):
        importlib.import_module(f"{__name__}.{_module.name}")
