"""Solvers for the radiosity system B_i = E_i + rho_i sum_j F_ij B_j, per RGB channel.

In matrix form (the lecture's slide) ``(I - diag(rho) F) B = E``:

* ``direct``       -- ``numpy.linalg.solve`` of that system, per channel;
* ``jacobi``       -- B <- E + rho F B, all patches at once (gathering);
* ``gauss-seidel`` -- the same, each patch using the newest values of the others;
* ``progressive``  -- Cohen, Chen, Wallace & Greenberg 1988: shoot the patch with the most
  unshot energy dB_i A_i to every other patch, needing one row of F per shot; an ambient term
  (their eq. 5) stands in for the light not yet shot, for display only.

Every solver is a generator of :class:`Step` (one per iteration or shot) with the residual or
the unshot energy and the elapsed time, so the CLI, the viewer and the bench read one record.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Iterator

import numba
import numpy as np

from shadelab.errors import ShadeLabError
from shadelab.scene.model import RADIOSITY_SOLVERS

SOLVERS = RADIOSITY_SOLVERS  # the preset schema's choices
DIVERGED = 1e12  # a relative residual above this means the iteration blows up
# Spectral radius of rho F at or above this is refused: form factors carry ~1e-4 quadrature
# error in their row sums, so an exactly closed rho = 1 scene measures just below 1.
SOLVABLE_RADIUS = 1.0 - 1e-3


@dataclass
class Step:
    """State after one iteration (or one shot of progressive refinement).

    Attributes
    ----------
    B : (N, 3) radiosity (energy leaving per unit area; B = pi L)
    iteration : 1-based count of iterations or shots
    residual : ||E + rho F B - B||_1 / ||E||_1 (nan where F is not all known: progressive)
    unshot : progressive only: sum_i dB_i A_i / sum_i E_i A_i (nan for the others)
    seconds : since the solver started
    ambient : (3,) progressive's ambient radiosity estimate (zeros for the others)

    ``B`` may be updated in place by the next step: copy it to keep it.
    """

    B: np.ndarray
    iteration: int
    residual: float
    unshot: float
    seconds: float
    ambient: np.ndarray

    def display_B(self, rho: np.ndarray) -> np.ndarray:
        """Radiosity for display: progressive refinement adds rho * ambient."""
        return self.B + rho * self.ambient[None, :]


def residual(F: np.ndarray, rho: np.ndarray, E: np.ndarray, B: np.ndarray) -> float:
    """Relative L1 residual of the radiosity system."""
    r = E + rho * (F @ B) - B
    return float(np.abs(r).sum() / max(np.abs(E).sum(), 1e-300))


def spectral_radius(F: np.ndarray, rho: np.ndarray, iterations: int = 300) -> float:
    """Largest spectral radius of diag(rho_c) F over the channels (power iteration)."""
    worst = 0.0
    for c in range(rho.shape[1]):
        x = np.ones(len(F))
        growth = 0.0
        for _ in range(iterations):
            y = rho[:, c] * (F @ x)
            norm = float(np.abs(y).sum())
            if norm == 0.0:
                growth = 0.0
                break
            growth = norm / float(np.abs(x).sum())
            x = y / norm * len(F)
        worst = max(worst, growth)
    return worst


def check_solvable(F: np.ndarray, rho: np.ndarray, names: Callable[[], str] | None = None):
    """Refuse a system without a bounded solution (reflectance >= 1 in a closed scene).

    Row sums of rho F below 1 guarantee convergence; otherwise the spectral radius decides
    (refused from ``SOLVABLE_RADIUS`` up: a nearly singular system converges too slowly).
    """
    if np.all(rho * F.sum(axis=1)[:, None] < SOLVABLE_RADIUS):
        return
    radius = spectral_radius(F, rho)
    if radius >= SOLVABLE_RADIUS:
        where = names() if names else "a material"
        raise ShadeLabError(f"{where}: reflectance rho = kd*Od >= 1 in a closed scene, so the "
                            f"radiosity system (I - rho F) B = E has no bounded solution "
                            f"(spectral radius of rho F = {radius:.4f}); keep kd*Od below 1")


# ---------------------------------------------------------------------- gathering solvers
def solve_direct(F: np.ndarray, rho: np.ndarray, E: np.ndarray) -> Iterator[Step]:
    """One step: the exact solution of (I - diag(rho) F) B = E per channel."""
    start = time.perf_counter()
    n = len(F)
    B = np.empty_like(E)
    for c in range(3):
        try:
            B[:, c] = np.linalg.solve(np.eye(n) - rho[:, c, None] * F, E[:, c])
        except np.linalg.LinAlgError:
            raise ShadeLabError("radiosity: the system (I - rho F) B = E is singular "
                                "(reflectance kd*Od >= 1 in a closed scene?)") from None
    yield Step(B, 1, residual(F, rho, E, B), float("nan"), time.perf_counter() - start,
               np.zeros(3))


def solve_jacobi(F: np.ndarray, rho: np.ndarray, E: np.ndarray, iterations: int = 200,
                 tolerance: float = 1e-4) -> Iterator[Step]:
    """B^(k+1) = E + rho F B^(k), starting from B = E."""
    start = time.perf_counter()
    B = E.copy()
    for k in range(1, iterations + 1):
        B = E + rho * (F @ B)
        res = residual(F, rho, E, B)
        yield Step(B, k, res, float("nan"), time.perf_counter() - start, np.zeros(3))
        if res < tolerance or not res < DIVERGED:
            break


@numba.njit(cache=True)
def _gauss_seidel_sweep(F, rho, E, B):
    n = F.shape[0]
    for i in range(n):
        for c in range(3):
            total = 0.0
            for j in range(n):
                total += F[i, j] * B[j, c]
            B[i, c] = E[i, c] + rho[i, c] * total


def solve_gauss_seidel(F: np.ndarray, rho: np.ndarray, E: np.ndarray, iterations: int = 200,
                       tolerance: float = 1e-4) -> Iterator[Step]:
    """Sweeps over the patches in order, each using the newest values of the others."""
    start = time.perf_counter()
    B = E.astype(np.float64).copy()
    F = np.ascontiguousarray(F, np.float64)
    for k in range(1, iterations + 1):
        _gauss_seidel_sweep(F, np.ascontiguousarray(rho, np.float64),
                            np.ascontiguousarray(E, np.float64), B)
        res = residual(F, rho, E, B)
        yield Step(B.copy(), k, res, float("nan"), time.perf_counter() - start, np.zeros(3))
        if res < tolerance or not res < DIVERGED:
            break


# ---------------------------------------------------------------------- shooting
@numba.njit(cache=True)
def _shoot(f, areas, rho, B, unshot, i):
    """One shot from patch i through its row f = F_i. (in place on B and unshot): every j
    gains rho_j dB_i F_ij A_i / A_j. Returns the next shooter (the largest unshot energy,
    first on ties) and the unshot power per channel, sum_j dB_j A_j."""
    n = len(areas)
    s0, s1, s2 = unshot[i, 0], unshot[i, 1], unshot[i, 2]
    ai = areas[i]
    for j in range(n):
        w = f[j] * ai / areas[j]
        if w != 0.0:
            g0, g1, g2 = rho[j, 0] * s0 * w, rho[j, 1] * s1 * w, rho[j, 2] * s2 * w
            B[j, 0] += g0
            B[j, 1] += g1
            B[j, 2] += g2
            unshot[j, 0] += g0
            unshot[j, 1] += g1
            unshot[j, 2] += g2
    unshot[i, 0] = unshot[i, 1] = unshot[i, 2] = 0.0
    power = np.zeros(3)
    best, best_energy = 0, -1.0
    for j in range(n):
        e0, e1, e2 = unshot[j, 0] * areas[j], unshot[j, 1] * areas[j], unshot[j, 2] * areas[j]
        power[0] += e0
        power[1] += e1
        power[2] += e2
        energy = e0 + e1 + e2
        if energy > best_energy:
            best, best_energy = j, energy
    return best, power


def solve_progressive(row: Callable[[int], np.ndarray], areas: np.ndarray, rho: np.ndarray,
                      E: np.ndarray, max_shots: int = 100000,
                      tolerance: float = 1e-4) -> Iterator[Step]:
    """Progressive refinement: shoot the largest unshot energy, one row of F per shot.

    ``row(i)`` returns F_i. (the solution's drivers hand it rows of the reciprocal matrix
    that the gathering solvers read, :func:`shadelab.radiosity.solution.solver_steps`). A
    shot from i adds to every j dB_j = rho_j dB_i F_ji = rho_j dB_i F_ij A_i / A_j
    (reciprocity), so the hemicube or the rays are cast from the shooter only. Each shot is
    one compiled pass over the patches (:func:`_shoot`).
    """
    start = time.perf_counter()
    B, unshot = E.astype(np.float64).copy(), E.astype(np.float64).copy()
    areas = np.ascontiguousarray(areas, np.float64)
    rho = np.ascontiguousarray(rho, np.float64)
    total_area = float(areas.sum())
    # Ambient term (Cohen et al. 1988): area-weighted reflectance and its interreflection sum
    rho_avg = (rho * areas[:, None]).sum(axis=0) / total_area
    interreflection = 1.0 / np.maximum(1.0 - rho_avg, 1e-6)
    initial = float((E * areas[:, None]).sum())
    if initial <= 0.0:
        raise ShadeLabError("radiosity: nothing emits light (no material with emission > 0)")
    i = int(np.argmax((unshot * areas[:, None]).sum(axis=1)))
    for k in range(1, max_shots + 1):
        f = np.ascontiguousarray(row(i), np.float64)
        i, power = _shoot(f, areas, rho, B, unshot, i)
        left = float(power.sum()) / initial
        ambient = interreflection * power / total_area
        yield Step(B, k, float("nan"), left, time.perf_counter() - start, ambient)
        if left < tolerance:
            break


def run_solver(name: str, F: np.ndarray | None, rho: np.ndarray, E: np.ndarray,
               iterations: int = 200, tolerance: float = 1e-4,
               row: Callable[[int], np.ndarray] | None = None,
               areas: np.ndarray | None = None) -> Iterator[Step]:
    """The named solver's steps (``F`` for gathering; ``row`` and ``areas`` for shooting).

    A system without a bounded solution is refused first (:func:`check_solvable`) when F is
    known.
    """
    if F is not None:
        check_solvable(F, rho)
    if name == "direct":
        return solve_direct(F, rho, E)
    if name == "jacobi":
        return solve_jacobi(F, rho, E, iterations, tolerance)
    if name == "gauss-seidel":
        return solve_gauss_seidel(F, rho, E, iterations, tolerance)
    if name == "progressive":
        if row is None:
            row = F.__getitem__
        return solve_progressive(row, areas, rho, E, max(iterations, 1) * max(len(E), 1),
                                 tolerance)
    raise ShadeLabError(f"--solver '{name}': expected one of {', '.join(SOLVERS)}")


def new_history() -> dict:
    """Convergence record: one entry per iteration (or shot)."""
    return {"iteration": [], "residual": [], "unshot": [], "time_s": []}


def record(history: dict, step: Step) -> None:
    history["iteration"].append(step.iteration)
    history["residual"].append(step.residual)
    history["unshot"].append(step.unshot)
    history["time_s"].append(step.seconds)


def solve(name: str, F: np.ndarray, rho: np.ndarray, E: np.ndarray, areas: np.ndarray,
          iterations: int = 200, tolerance: float = 1e-4) -> tuple[np.ndarray, dict]:
    """Run a solver to the end; returns the final B (display B for progressive) and history."""
    history, last = new_history(), None
    for last in run_solver(name, F, rho, E, iterations, tolerance, areas=areas):
        record(history, last)
    return last.display_B(rho).copy(), history
