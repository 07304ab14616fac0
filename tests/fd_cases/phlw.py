"""FD cases of the PHLW surface-design terms (gridshell.ncp.phlw_terms, paper 4.2.1).

A small bi-cubic B-spline (5 x 4 control points, 3 x 4 samples) with random control points
and random auxiliary variables near their consistent values, so every product term is active;
one case per mode (phlw, cnc, aa) for every term over the mode-dependent layout.
"""
import numpy as np

from gridshell.bspline import BSplineSurface, uniform_params
from gridshell.ncp import phlw as P


def _setup(rng, mode="phlw"):
    u0, v0 = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 4), indexing="ij")
    ctrl = (np.stack([u0, v0, 0.3 * (u0 ** 2 - v0 ** 2)], axis=-1)
            + 0.05 * rng.normal(size=(5, 4, 3)))
    surf = BSplineSurface.from_control_grid(ctrl, 3, 3)
    u, v = uniform_params(surf, (3, 4))
    data = P.make_samples(surf, u, v, mode)
    lay = P.make_layout(surf.n_ctrl, 12, 3, mode)
    aux = P.init_auxiliary(surf.ctrl.reshape(-1, 3), data)
    vals = {"C": surf.ctrl.reshape(-1, 3), **aux, "t": rng.normal(size=3)}
    if mode == "phlw":
        vals["n"] = rng.normal(size=3)
    elif mode == "cnc":
        vals["n"] = rng.normal(size=1)
    x = lay.pack(vals)
    x = x + 0.1 * rng.normal(size=x.size)   # off the constraint manifold
    return lay, x, data


def _case(mode="phlw"):
    def make(rng):
        return _setup(rng, mode)
    return make


def _gliding(rng):
    lay, x, data = _setup(rng)
    k = data.ops["S"].shape[0]
    n = rng.normal(size=(k, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    return lay, x, P.SampleGliding(data.ops["S"], rng.normal(size=(k, 3)), n)


#: terms over the PHLW layout, whose blocks depend on the mode (``n`` per row in phlw, one
#: ``n`` in cnc, none in aa): each is checked in every mode of ``P.MODES``. ``phlw_target``
#: and ``beta_fairness`` also read ``n`` through the mode-dependent ``Samples.n_index``.
MODE_TERMS = ("normal_eq", "first_form_eq", "delta_eq", "sqrt_delta_eq", "second_form_eq",
              "curvature_eq", "principal_eq", "phlw_target", "beta_fairness")

CASES = {f"gridshell.ncp.phlw_terms.{name}[{mode}]": _case(mode)
         for name in MODE_TERMS for mode in P.MODES}
# sample_gliding reads only the control points, at the same place in every mode
CASES["gridshell.ncp.phlw_terms.sample_gliding"] = _gliding
