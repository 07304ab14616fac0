"""The strips of the NCP alignment states (gridshell.structure.heldpath), side by side in one
run: the new ``strips`` stage of ``design_ncp`` (every state's strips at equilibrium between
the kinematic sequence's joints and axes) against the rest of the design, and the structural
check of the states on those strips against the check from the joints alone (the spline
method it replaces), on the demo's CNC torus zone (full size) and the AA pseudosphere.
Prints seconds.

    python benchmarks/ncp_strips.py
"""
from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def _cases():
    from gridshell import data
    from tests.helpers.ncp_cases import pseudosphere

    return (("CNC torus zone", data.path("torus_patch.obj"),
             {"mode": "cnc", "curves": 12, "samples": (48, 48), "frames": 12}),
            ("AA pseudosphere", pseudosphere(), {"mode": "aa", "curves": 10}))


def main() -> None:
    from gridshell.api import write
    from gridshell.ncp.pipeline import design_ncp
    from gridshell.structure.check import check_bundle
    from gridshell.structure.heldpath import held_path
    from gridshell.structure.materials import get_material
    from gridshell.structure.section import Section

    pp, section = get_material("pp"), Section(20.0, 1.0, 0.1)
    print(f"{'case':16s} {'joints':>6s} {'states':>6s} {'design [s]':>10s} {'strips [s]':>10s} "
          f"{'check strips [s]':>16s} {'check joints [s]':>16s}")
    for name, src, opts in _cases():
        t0 = time.perf_counter()
        bundle, report = design_ncp(src, **opts)
        t_design = time.perf_counter() - t0
        seq = report["state"].sequence
        t0 = time.perf_counter()
        held_path(bundle, seq.V, seq.r, seq.t)
        t_strips = time.perf_counter() - t0
        with tempfile.TemporaryDirectory() as tmp:
            out = write(Path(tmp) / "b", (bundle, report), render=False)
            t0 = time.perf_counter()
            check_bundle(bundle, pp, section, bundle_dir=out)
            t_check = time.perf_counter() - t0
            os.remove(out / "sequence" / "strips.npz")
            t0 = time.perf_counter()
            check_bundle(bundle, pp, section, bundle_dir=out)
            t_joints = time.perf_counter() - t0
        print(f"{name:16s} {len(bundle.net.joints):6d} {len(seq.V):6d} {t_design:10.2f} "
              f"{t_strips:10.2f} {t_check:16.2f} {t_joints:16.2f}")


if __name__ == "__main__":
    main()
