# Makes the sample meshes of samples/ from their closed forms (metres), and the copies of the
# demo inputs in gridshell/data/ (package data of `gridshell demo`).
#
#     .venv/bin/python samples/make_meshes.py    # rewrites samples/*.obj, gridshell/data/*.obj
#
# Deterministic: running it again gives byte-identical files (tests/architecture/test_samples.py checks that
# the committed files are what this script makes). What each mesh is: samples/README.md.
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from gridshell.core.atomic import write_text
from gridshell.geometry.grid import grid_quads

HERE = Path(__file__).resolve().parent
DATA = HERE.parent / "gridshell" / "data"
#: meshes the demo uses; written to samples/ and, as copies, to gridshell/data/
DEMO = ("dome.obj", "torus_patch.obj")


def _grid(R: int, C: int, f) -> np.ndarray:
    """``P (R, C, 3)`` of ``f(a, b)`` over the unit square, ``a`` along the rows."""
    a, b = np.meshgrid(np.linspace(0.0, 1.0, R), np.linspace(0.0, 1.0, C), indexing="ij")
    return np.stack(f(a, b), axis=-1)


def dome(nx: int = 21, ny: int = 17) -> tuple[np.ndarray, np.ndarray]:
    """Freeform dome over a 3.2 m x 2.4 m rectangle, crown at z = 0.9 m, as a triangle mesh.

    ``z = h (1 - 0.55 u^2 - 0.45 v^2 + 0.12 sin(1.3 u + 0.4) v - 0.08 u^3)`` with
    ``u = x / 1.6``, ``v = y / 1.2``; each grid cell split into two triangles, diagonals
    alternating. Not isometric to a surface of revolution: a GG target with no exact net.
    """
    a, b, h = 1.6, 1.2, 0.9
    P = _grid(nx, ny, lambda s, t: ((2 * s - 1) * a, (2 * t - 1) * b, 0 * s))
    u, v = P[..., 0] / a, P[..., 1] / b
    P[..., 2] = h * (1 - 0.55 * u**2 - 0.45 * v**2 + 0.12 * np.sin(1.3 * u + 0.4) * v
                     - 0.08 * u**3)
    Q = grid_quads(nx, ny)
    i = np.arange(len(Q)) // (ny - 1)
    j = np.arange(len(Q)) % (ny - 1)
    even = (i + j) % 2 == 0
    T = np.concatenate([np.where(even[:, None], Q[:, [0, 1, 2]], Q[:, [0, 1, 3]]),
                        np.where(even[:, None], Q[:, [0, 2, 3]], Q[:, [1, 2, 3]])])
    return P.reshape(-1, 3), T


def helicoid(n: int = 25, c: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Helicoid ``(u cos v, u sin v, c v)``, ``u`` in [-1, 1], ``v`` in [0, 2], as an
    ``n x n`` quad grid: rows ``u = const`` (helices), columns ``v = const`` (rulings).

    Isometric to the catenoid ``r = sqrt(c^2 + s^2)``: an exact GG target; the rulings (grid
    columns, ``--meridians cols``) map to its meridians.
    """
    U, W = np.meshgrid(np.linspace(-1.0, 1.0, n), np.linspace(0.0, 2.0, n), indexing="ij")
    P = np.stack([U * np.cos(W), U * np.sin(W), c * W], axis=-1)
    return P.reshape(-1, 3), grid_quads(n, n)


def saddle(n: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """Saddle ``z = 0.3 (x^2 - y^2)`` over [-1, 1]^2 as an ``n x n`` quad grid, rows along x.

    The reference of ``tests/helpers/data/phlw_saddle_surface.json`` (``gridshell phlw saddle.obj
    --mode phlw``): not PHLW itself, the PHLW step moves it to the nearest PHLW surface.
    """
    x, y = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-1, 1, n), indexing="ij")
    P = np.stack([x, y, 0.3 * (x**2 - y**2)], axis=-1)
    return P.reshape(-1, 3), grid_quads(n, n)


def pseudosphere(n: int = 20, k: float = 2.5) -> tuple[np.ndarray, np.ndarray]:
    """A canopy cut from the pseudosphere of radius ``k`` (K = -1/k^2), axis along x:
    ``k (s - tanh s, sech s sin p, sech s cos p)``, ``s`` in [0.5, 1.5], ``p`` in
    [-0.75, 0.75]; ``n x n`` quad grid, rows ``s = const`` (the parallels, principal lines).

    A PK surface (constant negative Gaussian curvature): asymptotic (AA) nets, collapsing
    into a straight line, exist on it exactly.
    """
    s, p = np.meshgrid(np.linspace(0.5, 1.5, n), np.linspace(-0.75, 0.75, n), indexing="ij")
    P = k * np.stack([s - np.tanh(s), np.sin(p) / np.cosh(s), np.cos(p) / np.cosh(s)], -1)
    P[..., 2] -= P[..., 2].min()
    return P.reshape(-1, 3), grid_quads(n, n)


def torus_patch(n: int = 20, R: float = 3.0, r: float = 1.5) -> tuple[np.ndarray, np.ndarray]:
    """A pavilion vault cut from the outer zone of a torus (R = 3 m, r = 1.5 m), its axis
    horizontal (y): ``(rho sin phi, r sin theta, rho cos phi)``, ``rho = R + r cos theta``,
    ``theta`` in [-0.9, 0.9], ``phi`` in [-0.35, 0.35]; ``n x n`` quad grid, rows
    ``theta = const`` (parallels, principal lines); base moved to z = 0.

    A surface of revolution: ``K - 2 n H + n^2`` is constant on every parallel, so any
    constant normal curvature ``n`` between the principal curvatures gives a CNC net
    collapsing into a circle of radius ``1/n``.
    """
    th, ph = np.meshgrid(np.linspace(-0.9, 0.9, n), np.linspace(-0.35, 0.35, n), indexing="ij")
    rho = R + r * np.cos(th)
    P = np.stack([rho * np.sin(ph), r * np.sin(th), rho * np.cos(ph)], axis=-1)
    P[..., 2] -= P[..., 2].min()
    return P.reshape(-1, 3), grid_quads(n, n)


MESHES = {
    "dome.obj": dome,
    "helicoid.obj": helicoid,
    "saddle.obj": saddle,
    "pseudosphere.obj": pseudosphere,
    "torus_patch.obj": torus_patch,
}


def obj_text(name: str) -> str:
    """The OBJ text of sample ``name``: a comment naming its origin, 12-digit coordinates."""
    V, F = MESHES[name]()
    doc = (MESHES[name].__doc__ or "").strip().splitlines()[0]
    head = (f"# {name}: {doc}\n# made by samples/make_meshes.py ({MESHES[name].__name__}); "
            f"metres; {len(V)} vertices, {len(F)} faces\n")
    v = "".join(f"v {x:.12g} {y:.12g} {z:.12g}\n" for x, y, z in V.tolist())
    f = "".join("f " + " ".join(str(i + 1) for i in row) + "\n" for row in F.tolist())
    return head + v + f


def main(argv: list[str] | None = None) -> int:
    for name in MESHES:
        text = obj_text(name)
        write_text(HERE / name, text)
        if name in DEMO:
            write_text(DATA / name, text)
        print(f"{name}: {len(text) / 1024:.0f} KB")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
