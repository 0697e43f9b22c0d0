"""Random touch-pose generators for the tcpcal tests and ``tests/bench/bench_solver.py``.

Touch poses are built from the forward model (4P-1) ``R_i t + f_i = r (+ noise)``: pick the
flange rotation ``R_i``, then ``f_i = r - R_i t + eps_i``. Units: whatever the caller uses
(mm in the tests); angles in degrees.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

# Tool pointing down: flange Z along WORLD -Z (a rotation of 180 deg about WORLD Y).
R_DOWN = Rotation.from_euler("y", 180.0, degrees=True)


def random_rotations(rng: np.random.Generator, n: int) -> np.ndarray:
    """(n, 3, 3) rotations uniform on SO(3)."""
    return Rotation.random(n, random_state=rng).as_matrix()


def tilted_rotations(
    rng: np.random.Generator,
    n: int,
    tilt_deg: tuple[float, float] = (20.0, 50.0),
    base: Rotation = R_DOWN,
) -> np.ndarray:
    """(n, 3, 3) flange rotations tilted from ``base`` by an angle uniform in ``tilt_deg`` about a
    horizontal WORLD axis of uniform azimuth, with a uniform spin about the flange Z axis.

    Touch i is then a typical pendant touch: the tool leans ``tilt`` degrees away from the
    vertical, in a random direction, turned about its own axis.
    """
    az = rng.uniform(0.0, 2.0 * np.pi, n)
    tilt = np.radians(rng.uniform(tilt_deg[0], tilt_deg[1], n))
    axes = np.stack([np.cos(az), np.sin(az), np.zeros(n)], axis=1)
    lean = Rotation.from_rotvec(axes * tilt[:, None])
    spin = Rotation.from_euler("z", rng.uniform(-180.0, 180.0, (n, 1)), degrees=True)
    return (lean * base * spin).as_matrix()


def random_tcp(rng: np.random.Generator, length: float | tuple[float, float] = (10.0, 500.0)) -> np.ndarray:
    """A TCP vector (FLANGE) of length ``length`` (or uniform in the range) in a random direction."""
    if isinstance(length, tuple):
        length = float(rng.uniform(*length))
    v = rng.standard_normal(3)
    return length * v / np.linalg.norm(v)


def touch_positions(
    rotations: np.ndarray,
    tcp: np.ndarray,
    reference: np.ndarray,
    rng: np.random.Generator | None = None,
    sigma: float = 0.0,
) -> np.ndarray:
    """Flange positions ``f_i = r - R_i t + eps_i`` (eps isotropic Gaussian, ``sigma`` per axis):
    the tip misses the reference by ``eps_i`` (methods.md (4P-1))."""
    f = reference[None, :] - np.einsum("nij,j->ni", rotations, tcp)
    if sigma:
        assert rng is not None
        f = f + sigma * rng.standard_normal(f.shape)
    return f


def make_touches(
    rng: np.random.Generator,
    n: int,
    *,
    tilt_deg: tuple[float, float] = (20.0, 50.0),
    tcp: np.ndarray | None = None,
    reference: np.ndarray | None = None,
    sigma: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(rotations, positions, tcp, reference)`` for n tilted touches of one reference point."""
    tcp = random_tcp(rng) if tcp is None else np.asarray(tcp, dtype=float)
    reference = rng.uniform(-800.0, 800.0, 3) + np.array([0.0, 0.0, 400.0]) if reference is None else np.asarray(reference, dtype=float)
    rot = tilted_rotations(rng, n, tilt_deg)
    return rot, touch_positions(rot, tcp, reference, rng, sigma), tcp, reference


def stacked_a(rotations: np.ndarray) -> np.ndarray:
    """The explicit 3N x 6 matrix of (4P-3): rows ``[R_i, -I]`` (for independent checks)."""
    n = rotations.shape[0]
    a = np.zeros((3 * n, 6))
    for i in range(n):
        a[3 * i : 3 * i + 3, :3] = rotations[i]
        a[3 * i : 3 * i + 3, 3:] = -np.eye(3)
    return a


def crb_tcp(rotations: np.ndarray, sigma: float) -> np.ndarray:
    """Cramer-Rao bound of the TCP (methods.md section 7): top-left 3x3 block of
    ``sigma^2 (A^T A)^-1`` with A built explicitly."""
    a = stacked_a(rotations)
    return sigma**2 * np.linalg.inv(a.T @ a)[:3, :3]
