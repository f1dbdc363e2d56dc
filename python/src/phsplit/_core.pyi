"""Type stub of the native module phsplit._core (Rust, PyO3)."""
from typing import Any

import numpy as np
import numpy.typing as npt

METHODS: list[str]
MAX_STEPS: int
__version__: str

class PhsplitError(Exception): ...
class InvalidInputError(ValueError): ...
class ScenarioParseError(ValueError): ...
class IntegrationError(PhsplitError): ...

class Vessel:
    @staticmethod
    def paper() -> Vessel: ...
    @staticmethod
    def from_toml_str(text: str) -> Vessel: ...
    @staticmethod
    def paper_toml() -> str: ...
    def to_dict(self) -> dict[str, dict[str, Any]]: ...
    def energy(self, state: npt.NDArray[np.float64]) -> float: ...
    def initial_state(
        self,
        euler: list[float] | None = ...,
        position: list[float] | None = ...,
        velocity: list[float] | None = ...,
        angular_velocity: list[float] | None = ...,
    ) -> npt.NDArray[np.float64]: ...

class VectorField:
    """Compiled right-hand side of eq. (39) for external solvers."""

    def __init__(self, vessel: Vessel, control_start: float | None = ...) -> None: ...
    def __call__(self, t: float, y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def into(self, t: float, y: npt.NDArray[np.float64], out: npt.NDArray[np.float64]) -> None: ...

def integrate(
    vessel: Vessel,
    t0: float,
    h: float,
    n_steps: int,
    method: str,
    control_start: float | None,
    outer: str,
    save_every: int,
    ledger: bool,
    state0: npt.NDArray[np.float64],
    linear_flow: str = ...,
    orthonormalize: bool = ...,
) -> dict[str, Any]: ...
def method_info(name: str) -> dict[str, Any]: ...
def euler_zyx(q: list[list[float]]) -> list[float]: ...
