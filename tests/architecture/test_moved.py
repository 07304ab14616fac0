"""Old module paths of the flat layout still import, for one release, with a warning naming the
new path (gridshell.core.moved)."""
import subprocess
import sys

import pytest

from gridshell.core.moved import MOVED


def test_every_new_path_exists():
    import importlib

    for new in sorted(set(MOVED.values())):
        importlib.import_module(new)


@pytest.mark.parametrize("old", ["gridshell.bspline", "gridshell.io.units", "gridshell.ncp.phlw_terms",
                                 "fabrication.nesting", "gridshell.export.units"])
def test_an_old_path_is_the_new_module_with_a_warning(old):
    code = (f"import warnings, importlib\nwarnings.simplefilter('always')\n"
            f"with warnings.catch_warnings(record=True) as w:\n"
            f"    m = importlib.import_module({old!r})\n"
            f"assert m is importlib.import_module({MOVED[old]!r}), m\n"
            f"assert any({MOVED[old]!r} in str(x.message) and x.category is DeprecationWarning "
            f"for x in w), [str(x.message) for x in w]\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)


def test_the_old_top_level_fabrication_package_still_cuts():
    code = ("import warnings\nwarnings.simplefilter('ignore')\nimport fabrication\n"
            "from gridshell.fabrication.pipeline import fabricate\n"
            "assert fabrication.fabricate is fabricate and fabrication.FabParams().width > 0\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)
