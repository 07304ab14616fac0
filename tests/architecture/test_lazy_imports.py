"""``import gridshell.api`` loads no pipeline: each design function imports its own when
called, so ``gridshell gg`` does not load the NCP and PHLW modules, nor ``ncp`` the GG ones
(issue 18, big inputs: the command's start is part of its time)."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PIPELINES = ("gridshell.gg", "gridshell.ncp", "gridshell.fabrication", "scipy.integrate", "pymeshlab")


def _loaded(code: str) -> list[str]:
    """The modules of :data:`PIPELINES` loaded after running ``code`` in a new interpreter."""
    probe = (f"{code}\nimport json, sys\n"
             f"print(json.dumps(sorted(m for m in sys.modules if m.startswith({PIPELINES!r}))))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True, timeout=120)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_the_api_and_the_command_line_load_no_pipeline_until_one_runs():
    assert _loaded("import gridshell.api") == []
    assert _loaded("import gridshell as gs; gs.write, gs.design_gg, gs.optimize_phlw") == []
    assert _loaded("from gridshell.cli.main import build_parser; build_parser(['gg'])") == []


def test_a_design_function_loads_its_own_pipeline_only():
    loaded = _loaded("import gridshell.api as api\n"
                     "try:\n    api.design_gg('missing.obj')\nexcept Exception:\n    pass")
    assert "gridshell.gg.pipeline" in loaded
    assert not any(m.startswith("gridshell.ncp") for m in loaded), loaded


def test_the_export_plans_its_cut_sheets_without_the_dxf_writer():
    """``gridshell export`` reads the fabrication parameters and plans the cut sheets in
    memory: ezdxf (the DXF writer's library) is loaded only by ``fabricate``, which writes."""
    code = ("import sys\n"
            "from tests.helpers.render_cases import make_bundle\n"
            "from gridshell.export.fabparams import export_params, plan_sheets\n"
            "fab, _ = export_params(None)\n"
            "plan_sheets(make_bundle(), fab)\n"
            "from gridshell import fabrication\n"
            "assert 'ezdxf' not in sys.modules, 'ezdxf loaded'\n"
            "for m in ('dxf', 'svg', 'preview', 'plan', 'cutlist'):\n"
            "    assert 'gridshell.fabrication.' + m not in sys.modules, m\n"
            "fabrication.fabricate\n"
            "assert 'ezdxf' not in sys.modules, 'ezdxf loaded by fabrication.fabricate'")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120, cwd=ROOT)
    loaded = _loaded("from gridshell import fabrication\nfabrication.FabParams")
    assert "gridshell.fabrication.params" in loaded and "gridshell.fabrication.pipeline" not in loaded, loaded
