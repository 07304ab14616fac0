"""Small synthetic design bundles for the render, report and export tests.

A 4 x 4 net of joints on the paraboloid patch ``z = 0.3 (x^2 + y^2)``, ``|x|, |y| <= 1``:
rows are family C^1, columns family C^3, each lamella axis a dense polyline on the surface
through its joints. The aligned configuration puts every joint on the x axis at its arc length
along its row (degenerate faces, as a real collapse gives). Metrics are made up.
"""
from __future__ import annotations

import numpy as np

from gridshell.design.bundle import DesignBundle, write_bundle
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.net import Lamella, Net, polyline_arclength
from gridshell.geometry.meshfile import write_mesh

N = 4  # joints per lamella
DENSE = 7  # axis points per joint-to-joint segment


def paraboloid(x, y):
    return np.stack([x, y, 0.3 * (x * x + y * y)], axis=-1)


def make_net() -> Net:
    t = np.linspace(-1.0, 1.0, N)
    X, Y = np.meshgrid(t, t, indexing="ij")
    J = paraboloid(X, Y).reshape(-1, 3)
    G = np.arange(N * N).reshape(N, N)
    d = np.linspace(-1.0, 1.0, (N - 1) * DENSE + 1)
    lams = []
    for i in range(N):  # rows: x fixed, y runs -> family 1
        axis = paraboloid(np.full_like(d, t[i]), d)
        s = polyline_arclength(axis)[::DENSE]
        lams.append(Lamella(id=i, family=1, joints=G[i], joint_s=s, axis=axis))
    for j in range(N):  # columns: y fixed, x runs -> family 3
        axis = paraboloid(d, np.full_like(d, t[j]))
        s = polyline_arclength(axis)[::DENSE]
        lams.append(Lamella(id=N + j, family=3, joints=G[:, j], joint_s=s, axis=axis))
    return Net(joints=J, loops=grid_quads(N, N), lamellae=lams)


def make_surface(n: int = 9) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(-1.1, 1.1, n)
    X, Y = np.meshgrid(t, t, indexing="ij")
    return paraboloid(X, Y).reshape(-1, 3), grid_quads(n, n)


def make_bundle(kind: str = "GG", metrics: dict | None = None) -> DesignBundle:
    net = make_net()
    V, F = make_surface()
    aligned = np.zeros_like(net.joints)
    for lam in net.family(1):
        aligned[lam.joints, 0] = lam.joint_s
    if metrics is None:
        metrics = ({"alignability": {"mean": 0.42, "max": 1.7},
                    "alignability_arc": {"mean": 0.05, "max": 0.2},
                    "geodesic_turning": 3.5} if kind == "GG" else
                   {"delta_a_before": {"mean": 6.0, "max": 17.0},
                    "delta_a_after": {"mean": 0.3, "max": 0.9},
                    "delta_l": {"mean": 0.2, "max": 1.5},
                    "delta_n": {"mean": 0.1, "max": 0.4}})
    return DesignBundle(kind=kind, net=net, aligned=aligned, surface_V=V, surface_F=F,
                        metrics=metrics, params={"n_lamellae": N, "spacing": 0.66,
                                                 "nested": {"a": 1, "b": [1, 2, 3]}})


def sequence_extra(bundle: DesignBundle, frames: int = 3) -> dict:
    """``extra`` entries of an alignment sequence from the net to the aligned joints."""
    out = {}
    for k, a in enumerate(np.linspace(0.0, 1.0, frames)):
        V = (1 - a) * bundle.net.joints + a * bundle.aligned
        out[f"sequence/frame_{k:03d}.obj"] = (lambda p, V=V: write_mesh(p, V, bundle.net.loops))
    return out


def write_case(path, kind: str = "GG", sequence: bool = False, extra: dict | None = None,
               metrics: dict | None = None):
    b = make_bundle(kind, metrics)
    ex = dict(extra or {})
    if sequence:
        ex.update(sequence_extra(b))
    return write_bundle(path, b, extra=ex)


def states_case():
    """A 4 x 4 joint grid of a dome shrinking onto a line: deployed, half-way, collapsed."""
    from gridshell.geometry.grid import grid_quads

    t = np.linspace(-1.0, 1.0, 4)
    X, Y = np.meshgrid(t, t, indexing="ij")
    V0 = np.stack([X, Y, 0.3 * (2 - X * X - Y * Y)], -1).reshape(-1, 3)
    V2 = np.stack([X.ravel() + Y.ravel() + 3, np.zeros(16), np.zeros(16)], 1)
    G = np.arange(16).reshape(4, 4)
    E = np.concatenate([np.stack([G[:, :-1].ravel(), G[:, 1:].ravel()], 1),
                        np.stack([G[:-1].ravel(), G[1:].ravel()], 1)])
    fam = np.repeat([1, 3], len(E) // 2)
    return [V0, 0.5 * (V0 + V2), V2], E, fam, grid_quads(4, 4)
