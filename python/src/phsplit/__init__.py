"""phsplit: passivity-preserving splitting methods for marine vessel dynamics.

Implements Celledoni, Høiseth & Ramzina, *Passivity-preserving splitting methods for rigid body
systems*, Multibody System Dynamics 44 (2018) 251–275, on a Rust core.

>>> import phsplit
>>> sol = phsplit.simulate(phsplit.Vessel.paper(), t_span=(0.0, 10.0), h=0.5, method="sp2")
>>> sol.x.shape
(21, 3)
"""
from __future__ import annotations

import time as _time

#: When the package was imported: the start of a ``phsplit`` command, whose summary reports the
#: whole command's time from here.
_STARTED = _time.perf_counter()


def _early_signal(signum, frame):  # pragma: no cover - exercised by the CLI's signal test
    import os

    os.write(2, b"phsplit: interrupted while starting; nothing was written\n")
    os._exit(130)


def _quiet_start() -> None:
    """When this import is the start of the ``phsplit`` command (the console script, or
    ``python -m phsplit``), Ctrl-C or SIGTERM before the CLI installs its own handlers ends the
    process with one line and status 130 instead of a traceback (nothing has been written
    then). A library import is left alone."""
    import os
    import signal
    import sys

    exe = os.path.basename(sys.argv[0]) if sys.argv else ""
    if exe in ("phsplit", "-m") and signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _early_signal)
        if signal.getsignal(signal.SIGTERM) in (signal.SIG_DFL, None):
            signal.signal(signal.SIGTERM, _early_signal)


_quiet_start()

from ._core import (
    METHODS,
    IntegrationError,
    InvalidInputError,
    PhsplitError,
    ScenarioParseError,
    __version__,
)
from ._core import method_info as _method_info
from . import dp, events, hydro, pipe, results, rigid_body, sea, so3, special
from .batch import simulate_many, with_parameters
from .capability import capability
from .results import open_dataset, open_sweep, rerun
from .scenario import Scenario
from .seakeeping import rao
from .scenario import load as load_scenario
from .simulate import (Ledger, ModelRangeWarning, PassivityWarning, SettingWarning, Settings, Solution, StepSizeWarning, Vessel,
                       presets, simulate)


def method_info(name: str) -> dict:
    """Order, stages, citation and passivity guarantee of a method (see ``METHODS``)."""
    if not isinstance(name, str):
        raise InvalidInputError(f"method_info takes a method's name, one of {', '.join(METHODS)}; got "
                                f"{type(name).__name__} {name!r}")
    return dict(_method_info(name))


__all__ = [
    "METHODS",
    "IntegrationError",
    "InvalidInputError",
    "Ledger",
    "ModelRangeWarning",
    "PassivityWarning",
    "SettingWarning",
    "PhsplitError",
    "Scenario",
    "ScenarioParseError",
    "Settings",
    "Solution",
    "StepSizeWarning",
    "Vessel",
    "__version__",
    "capability",
    "dp",
    "events",
    "hydro",
    "load_scenario",
    "method_info",
    "open_dataset",
    "open_sweep",
    "pipe",
    "presets",
    "rao",
    "rerun",
    "results",
    "rigid_body",
    "sea",
    "simulate",
    "simulate_many",
    "so3",
    "special",
    "with_parameters",
]
