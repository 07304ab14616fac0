"""Synthetic design bundles for the fabrication tests (built here, not read from files).

A ``nr x nc`` joint grid on the saddle ``z = c (x^2 - y^2)``; rows are family 1, columns
family 3, axes are dense polylines on the saddle through the joints, and ``joint_s`` their
arc length at the joints (so the design is self-consistent). Collapse curves: a circle of
radius ``R`` (CNC) or the parabola ``y = a x^2`` (NCP).
"""
from __future__ import annotations

import numpy as np

from gridshell.bundle import CollapseCurve, DesignBundle
from gridshell.grid import grid_quads
from gridshell.net import Lamella, Net, polyline_arclength

PARABOLA_A = 0.6


def _coords(n, a, stretch):
    j = np.arange(n, dtype=float)
    return a * (j + stretch * j ** 2)


def saddle_net(nr=4, nc=5, a=0.25, stretch=0.15, c=0.2, dense=12):
    x, y = _coords(nc, a, stretch), _coords(nr, a, stretch)
    z = lambda X, Y: c * (X ** 2 - Y ** 2)  # noqa: E731
    X, Y = np.meshgrid(x, y)
    V = np.stack([X.ravel(), Y.ravel(), z(X, Y).ravel()], 1)
    G = np.arange(nr * nc).reshape(nr, nc)
    lams = []

    def lamella(lid, fam, joints, ts, fixed, along_x):
        t = np.concatenate([np.linspace(ts[k], ts[k + 1], dense, endpoint=False)
                            for k in range(len(ts) - 1)] + [ts[-1:]])
        P = (np.stack([t, np.full_like(t, fixed), z(t, fixed)], 1) if along_x
             else np.stack([np.full_like(t, fixed), t, z(fixed, t)], 1))
        s = polyline_arclength(P)
        return Lamella(lid, fam, joints, s[::dense], P)

    for i in range(nr):
        lams.append(lamella(i, 1, G[i], x, y[i], True))
    for j in range(nc):
        lams.append(lamella(nr + j, 3, G[:, j], y, x[j], False))
    return Net(V, grid_quads(nr, nc), lams)


def circle_collapse(R):
    t = np.linspace(0, 2.5, 200)
    P = R * np.stack([np.sin(t), 1 - np.cos(t)], 1)
    Nrm = np.stack([-np.sin(t), np.cos(t)], 1)          # towards the centre
    return CollapseCurve(P, Nrm, shape="circle", radius=R)


def parabola_points(x):
    return np.stack([x, PARABOLA_A * x ** 2], -1)


def parabola_collapse(k=600):
    x = np.linspace(-1.5, 1.5, k)
    P = parabola_points(x)
    T = np.stack([np.ones_like(x), 2 * PARABOLA_A * x], 1)
    T /= np.linalg.norm(T, axis=1, keepdims=True)
    return CollapseCurve(P, np.stack([-T[:, 1], T[:, 0]], 1), shape="curve")


def parabola_at(c):
    """Points of y = a x^2 at arc lengths ``c`` from x = -1.5 (numerical inversion)."""
    x = np.linspace(-1.5, 1.5, 400001)
    seg = np.sqrt(1 + (2 * PARABOLA_A * 0.5 * (x[1:] + x[:-1])) ** 2) * np.diff(x)
    s = np.concatenate([[0], np.cumsum(seg)])
    return parabola_points(np.interp(c, s, x))


def make_bundle(kind="GG", R=1.0, collapse_offset=0.4, **net_kw):
    net = saddle_net(**net_kw)
    collapse = collapse_s = None
    metrics = {}
    if kind == "CNC":
        collapse = circle_collapse(R)
        metrics["n"] = 1.0 / R
    if kind == "NCP":
        collapse = parabola_collapse()
        collapse_s = {lam.id: lam.joint_s + collapse_offset for lam in net.lamellae}
    return DesignBundle(kind=kind, net=net, aligned=net.joints, surface_V=net.joints,
                        surface_F=net.loops, metrics=metrics, collapse=collapse,
                        collapse_s=collapse_s)


def read_dxf_sheet(path):
    """Re-read a written sheet: audit it and return its parts.

    Returns ``doc`` and a list of parts ``{"poly": shapely Polygon, "holes": (k,2),
    "radii": (k,), "scores": [(2,2)], "engrave": [(p,2)], "entity": outline entity}``; holes,
    score lines and strokes are assigned to the outline that contains them.
    """
    import ezdxf.path
    import shapely
    from ezdxf import recover

    doc, auditor = recover.readfile(str(path))
    assert not auditor.has_errors, auditor.errors
    audit = doc.audit()
    assert not audit.has_errors, audit.errors
    outlines, circles, lines, strokes = [], [], [], []
    for e in doc.modelspace():
        layer = e.dxf.layer
        if e.dxftype() == "CIRCLE":
            assert layer == "CUT"
            circles.append((np.array(e.dxf.center)[:2], e.dxf.radius))
        elif e.dxftype() == "LINE":
            assert layer == "SCORE"
            lines.append(np.array([e.dxf.start, e.dxf.end])[:, :2])
        elif e.dxftype() in ("LWPOLYLINE", "POLYLINE"):
            pts = np.array([tuple(v)[:2] for v in ezdxf.path.make_path(e).flattening(0.005)])
            if layer == "CUT":
                assert e.is_closed
                outlines.append((shapely.Polygon(pts), e))
            else:
                assert layer == "ENGRAVE"
                strokes.append(pts)
        else:
            raise AssertionError(f"unexpected entity {e.dxftype()}")
    parts = [{"poly": P, "entity": e, "holes": [], "radii": [], "scores": [], "engrave": []}
             for P, e in outlines]

    def owner(X):
        hits = [p for p in parts if p["poly"].contains(shapely.MultiPoint(X))]
        assert len(hits) == 1
        return hits[0]

    for c, r in circles:
        p = owner(c[None])
        p["holes"].append(c)
        p["radii"].append(r)
    for L in lines:
        owner(L.mean(axis=0)[None])["scores"].append(L)
    for S in strokes:
        owner(S)["engrave"].append(S)
    for p in parts:
        p["holes"] = np.array(p["holes"]).reshape(-1, 2)
        p["radii"] = np.array(p["radii"])
    return doc, parts


def fit_circle(P):
    """Centre ``(2,)`` and radius of the least-squares circle through points ``P (k,2)``."""
    A = np.column_stack([2 * P, np.ones(len(P))])
    b = (P ** 2).sum(1)
    x = np.linalg.lstsq(A, b, rcond=None)[0]
    return x[:2], float(np.sqrt(x[2] + x[:2] @ x[:2]))
