"""Types of the compiled core (`python/src/lib.rs`); use the `softarm` API."""

from typing import Optional

import numpy as np
import numpy.typing as npt

Vector = npt.NDArray[np.float64]

class IntegrationError(RuntimeError):
    report: dict

class Model:
    name: str
    dof: int
    coordinates: list[str]
    parameters: list[str]
    backend: str
    origin: str
    def mass_bias(self, q: Vector, qd: Optional[Vector] = None, t: float = 0.0) -> tuple[Vector, Vector]: ...
    def jacobian(self, q: Vector, qd: Optional[Vector] = None, t: float = 0.0) -> Vector: ...
    def outputs(self, q: Vector, qd: Optional[Vector] = None, t: float = 0.0) -> Vector: ...
    def linearize(
        self, inputs: list[str] = ..., u0: Optional[Vector] = None, q0: Optional[Vector] = None,
    ) -> tuple[Vector, Vector, Vector, Vector, Vector, Vector]: ...
    def equilibrium(self, q0: Optional[Vector] = None) -> tuple[Vector, float, int]: ...
    def modes(self, q: Vector) -> tuple[Vector, Vector]: ...  # shapes (n, k), frequencies (k,)
    def fit(
        self,
        free: list[str],
        window: Optional[tuple[float, float]] = None,
        validate: Optional[str] = None,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        max_iterations: int = 40,
    ) -> str: ...  # fit.json's content
    def simulate(
        self,
        t_end: Optional[float] = None,
        solver: Optional[str] = None,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        dt: Optional[float] = None,
        output_dt: Optional[float] = None,
        max_steps: Optional[int] = None,
        q0: Optional[Vector] = None,
        qd0: Optional[Vector] = None,
        start: Optional[str] = None,
        inputs: list[tuple[str, list[float], list[float]]] = ...,
        rho_inf: Optional[float] = None,
    ) -> tuple[Vector, Vector, Vector, str, list[str], Vector, list[str], Vector]: ...

    def simulator(
        self, dt: float, inputs: list[str] = ..., solver: Optional[str] = None,
        rtol: Optional[float] = None, atol: Optional[float] = None,
        step: Optional[float] = None,
    ) -> Simulator: ...

class Simulator:
    dt: float
    t: float
    state: Vector
    inputs: list[str]
    def step(self, u: Optional[Vector] = None) -> Vector: ...
    def reset(self, state: Optional[Vector] = None) -> Vector: ...
    def outputs(self) -> Vector: ...

def load_model(spec: str, overrides: list[str] = ...) -> Model: ...
def models() -> list[str]: ...

OUTPUT_NAMES: list[str]
