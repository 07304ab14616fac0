"""DXF cut files through ezdxf (issue item 5).

R2010 by default, R12 through ezdxf's R12 export (``ezdxf.addons.r12export``); millimetres
(``$INSUNITS = 4``); layers CUT (red, ACI 1), SCORE (blue, ACI 5), ENGRAVE (green, ACI 3; not
ACI 7, which shows white on a dark background) from :mod:`gridshell.fabrication.layers`, each with the
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
import numpy as np
from ezdxf import units

from gridshell.core.atomic import atomic_path

from gridshell.fabrication.layers import LAYERS
from gridshell.fabrication.params import FabParams
from gridshell.fabrication.part import Part


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

    engrave = att("ENGRAVE")
    for p in parts:
        for L in p.engrave:
            add_polyline(msp, L, engrave)
    for p in parts:
        for a, b in p.scores:
            msp.add_line(tuple(a), tuple(b), dxfattribs=att("SCORE"))
    for p in parts:
        for c, r in zip(p.holes, p.radii):
            msp.add_circle(tuple(c), float(r), dxfattribs=att("CUT"))
    outlines = []
    for p in parts:
        path = p.outline.segments(params.tolerance) if params.segments else p.outline
        outlines.append(add_polyline(msp, np.column_stack([path.V, path.B]), att("CUT"),
                                     closed=True))
    set_extents(doc, sheet, outlines, _inner_points(parts))
    return doc


def add_polyline(msp, pts: np.ndarray, dxfattribs: dict, closed: bool = False):
    """An LWPOLYLINE through ``pts`` ``(k,2)`` (or ``(k,3)``: x, y, bulge), mm: the entity
    ``msp.add_lwpolyline(pts.tolist(), format="xy" / "xyb")`` makes, its point array
    (x, y, start width, end width, bulge; float64) filled at once instead of point by point
    (an engraved label is ~10 points, a 192-part plan ~17k labels)."""
    e = msp.add_lwpolyline([], close=closed, dxfattribs=dxfattribs)
    pts = np.asarray(pts, np.float64)
    v = np.zeros((len(pts), 5))
    v[:, :2] = pts[:, :2]
    if pts.shape[1] == 3:
        v[:, 4] = pts[:, 2]
    e.lwpoints.values = v
    return e


def _inner_points(parts: list[Part]) -> np.ndarray:
    """Corner points of everything drawn inside the outlines (engravings, score lines, the
    holes' boxes), ``(k, 2)`` mm."""
    pts = [np.zeros((0, 2))]
    for p in parts:
        pts += [np.asarray(L, float).reshape(-1, 2) for L in p.engrave]
        pts += [np.asarray(ab, float).reshape(-1, 2) for ab in p.scores]
        for c, r in zip(p.holes, p.radii):
            pts.append(np.asarray(c, float).reshape(1, 2) + np.array([[-r, -r], [r, r]]))
    return np.concatenate(pts)


def set_extents(doc, sheet: tuple[float, float], outlines: list | None = None,
                inner: np.ndarray | None = None) -> None:
    """``$EXTMIN`` / ``$EXTMAX`` of ``doc``, mm: the bounding box of the cut ``outlines``
    (ezdxf.bbox, bulge arcs included) and of the ``inner`` points (what is drawn inside them:
    a corner list is exact for polylines, lines and the holes' boxes), or of every modelspace
    entity when ``outlines`` is None; the sheet for an empty drawing. Measuring the outlines
    instead of the ~17k engraved label strokes of a 192-part plan: 5.2 -> 0.1 s."""
    from ezdxf import bbox

    msp = doc.modelspace()
    box = bbox.extents(msp if outlines is None else outlines, fast=False)
    lo = np.array([box.extmin.x, box.extmin.y]) if box.has_data else np.full(2, np.inf)
    hi = np.array([box.extmax.x, box.extmax.y]) if box.has_data else np.full(2, -np.inf)
    if inner is not None and len(inner):
        lo, hi = np.minimum(lo, inner.min(0)), np.maximum(hi, inner.max(0))
    if np.all(np.isfinite(lo)):
        lo, hi = (float(lo[0]), float(lo[1]), 0.0), (float(hi[0]), float(hi[1]), 0.0)
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
