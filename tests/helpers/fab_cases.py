"""Synthetic design bundles for the fabrication tests (built here, not read from files).

A ``nr x nc`` joint grid on the twisted saddle ``z = c (x^2 - y^2) + twist x y``; rows are
family 1, columns family 3, axes are dense polylines on the surface through the joints, and
``joint_s`` their arc length at the joints (so the design is self-consistent). The grid lines
are spaced differently along x and y (``a``, ``stretch`` per axis) and the ``x y`` term tilts
every row and column by a different slope, so no two lamellae share their joint spacings
(with ``twist=0`` all rows are congruent, and so are all columns). Collapse curves: a circle
of radius ``R`` (CNC) or the parabola ``y = a x^2`` (NCP), on which lamella ``i`` starts at
``collapse_offset + collapse_step * i`` (m of arc length).
"""
from __future__ import annotations

import numpy as np

from gridshell.design.bundle import CollapseCurve, DesignBundle
from gridshell.geometry.grid import grid_quads
from gridshell.geometry.net import Lamella, Net, polyline_arclength

PARABOLA_A = 0.6


def _coords(n, a, stretch):
    j = np.arange(n, dtype=float)
    return a * (j + stretch * j ** 2)


def _pair(v):
    return (float(v), float(v)) if np.isscalar(v) else (float(v[0]), float(v[1]))


def saddle_net(nr=4, nc=5, a=(0.25, 0.22), stretch=(0.15, 0.3), c=0.2, twist=0.35, dense=12):
    """Net of ``nr`` rows (ids ``0..nr-1``, family 1) and ``nc`` columns (ids ``nr..``,
    family 3); ``a`` and ``stretch`` are a number or an ``(x, y)`` pair; metres."""
    (ax, ay), (sx, sy) = _pair(a), _pair(stretch)
    x, y = _coords(nc, ax, sx), _coords(nr, ay, sy)
    z = lambda X, Y: c * (X ** 2 - Y ** 2) + twist * X * Y  # noqa: E731
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


def make_bundle(kind="GG", R=1.0, collapse_offset=0.4, collapse_step=0.09, **net_kw):
    """A DesignBundle of ``kind`` on :func:`saddle_net` (``net_kw``); NCP lamella ``i`` lies on
    the parabola from arc length ``collapse_offset + collapse_step * i`` on."""
    net = saddle_net(**net_kw)
    collapse = collapse_s = None
    metrics = {}
    if kind == "CNC":
        collapse = circle_collapse(R)
        metrics["n"] = 1.0 / R
    if kind == "NCP":
        collapse = parabola_collapse()
        collapse_s = {lam.id: lam.joint_s - lam.joint_s[0] + collapse_offset
                      + collapse_step * lam.id for lam in net.lamellae}
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


def parabola_band(u0, u1, half_width, scale=100.0, k=4001):
    """The strip of half width ``half_width`` (mm) around the parabola between arc lengths
    ``u0 < u1`` (m from x = -1.5), as a shapely Polygon in mm (``scale`` mm per m), from the
    analytic curve and its unit normals; the ends are cut along the normals."""
    import shapely

    u = np.linspace(u0, u1, k)
    P = parabola_at(u)
    T = np.stack([np.ones(k), 2 * PARABOLA_A * P[:, 0]], 1)
    T /= np.linalg.norm(T, axis=1, keepdims=True)
    N = np.stack([-T[:, 1], T[:, 0]], 1)
    P = P * scale
    return shapely.Polygon(np.concatenate([P + half_width * N, (P - half_width * N)[::-1]]))


def motion_apply(m, X):
    """Apply a report motion ``{"angle_deg", "dx", "dy"}`` (rotation about the origin, then
    translation) to points ``X (k,2)``."""
    a = np.radians(m["angle_deg"])
    R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    return np.asarray(X, float) @ R.T + np.array([m["dx"], m["dy"]])


def joints_in_strip_coordinates(b, lam, scale=100.0):
    """Where the joints of ``lam`` lie in the strip coordinates of :mod:`gridshell.fabrication.axis`
    (mm), from the design alone: straight strips along +x from the origin; arcs from the
    origin turning left about ``(0, R)``; NCP strips in the collapse curve's own plane, at
    ``collapse_s`` on the analytic parabola."""
    s = lam.joint_s * scale
    if b.kind in ("GG", "AA"):
        return np.column_stack([s, np.zeros_like(s)])
    if b.kind == "CNC":
        R = b.collapse.radius * scale
        return np.column_stack([R * np.sin(s / R), R * (1 - np.cos(s / R))])
    return parabola_at(b.collapse_s[lam.id]) * scale


def match_pieces(b, rep, sheets, tol=0.05, scale=100.0):
    """Which DXF part is which piece, by the report's ids and placements.

    For every ``rep["pieces"]`` entry (lamella id, piece, sheet, motion), the joints of that
    lamella on that piece are carried from strip coordinates to the sheet by its motion; the
    part of that sheet whose holes all lie within ``tol`` mm of them (in order) is the piece.
    Returns ``{(lamella, piece): (part, expected (k,2))}``; asserts a one-to-one match.
    """
    lams = {int(lam.id): lam for lam in b.net.lamellae}
    out, used = {}, set()
    for pc in rep["pieces"]:
        lam = lams[pc["lamella"]]
        js = lam.joint_s * scale
        on = (js >= pc["s0"] - 1e-6) & (js <= pc["s0"] + pc["flat_length_mm"] + 1e-6)
        expect = motion_apply(pc["motion"], joints_in_strip_coordinates(b, lam, scale)[on])
        k = pc["sheet"] - 1
        hits = [i for i, p in enumerate(sheets[k][1]) if p["holes"].shape == expect.shape
                and np.max(np.linalg.norm(p["holes"] - expect, axis=1)) <= tol]
        assert len(hits) == 1, (f"lamella {lam.id} piece {pc['piece']}: {len(hits)} parts of "
                                f"sheet {k + 1} have its holes where the report places them")
        assert (k, hits[0]) not in used
        used.add((k, hits[0]))
        out[(pc["lamella"], pc["piece"])] = (sheets[k][1][hits[0]], expect)
    assert len(used) == sum(len(ps) for _, ps in sheets)
    return out


def read_cutlist(path):
    """Rows of ``cutlist.csv`` keyed by ``(lamella, piece)``; joint positions as arrays."""
    import csv

    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    out = {}
    for r in rows:
        r["joint_positions_mm"] = np.array(r["joint_positions_mm"].split(), float)
        out[(int(r["lamella"]), int(r["piece"].split("/")[0]))] = r
    return out


def similarity_fit(P, Q):
    """Least-squares ``Q ~ s R P + t`` over rotations and reflections ``R`` (Umeyama);
    returns the fitted ``P`` and the residuals ``(k,)``."""
    pc, qc = P.mean(0), Q.mean(0)
    A, B = P - pc, Q - qc
    U, S, Vt = np.linalg.svd(B.T @ A)
    R = U @ Vt
    s = S.sum() / (A ** 2).sum()
    F = s * A @ R.T + qc
    return F, np.linalg.norm(F - Q, axis=1)


def plan_labels(path):
    """``{lamella id: (x, y)}`` anchor of each id label in ``plan.svg`` (SVG units, y down),
    read with ElementTree from the ``<g id="lamella-ID">`` groups."""
    import xml.etree.ElementTree as ET

    ns = "{http://www.w3.org/2000/svg}"
    out = {}
    for g in ET.parse(path).getroot().iter(f"{ns}g"):
        gid = g.get("id", "")
        if gid.startswith("lamella-"):
            texts = list(g.iter(f"{ns}text"))
            assert len(texts) == 1 and texts[0].text == gid.split("-", 1)[1], gid
            out[int(gid.split("-", 1)[1])] = (float(texts[0].get("x")), float(texts[0].get("y")))
    return out
