"""NCP beyond the regular patch (issue 29 item 2): the ring around an umbilic.

A dome or hill has a (near-)umbilic at its top, where the principal directions are undefined,
so no B-spline whose parameter lines are curvature lines covers it (the paper, 5.2). Around
the umbilic the curvature lines of such shapes run as closed loops (on a surface of revolution:
the parallels and the meridians). The ring patch is the target reparametrised in (scaled)
polar coordinates about the umbilic: ``u`` the radius from ``inner`` to ``outer``, ``v`` the
angle over ``2 pi (1 - gap)`` - a rectangle in parameters whose rows (``u = const``) are the
loops around the top and whose boundaries are the oculus, the outer rim and the two sides of
the gap. On a surface of revolution its rows are principal lines with ``K`` and ``H`` constant
along each, so ``K - 2 n H + n^2 + t^2 = 0`` holds on every row with ``n = H`` (the net angle
pi/4): it is a PHLW surface as it is (Theorem 2), whatever its profile; elsewhere the PHLW step
moves it to the nearest one. The top (the oculus) and the gap are left out; the coverage of the
net over the whole target says how much.

A CNC net needs one ``n`` inside every sample's ``[kappa_II, kappa_I]``: on a dome the range
shrinks to a point at the umbilic and slides with the radius, so a ring admits CNC only where
those ranges overlap (docs/ncp_domes.md); AA needs K < 0, none on a dome.

Lengths in metres; the frame is the umbilic's: ``e3`` the surface normal there, ``e1`` the
footprint's long direction.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gridshell.core.errors import InputError
from gridshell.geometry.bspline import BSplineSurface, fit_grid

__all__ = ["FITS", "RingPatch", "RingSource", "ring_patch", "umbilic_frame"]

#: the oculus left open on a ring: a disc of this many times the near-umbilic region's area
OCULUS = 1.5
#: the ring's share of the angle left open (the gap between the patch's two sides)
GAP = 0.1
#: the oculus's radius within these shares of the rim's
OCULUS_MIN, OCULUS_MAX = 0.25, 0.45
#: the outer rim this share of the largest (scaled) radius inside the footprint
RIM = 0.97
#: the ring B-splines tried in turn, (control points, samples it is fitted to), each (radius,
#: angle): the PHLW step's principal-angle figure (1 degree) holds on some and not on others
#: of these near-equal fits, so the first that holds is kept; in the order of the nets they
#: gave on a paraboloid dome (coverage 79, 80, 59 % and a failing step)
FITS = (((6, 18), (20, 60)), ((7, 14), (16, 40)), ((7, 20), (20, 60)), ((8, 24), (20, 60)))


@dataclass
class RingPatch:
    """The ring reference (module docstring): ``surface`` (rows ``u`` = loops around the
    top), the target's faces inside the ring ``V, F`` (metres), the frame ``origin`` and
    ``axes (3, 3)`` (rows e1, e2, e3), ``inner`` / ``outer`` radii (m, along e1), ``aspect``
    (the e2 / e1 scale of the loops), ``gap`` (share of the angle), ``share`` (the ring's
    share of the target's area, %), ``fit_rms`` (m)."""

    surface: BSplineSurface
    V: np.ndarray
    F: np.ndarray
    origin: np.ndarray
    axes: np.ndarray
    inner: float
    outer: float
    aspect: float
    gap: float
    share: float
    fit_rms: float

    def record(self) -> dict[str, Any]:
        """What design.json and the summary say about the region designed on."""
        return {"kind": "ring around the umbilic", "centre_m": self.origin.tolist(),
                "axis": self.axes[2].tolist(), "inner_m": self.inner, "outer_m": self.outer,
                "aspect": self.aspect, "gap_deg": 360.0 * self.gap,
                "share_percent": self.share, "fit_rms_m": self.fit_rms}


@dataclass
class RingSource:
    """An NCP source (:func:`gridshell.ncp.source.load_surface`): the PHLW step runs on
    ``patch`` towards its faces; the net's fidelity is measured against the whole target
    ``geo`` (:class:`gridshell.io.read.InputGeometry`); ``result`` the step's outcome when
    the caller has made it (chosen among several fits)."""

    geo: Any
    patch: RingPatch
    result: Any = None          # the PHLW step's PHLWResult on ``patch``, if already made
    notes: list[str] = field(default_factory=list)


def _frame(V: np.ndarray, centre: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Rows e1, e2, e3: e3 the unit normal, e1 the footprint's long direction across it."""
    e3 = normal / np.linalg.norm(normal)
    P = V - centre
    P = P - np.outer(P @ e3, e3)
    _, _, Vt = np.linalg.svd(P - P.mean(0), full_matrices=False)
    e1 = Vt[0] - (Vt[0] @ e3) * e3
    e1 /= np.linalg.norm(e1)
    return np.stack([e1, np.cross(e3, e1), e3])


def _boundary(F: np.ndarray) -> np.ndarray:
    """Indices of the vertices on the mesh's boundary (edges of one face)."""
    E = np.sort(np.stack([F, np.roll(F, -1, axis=1)], -1).reshape(-1, 2), axis=1)
    uniq, count = np.unique(E, axis=0, return_counts=True)
    return np.unique(uniq[count == 1])


def _area(V: np.ndarray, T: np.ndarray) -> np.ndarray:
    return 0.5 * np.linalg.norm(np.cross(V[T[:, 1]] - V[T[:, 0]], V[T[:, 2]] - V[T[:, 0]]),
                                axis=1)


def ring_patch(V: np.ndarray, F: np.ndarray, centre: np.ndarray, normal: np.ndarray, *,
               inner: float, gap: float = GAP, fit: tuple = FITS[0]) -> RingPatch:
    """The ring reference of the target ``V, F`` (metres, triangles or quads) about the
    umbilic at ``centre`` with surface normal ``normal``; ``inner`` the oculus radius (m);
    ``fit`` the B-spline's control points and the samples it is fitted to (radius, angle).
    :class:`InputError` where the target is not a height field over the umbilic's tangent
    plane or the ring would be empty."""
    from scipy.interpolate import LinearNDInterpolator
    from scipy.spatial import ConvexHull

    from gridshell.geometry.igl_adapter import triangulate

    V = np.asarray(V, float)
    tV, T, _ = triangulate(V, np.asarray(F))
    c = np.asarray(centre, float)
    A = _frame(tV, c, np.asarray(normal, float))
    L = (tV - c) @ A.T                                   # local coordinates
    # a height field over the tangent plane: its faces' projections cover the footprint once
    # (their areas add up to no more than the footprint's convex hull), whatever their
    # orientation
    n_loc = np.cross(L[T[:, 1]] - L[T[:, 0]], L[T[:, 2]] - L[T[:, 0]])
    if 0.5 * np.abs(n_loc[:, 2]).sum() > 1.02 * ConvexHull(L[:, :2]).volume:
        raise InputError("the target folds over the tangent plane at its top (not a height "
                         "field there): no ring patch")
    b = _boundary(T)
    xb, yb = L[b, 0], L[b, 1]
    half = np.array([np.abs(xb).max(), np.abs(yb).max()])
    aspect = float(np.clip(half[1] / max(half[0], 1e-12), 0.3, 1.0))
    outer = RIM * float(np.min(np.hypot(xb, yb / aspect)))
    if not outer > 0:
        raise InputError("the ring around the umbilic is empty (the top on the rim)")
    # the oculus at least OCULUS_MIN and at most OCULUS_MAX of the rim's radius: off the
    # umbilic the net's directions exist (n = H lies strictly between the principal
    # curvatures wherever they differ), the loops around it must be its curvature lines
    inner = float(np.clip(inner, OCULUS_MIN * outer, OCULUS_MAX * outer))
    height = LinearNDInterpolator(L[:, :2], L[:, 2])
    (cu, cv), (su, sv) = fit
    rho = np.linspace(inner, outer, su)
    th = np.linspace(0.0, 2 * np.pi * (1 - gap), sv)
    R, Q = np.meshgrid(rho, th, indexing="ij")
    X, Y = R * np.cos(Q), aspect * R * np.sin(Q)
    Z = height(X, Y)
    if not np.all(np.isfinite(Z)):
        raise InputError("the ring around the umbilic leaves the target's footprint")
    P = c + np.stack([X, Y, Z], -1) @ A
    surf, rms = fit_grid(P, cu, cv, 3, 3, params="uniform")
    # the target's faces inside the ring (centroid), the PHLW step's reference
    C = L[T].mean(axis=1)
    r = np.hypot(C[:, 0], C[:, 1] / aspect)
    ang = np.mod(np.arctan2(C[:, 1] / aspect, C[:, 0]), 2 * np.pi)
    keep = (r >= inner) & (r <= outer) & (ang <= 2 * np.pi * (1 - gap))
    if keep.sum() < 8:
        raise InputError("the ring around the umbilic holds too few faces of the target")
    used, Tr = np.unique(T[keep], return_inverse=True)
    share = float(100.0 * _area(tV, T[keep]).sum() / _area(tV, T).sum())
    return RingPatch(surface=surf, V=tV[used], F=Tr.reshape(-1, 3), origin=c, axes=A,
                     inner=float(inner), outer=outer, aspect=aspect, gap=float(gap),
                     share=share, fit_rms=float(rms))


def umbilic_frame(V: np.ndarray, F: np.ndarray, centre: np.ndarray | None, share: float
                  ) -> tuple[np.ndarray, np.ndarray, float]:
    """``(centre, normal, oculus radius)`` of the ring about a target's near-umbilic region
    (``centre`` (3,) m, ``share`` of the target's area): the centre moved onto the target
    ``V, F``, the target's normal there, the radius of a disc :data:`OCULUS` times the
    region's area (m; :func:`ring_patch` keeps it within its bounds); ``centre`` None: the
    crest (the point farthest from the target's mean plane) and radius 0."""
    from gridshell.geometry.igl_adapter import closest_points, triangulate

    tV, T, _ = triangulate(np.asarray(V, float), F)
    N = np.cross(tV[T[:, 1]] - tV[T[:, 0]], tV[T[:, 2]] - tV[T[:, 0]])   # 2 x area normals
    area = 0.5 * np.linalg.norm(N, axis=1).sum()
    if centre is None:     # a crest without a near-umbilic region (a bump): its highest point
        n = N.sum(axis=0)
        n = n / (np.linalg.norm(n) or 1.0)
        h = (tV - tV.mean(axis=0)) @ n
        centre, share = tV[int(np.argmax(np.abs(h)) if abs(h.min()) > h.max()
                               else np.argmax(h))], 0.0
    _, _, C = closest_points(np.asarray([centre], float), tV, T)
    inner = float(np.sqrt(OCULUS * share * area / np.pi))
    # the normal: the area-weighted mean over the faces within the oculus (one face at the
    # apex of a fan is tilted)
    near = np.linalg.norm(tV[T].mean(axis=1) - C[0], axis=1) <= max(inner, 1e-9)
    normal = N[near].sum(axis=0) if near.any() else N.sum(axis=0)
    return np.asarray(C[0], float), normal, inner
