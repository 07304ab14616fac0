"""DXF cut files through ezdxf (issue item 5).

R2010 by default, R12 through ezdxf's R12 export (``ezdxf.addons.r12export``); millimetres
(``$INSUNITS = 4``); layers CUT (red, ACI 1), SCORE (blue, ACI 5), ENGRAVE (green, ACI 3; not
ACI 7, which shows white on a dark background) from :mod:`fabrication.layers`, each with the
same colour as a true colour too, and each entity also coloured explicitly (ACI and true
colour) for cutters that read entity colours. ``$EXTMIN`` / ``$EXTMAX`` are the drawing's real
extents in mm (the bounding box of the parts, arcs included). Outlines
are closed LWPOLYLINEs with bulges for arcs (or short segments), holes CIRCLEs, score marks
LINEs, labels open LWPOLYLINEs (never TEXT). Order in the file: ENGRAVE, SCORE, holes, then
outlines - so that inner features are cut while the part still sits in the sheet.
"""
from __future__ import annotations

from pathlib import Path as FsPath

import ezdxf
from ezdxf import units

from gridshell.atomic import atomic_path

from .layers import LAYERS
from .params import FabParams
from .part import Part


def sheet_document(parts: list[Part], sheet: tuple[float, float], params: FabParams):
    """An ezdxf R2010 document of one sheet's parts."""
    doc = ezdxf.new("R2010", setup=False)
    doc.units = units.MM
    doc.header["$MEASUREMENT"] = 1
    for name, (aci, rgb) in LAYERS.items():
        layer = doc.layers.add(name, color=aci)
        layer.rgb = rgb
    msp = doc.modelspace()

    def att(layer):
        aci, rgb = LAYERS[layer]
        return {"layer": layer, "color": aci, "true_color": ezdxf.rgb2int(rgb)}

    for p in parts:
        for L in p.engrave:
            msp.add_lwpolyline(L.tolist(), format="xy", close=False, dxfattribs=att("ENGRAVE"))
    for p in parts:
        for a, b in p.scores:
            msp.add_line(tuple(a), tuple(b), dxfattribs=att("SCORE"))
    for p in parts:
        for c, r in zip(p.holes, p.radii):
            msp.add_circle(tuple(c), float(r), dxfattribs=att("CUT"))
    for p in parts:
        path = p.outline.segments(params.tolerance) if params.segments else p.outline
        pts = [(float(x), float(y), float(b)) for (x, y), b in zip(path.V, path.B)]
        msp.add_lwpolyline(pts, format="xyb", close=True, dxfattribs=att("CUT"))
    set_extents(doc, sheet)
    return doc


def set_extents(doc, sheet: tuple[float, float]) -> None:
    """``$EXTMIN`` / ``$EXTMAX`` of ``doc``: the bounding box of its modelspace entities
    (ezdxf.bbox, bulge arcs included), mm; the sheet for an empty drawing."""
    from ezdxf import bbox

    msp = doc.modelspace()
    box = bbox.extents(msp, fast=False)
    if box.has_data:
        lo = (float(box.extmin.x), float(box.extmin.y), 0.0)
        hi = (float(box.extmax.x), float(box.extmax.y), 0.0)
    else:
        lo, hi = (0.0, 0.0, 0.0), (float(sheet[0]), float(sheet[1]), 0.0)
    doc.header["$EXTMIN"], doc.header["$EXTMAX"] = lo, hi
    msp.dxf.extmin, msp.dxf.extmax = lo, hi      # ezdxf copies these to the header on save


def write_sheet_dxf(path: str | FsPath, parts: list[Part], sheet: tuple[float, float],
                    params: FabParams) -> None:
    """Write one sheet to ``path``, atomically."""
    doc = sheet_document(parts, sheet, params)
    with atomic_path(path) as tmp:
        if params.dxf_version == "R12":
            tmp.write_text(r12_text(doc, params.tolerance), encoding="ascii", errors="replace")
        else:
            doc.saveas(str(tmp))


def r12_text(doc, tolerance: float) -> str:
    """``doc`` as DXF R12 text through ezdxf's R12 export (LWPOLYLINE -> POLYLINE, bulges
    kept). R12 predates ``$INSUNITS``; it is added to the header all the same (readers of
    old files ignore it, current ones take it) together with ``$MEASUREMENT = 1``."""
    import io

    from ezdxf.addons import r12export

    buf = io.StringIO()
    r12export.write(doc, buf, max_sagitta=tolerance)
    text = buf.getvalue()
    key = "$ACADVER\n  1\nAC1009\n"
    if key not in text:  # pragma: no cover - ezdxf changed its R12 header layout
        raise RuntimeError("unexpected R12 header from ezdxf; cannot add $INSUNITS")
    return text.replace(key, key + "  9\n$INSUNITS\n 70\n4\n  9\n$MEASUREMENT\n 70\n1\n", 1)
