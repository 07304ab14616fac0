"""FD cases of the NCP terms: level functions (gridshell.ncp.levelset, eqs. 4.12-4.13) and the
joint-mesh constraints of post-optimization and alignment (gridshell.ncp.postopt, paper 4.2.4).

Random small configurations; deployed blocks are 3D and aligned blocks 2D so that mixed
dimensions are exercised.
"""
import numpy as np
import scipy.sparse as sp

from gridshell.ncp import levelset as LS
from gridshell.ncp import postopt as PO
from gridshell.solver import Layout


def _directional(rng):
    nc, k = 9, 6
    lay = Layout({"pad": 2, "xi": nc})
    Du = sp.random(k, nc, density=0.6, random_state=3, format="csr")
    Dv = sp.random(k, nc, density=0.6, random_state=4, format="csr")
    data = LS.DirectionalDerivative(Du, Dv, rng.normal(size=k), rng.normal(size=k),
                                    rng.normal(size=k))
    return lay, rng.normal(size=lay.size), data


def _mesh_layout(rng, n=5):
    lay = Layout([("V", (n, 3)), ("r", (n, 3)), ("Vt", (n, 2)), ("rt", (n, 2))])
    edges = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [1, 4], [4, 2]])
    return lay, rng.normal(size=lay.size), edges


def _edge_length(rng):
    lay, x, E = _mesh_layout(rng)
    return lay, x, PO.EdgeLength(E)


def _rotation_axis(rng):
    lay, x, E = _mesh_layout(rng)
    j, k = PO.vertex_pairs(E)
    return lay, x, PO.AxisPairs(j, k)


def _unit(rng):
    lay, x, _ = _mesh_layout(rng)
    return lay, x, PO.UnitNorm("rt")


CASES = {
    "gridshell.ncp.levelset.directional_derivative": _directional,
    "gridshell.ncp.postopt.edge_length_eq": _edge_length,
    "gridshell.ncp.postopt.rotation_axis_eq": _rotation_axis,
    "gridshell.ncp.postopt.unit_norm_eq": _unit,
}
