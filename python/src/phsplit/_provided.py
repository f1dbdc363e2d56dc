"""What an upper layer provides to the data types below it.

``Settings.run`` runs a simulation and ``Solution.at`` computes dense output: both belong to
layers above the data types (the façade :mod:`phsplit.simulate` and the driver
:mod:`phsplit.events`). Those modules register their functions here when they are imported
(``import phsplit`` imports them), so that the data types call upwards without importing
upwards: the import graph stays layered and acyclic (the import contract in pyproject.toml).
"""
from __future__ import annotations

from typing import Any, Callable

from . import _core

_FUNCTIONS: dict[str, Callable[..., Any]] = {}


def provide(name: str, function: Callable[..., Any]) -> None:
    """Register ``function`` under ``name`` (called by the module that defines it)."""
    _FUNCTIONS[name] = function


def get(name: str) -> Callable[..., Any]:
    """The function registered under ``name``."""
    try:
        return _FUNCTIONS[name]
    except KeyError:
        raise _core.PhsplitError(f"phsplit's {name} is not loaded: import phsplit first") from None
