"""A bundle's outputs made in one call: render.png, alignment.gif, report.html and the Rhino
.3dm (``gridshell render --report --3dm``), the .3dm built in a second process meanwhile.

The .3dm model (:func:`gridshell.export.rhino.write_model`) needs nothing the pictures and the
report make, and they need nothing from it, so on Linux it is built in a forked process
(:mod:`gridshell.core.aside`) while this one renders: two cores, one wall clock. The child writes
only a temporary file that this process owns; this process publishes it (the atomic rename and
the bundle's manifest entry, :func:`gridshell.core.atomic.atomic_path`) after its own files, so the
outputs, their order in the manifest and every error are those of the calls one after the
other. If anything here fails, the child is stopped and its temporary file removed: no .3dm
is left half-written. Where a fork is not safe (:func:`gridshell.core.aside.can_fork`) the model is
built in this process at the end.
"""
from __future__ import annotations

import os
from contextlib import ExitStack
from pathlib import Path
from typing import Any, Callable

__all__ = ["write_outputs"]


def write_outputs(bundle: str | os.PathLike, *, png: bool = True, sequence: bool = False,
                  report: bool = False, pdf: bool = False,
                  rhino: str | os.PathLike | None = None,
                  width: float | None = None, size: tuple[int, int] | None = None,
                  rhino_options: dict[str, Any] | None = None,
                  progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Write the outputs of the design bundle directory ``bundle``.

    Parameters
    ----------
    png : bool
        ``render.png`` (:func:`gridshell.render.ribbons.render_bundle`; ``width`` the strip's
        real width in metres, ``size`` the picture in pixels).
    sequence : bool
        ``alignment.gif`` and ``sequence/frame_*.png`` of the bundle's alignment sequence
        (:func:`gridshell.render.sequence.render_bundle_sequence`).
    report : bool
        ``report.html`` (:func:`gridshell.render.report.write_report`), after the pictures.
    pdf : bool
        ``report.pdf`` (:func:`gridshell.render.pdf.pdf_document`: overview, assembly, sheets,
        structure), made in a second process after render.png while this one writes the rest.
    rhino : path-like, optional
        The .3dm file (:func:`gridshell.export.rhino.export_3dm`, with ``rhino_options``: any
        of its keyword arguments but ``progress``; the model is built in another process,
        which prints nothing).
    progress : callable, optional
        Called with a line of text per step.

    Returns
    -------
    dict
        ``render`` (Path or None), ``sequence`` (the sequence renderer's result or None),
        ``report`` and ``pdf`` (Path or None), ``rhino`` (what :func:`~gridshell.export.rhino.export_3dm`
        returns, or None).
    """
    bundle = Path(bundle)
    say = progress or (lambda msg: None)
    out: dict[str, Any] = {"render": None, "sequence": None, "report": None, "pdf": None,
                           "rhino": None}
    with ExitStack() as stack:
        job = None if rhino is None else _rhino_job(stack, bundle, rhino, rhino_options, say)
        if png:
            from gridshell.render.ribbons import render_bundle

            say("rendering render.png")
            kw = {} if size is None else {"size": tuple(size)}
            out["render"] = render_bundle(bundle, width=width, **kw)
        paper = _pdf_job(stack, bundle, say) if pdf else None      # after render.png
        if sequence:
            from gridshell.render.sequence import render_bundle_sequence

            out["sequence"] = render_bundle_sequence(bundle, progress=progress)
        if report:
            from gridshell.render.report import write_report

            say("writing report.html")
            out["report"] = write_report(bundle)
        if paper is not None:
            paper[0].result()
            out["pdf"] = paper[1]
        if job is not None:
            out["rhino"] = dict(job[0].result(), path=str(job[1]))
    return out


def _rhino_job(stack: ExitStack, bundle: Path, rhino: str | os.PathLike,
               options: dict[str, Any] | None, say: Callable[[str], None]) -> tuple[Any, Path]:
    """The .3dm built in a second process into a temporary file that ``stack`` publishes:
    ``(job, path)``."""
    from gridshell.core.aside import Aside, can_fork
    from gridshell.core.atomic import atomic_path
    from gridshell.design.bundle import read_bundle
    from gridshell.export.rhino import check_3dm_path, write_model

    path = check_3dm_path(rhino)
    options = dict(options or {})
    if "progress" in options:
        raise TypeError("write_outputs: rhino_options takes no progress (the model is "
                        "built in another process, which prints nothing)")
    read_bundle(bundle)             # read once, before the fork: both processes have it
    tmp = stack.enter_context(atomic_path(path))
    inside = path.resolve().parent == bundle.resolve()
    say(f"exporting {path.name if inside else path}"
        + (" (in a second process)" if can_fork() else ""))
    return stack.enter_context(Aside(write_model, bundle, tmp, shown=path, **options)), path


def _pdf_job(stack: ExitStack, bundle: Path, say: Callable[[str], None]) -> tuple[Any, Path]:
    """report.pdf made in a second process into a temporary file that ``stack`` publishes:
    ``(job, path)``."""
    from gridshell.core.aside import Aside, can_fork
    from gridshell.core.atomic import atomic_path
    from gridshell.render.pdf import pdf_document

    say("writing report.pdf" + (" (in a second process)" if can_fork() else ""))
    path = bundle / "report.pdf"
    tmp = stack.enter_context(atomic_path(path))
    return stack.enter_context(Aside(pdf_document, bundle, tmp)), path
