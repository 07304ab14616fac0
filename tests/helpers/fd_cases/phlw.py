"""FD cases of the PHLW surface-design terms (gridshell.ncp.phlw.terms, paper 4.2.1).

A small bi-cubic B-spline (5 x 4 control points, 3 x 4 samples) with random control points
and random auxiliary variables near their consistent values, so every product term is active;
one case per mode (phlw, cnc, aa) for every term over the mode-dependent layout.
"""
import numpy as np

from gridshell.geometry.bspline import BSplineSurface, uniform_params
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

CASES = {f"gridshell.ncp.phlw.terms.{name}[{mode}]": _case(mode)
         for name in MODE_TERMS for mode in P.MODES}
# sample_gliding reads only the control points, at the same place in every mode
CASES["gridshell.ncp.phlw.terms.sample_gliding"] = _gliding


def _guard(mode):
    def make(rng):
        lay, x, data = _setup(rng, mode)
        # floors at half or twice |X| (+ 0.01): about half the hinges active, none near its kink
        lo = {nm: np.abs(lay.view(x, nm)) * rng.choice([0.5, 2.0], size=lay.view(x, nm).shape)
              + 0.01 for nm in ("E", "G", "w")}
        return lay, x, P.Regularity(lo["E"], lo["G"], lo["w"])
    return make


for _mode in P.MODES:
    CASES[f"gridshell.ncp.phlw.terms.parametrization_guard[{_mode}]"] = _guard(_mode)


def _umbilic(mode):
    def make(rng):
        lay, x, data = _setup(rng, mode)
        H, K = lay.view(x, "H"), lay.view(x, "K")
        # margins at half or twice H^2 - K (+ 0.01): both sides of the hinge, away from its kink
        r2 = np.abs(H * H - K) * rng.choice([0.5, 2.0], size=H.shape) + 0.01
        return lay, x, P.UmbilicMargin(r2)
    return make


for _mode in P.MODES:
    CASES[f"gridshell.ncp.phlw.terms.umbilic_guard[{_mode}]"] = _umbilic(_mode)


def _inward(rng):
    lay, x, data = _gliding(rng)
    # foot points shifted along the normals so that about half the samples are inside
    S = np.asarray(data.A @ lay.view(x, "C"))
    shift = rng.choice([-0.2, 0.2], size=len(S))[:, None] * data.normal
    return lay, x, P.SampleGliding(data.A, S + shift, data.normal)


CASES["gridshell.ncp.phlw.terms.boundary_inward"] = _inward
