"""The settings of a run (:class:`Settings`) and their TOML form. A data type of the bottom
layer: it imports only the core (``Settings.run`` calls the simulation the upper layer
provides, see :mod:`phsplit._provided`)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from . import _core, _provided
from ._arguments import checked

_DEFAULTS = _core.default_settings()


#: Settings whose ``None`` means "not given" (fixed steps).
_OPTIONAL = ("rtol", "atol", "h_max")


@dataclass(frozen=True)
class Settings:
    """The settings of a run, with the one set of defaults (the core's; the paper's Fig. 2:
    SP4, h = 0.5 s on [0, 200] s, the controller from t = 50 s; flow S2 ``"auto"``: exact where
    it acts on a diagonal mass matrix, else Gauss collocation, of order 4 for a second-order
    method at fixed steps where S2 has a forcing part; ``linear_flow = "exact"`` for the
    paper's exact S2) shared by :func:`simulate`,
    scenario files, :func:`~phsplit.simulate_many` and sweeps. Values are checked by the core
    when a run starts (or by :meth:`checked`)."""

    t_span: tuple[float, float] = tuple(_DEFAULTS["t_span"])  # type: ignore[assignment]
    h: float = _DEFAULTS["h"]
    method: str = _DEFAULTS["method"]
    control_start: float | None = _DEFAULTS["control_start"]
    outer: str = _DEFAULTS["outer"]
    save_every: int = _DEFAULTS["save_every"]
    linear_flow: str = _DEFAULTS["linear_flow"]
    ledger: bool = _DEFAULTS["ledger"]
    project_invariants: bool = _DEFAULTS["project_invariants"]
    #: Adaptive steps (docs/how-to/choose-method-step-flow.md): with ``rtol`` or ``atol`` the
    #: steps follow the error estimate and ``h`` is the first one tried; ``None``: fixed steps.
    rtol: float | None = _DEFAULTS["rtol"]
    atol: float | None = _DEFAULTS["atol"]
    h_max: float | None = _DEFAULTS["h_max"]

    @property
    def adaptive(self) -> bool:
        """Whether the steps are adaptive (``rtol`` or ``atol`` given)."""
        return self.rtol is not None or self.atol is not None

    def as_core(self) -> dict[str, Any]:
        """The settings as the core takes them: numpy scalars as Python numbers, ``None`` for
        ``control_start`` as ``"never"``; ``None`` anywhere else is refused by name."""
        d = {k: getattr(self, k) for k in self.__dataclass_fields__}
        if d["control_start"] is None:
            d["control_start"] = "never"
        for k in _OPTIONAL:
            if d[k] is None:
                del d[k]
        for k, v in d.items():
            if v is None:
                what = dict(_core.settings_keys())
                raise _core.InvalidInputError(f"{k} must be given ({what.get(k, 'a value')}), got None")
            if isinstance(v, np.bool_):
                d[k] = bool(v)
            elif isinstance(v, np.integer):
                d[k] = int(v)
            elif isinstance(v, np.floating):
                d[k] = float(v)
        return d

    def checked(self) -> dict[str, Any]:
        """The settings as the core validated them, with the step count ``n_steps``."""
        return _core.check_settings(self.as_core())

    def run(self, vessel, **kw):
        """``phsplit.simulate(vessel, settings=self, **kw)``."""
        return _provided.get("simulate")(vessel, settings=self, **kw)


# An unknown or misspelt field is an InvalidInputError naming it, as for the functions.
Settings.__init__ = checked(Settings.__init__, "Settings")  # type: ignore[method-assign]


def settings_to_toml(settings: Mapping[str, Any]) -> str:
    """Run settings (as the core returns them) as a ``[simulation]`` TOML table."""
    sim = {k: settings[k] for k in Settings.__dataclass_fields__ if k in settings}
    sim["t_span"] = [float(x) for x in sim["t_span"]]
    if sim.get("control_start") is None:
        sim["control_start"] = "never"
    for k in _OPTIONAL:
        if sim.get(k) is None:
            sim.pop(k, None)
    return _core.dumps_toml({"simulation": sim})
