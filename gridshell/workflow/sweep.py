"""A design study on Dask: every variant of a :class:`~gridshell.workflow.study.Study` as one task.

:func:`sweep` designs, verifies, checks and cuts each variant
(:func:`gridshell.workflow.variant.run_variant`) on a ``dask.distributed`` cluster: a
``LocalCluster`` of ``workers`` processes with one thread (and one BLAS thread) each by
default, or a running cluster at ``scheduler`` (``tcp://HOST:8786``: ``dask scheduler`` and
``dask worker`` processes, or one of dask's deployers). The workers write into the study's
directory, so a remote cluster needs it on a shared filesystem.

Layout of ``out``::

    study.json            the study (target, parameters, sampling)
    variants/<key>/       one finished variant: row.json, manifest.json, design/ (the bundle,
                          its structure.json and fabrication/)
    results.parquet       one row per variant (results.csv where pyarrow is absent)
    sweep.html, sweep.png the trade-offs (gridshell.render.sweep_page)
    manifest.json

Resumable and fault tolerant: a variant's key is the content hash of the target, its
parameters and the tool's version; a variant whose ``row.json`` exists is not run again (a
re-run of a finished study designs nothing). A worker that dies mid-task loses that task only:
the scheduler runs it again on another worker (``distributed.scheduler.allowed-failures``);
a variant that fails is a row with its exit code. Ctrl-C stops the study and leaves every
finished variant on disk.
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from gridshell.core.errors import InputError, OutputError
from gridshell.workflow.study import Study, file_sha256, variant_key
from gridshell.workflow.variant import COLUMNS, ROW, run_variant

__all__ = ["SweepResult", "load_results", "open_client", "sweep"]

Progress = Callable[[str], None] | None
VARIANTS = "variants"
STUDY = "study.json"
#: the files a sweep writes at the top of its directory (each replaced only while the
#: directory's manifest lists it unchanged)
OWN = (STUDY, "results.parquet", "results.csv", "sweep.html", "sweep.png")
INSTALL = "pip install 'gridshell[sweep]' (or 'make venv' in a checkout)"


@dataclass(frozen=True)
class SweepResult:
    """What :func:`sweep` did: the results ``table`` (a pandas DataFrame, one row per
    variant), how many variants ran now and how many were already done, the files written."""

    table: Any
    ran: int
    reused: int
    results: Path
    page: Path | None
    seconds: float


def _dask() -> Any:
    try:
        import distributed
        import pandas  # noqa: F401
    except ImportError:
        raise InputError(f"gridshell sweep runs on Dask: {INSTALL}") from None
    return distributed


def _plan(study: Study) -> list[tuple[str, dict[str, Any]]]:
    """``[(key, params)]`` of every variant, in the study's order (duplicates once)."""
    from gridshell.core.version import __version__

    sha = file_sha256(study.target)
    seen: dict[str, dict[str, Any]] = {}
    for params in study.variants():
        seen.setdefault(variant_key(sha, params, __version__, study.units), params)
    return list(seen.items())


def _prepare(study: Study, out: Path) -> Path:
    """``out`` made (refused if it holds another study's variants) and ``study.json`` written;
    returns the variants directory."""
    out.mkdir(parents=True, exist_ok=True)
    sfile = out / STUDY
    if sfile.exists():
        try:
            old = json.loads(sfile.read_text(encoding="utf-8"))
        except ValueError:
            old = None
        if old is None or "parameters" not in old:
            raise OutputError(f"{sfile} is not a study of gridshell sweep; choose another -o")
    elif any(p.name != VARIANTS for p in out.iterdir()):
        raise OutputError(f"{out} holds files that are not a study of gridshell sweep; choose an "
                          "empty or new -o directory (nothing in it is deleted)")
    from gridshell.core.atomic import write_text

    require_own(out)
    write_text(sfile, json.dumps(study.as_dict(), indent=1) + "\n")
    variants = out / VARIANTS
    variants.mkdir(exist_ok=True)
    _manifest(out)  # study.json is the sweep's own from here on
    return variants


def require_own(out: Path) -> None:
    """Refuse (OutputError) when a file the sweep is about to replace is not one it wrote:
    not listed unchanged in ``out``'s manifest (checked again before the table and the page)."""
    from gridshell.core.manifest import unchanged

    for name in OWN:
        if (out / name).exists() and not unchanged(out, name):
            raise OutputError(f"{out / name} was not written by gridshell sweep or changed since; "
                              "move it away or choose another -o (nothing is replaced)")


def _done(variants: Path, key: str) -> dict[str, Any] | None:
    f = variants / key / ROW
    try:
        return json.loads(f.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def open_client(workers: int, scheduler: str | None = None,
                distributed: Any = None) -> tuple[Any, Any]:
    """``(client, cluster)``: a ``dask.distributed`` client of the running cluster at
    ``scheduler``, or of a new LocalCluster of ``workers`` single-threaded processes (cluster
    None for a remote one); close both when done. The one door to Dask of the sweep and the
    corpus runner (benchmarks/corpus.py)."""
    distributed = distributed or _dask()
    if scheduler:
        try:
            return distributed.Client(scheduler, timeout="10s"), None
        except (OSError, TimeoutError) as exc:
            raise InputError(f"no Dask scheduler answers at {scheduler} ({exc}); start one "
                             "('dask scheduler' and 'dask worker ADDRESS') or leave out "
                             "--scheduler for a local cluster") from None
    # dask's nanny gives each worker one BLAS / OpenMP thread (distributed.nanny.pre-spawn-environ)
    cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=50)
    return distributed.Client(cluster), cluster


def sweep(study: Study, out: str | os.PathLike, *, workers: int | None = None,
              scheduler: str | None = None, progress: Progress = None,
              bar: bool = False, page: bool = True) -> SweepResult:
    """Run every variant of ``study`` not yet done in ``out`` on Dask; the results table.

    ``workers``: processes of the local cluster (default: the cores); ``scheduler``: the
    address of a running cluster instead; ``progress``: a callable for one line per finished
    variant; ``bar``: the Dask client's progress bar on the terminal instead; ``page``: also
    write sweep.html and sweep.png."""
    t0 = time.perf_counter()
    out = Path(out)
    if not Path(study.target).is_file():
        raise InputError(f"the study's target {study.target} is not a file; give a mesh or .3dm")
    plan = _plan(study)
    variants = _prepare(study, out)
    rows = {k: r for k, _ in plan if (r := _done(variants, k)) is not None}
    todo = [(k, p) for k, p in plan if k not in rows]
    say = progress or (lambda _m: None)
    say(f"{len(plan)} variants: {len(rows)} done before, {len(todo)} to run")
    if todo:
        rows.update(_compute(todo, study, variants, workers, scheduler, say, bar))
    table = _table([rows[k] for k, _ in plan if k in rows], study)
    require_own(out)
    results = _write_table(table, out)
    pic = None
    if page:
        from gridshell.render.sweep_page import best_keys, write_sweep_page

        pictures = _pictures(variants, best_keys(table), say)
        pic = write_sweep_page(table, out, list(study.values) + list(study.ranges), pictures)
    _manifest(out)
    return SweepResult(table, len(todo), len(plan) - len(todo), results, pic,
                       time.perf_counter() - t0)


def _compute(todo: list, study: Study, variants: Path, workers: int | None,
             scheduler: str | None, say: Callable[[str], None], bar: bool) -> dict[str, dict]:
    """Run ``todo`` on the cluster; the rows by key (as each task ends, so Ctrl-C keeps them)."""
    distributed = _dask()
    n = max(1, int(workers or os.cpu_count() or 1))
    client, cluster = open_client(min(n, len(todo)), scheduler, distributed)
    rows: dict[str, dict] = {}
    try:
        target = str(Path(study.target).resolve())
        futures = [client.submit(run_variant, target, p, k, str(variants.resolve()),
                                 study.units, key=f"variant-{k}", pure=False, retries=1,
                                 priority=_expected_cost(p))
                   for k, p in todo]
        if bar:
            distributed.progress(futures, notebook=False)
        for fut in distributed.as_completed(futures):
            k = fut.key[len("variant-"):]
            try:
                row = fut.result()
            except Exception as exc:  # a task its workers could not finish (killed each time)
                row = {**dict(todo)[k], "key": k, "code": 1, "stage": "worker",
                       "message": f"the task failed on its workers: {type(exc).__name__}: "
                                  f"{str(exc)[:300]}"}
            rows[k] = row
            if not bar:
                say(f"{len(rows)}/{len(todo)} "
                    f"{_label(row, study)}: exit {row.get('code')} "
                    f"{row.get('stage', '')} {row.get('time_s', 0) or 0:.1f} s")
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
        _sweep_temporary(variants, [k for k, _ in todo])
    return rows


def _expected_cost(p: dict[str, Any]) -> int:
    """A rank of a variant's expected run time (Dask runs higher priorities first, so the long
    tasks start early and the short ones fill the end: the workers finish together). NCP kinds
    (a PHLW step, tracing, post-optimization) take several times a GG design; more lamellae
    take longer."""
    kind = str(p.get("kind", "gg"))
    return (0 if kind == "gg" else 1000) + int(p.get("lamellae") or 10)


def _sweep_temporary(variants: Path, keys: list[str]) -> None:
    """Remove the temporary directories of this run's tasks whose worker was killed
    (``.KEY.*.tmp``, made by :func:`gridshell.workflow.variant.run_variant`; every task has
    ended here): only those names, only directories, never through a link."""
    import shutil

    for k in keys:
        for p in variants.glob(f".{k}.*.tmp"):
            if p.is_dir() and not p.is_symlink():
                shutil.rmtree(p, ignore_errors=True)


def _pictures(variants: Path, keys: list[str], say: Callable[[str], None]) -> dict[str, Path]:
    """render.png of each variant in ``keys`` (drawn once, kept in its bundle)."""
    from gridshell.core.errors import GridshellError
    from gridshell.render.ribbons import render_bundle

    out = {}
    for k in keys:
        pic = variants / k / "design" / "render.png"
        if not pic.is_file():
            say(f"drawing variant {k}")
            try:
                render_bundle(pic.parent, pic)
            except (GridshellError, OSError) as exc:
                say(f"variant {k}: no picture ({exc})")
                continue
        out[k] = pic
    return out


def _label(row: dict, study: Study) -> str:
    names = list(study.values) + list(study.ranges)
    return " ".join(f"{n}={row.get(n)}" for n in names) or row.get("key", "")


def _table(rows: list[dict], study: Study) -> Any:
    import pandas as pd

    names = list(dict.fromkeys([*study.fixed, *study.values, *study.ranges]))
    cols = names + [c for c in COLUMNS if c not in names]
    return pd.DataFrame([{c: r.get(c) for c in cols} for r in rows], columns=cols)


def _write_table(table: Any, out: Path) -> Path:
    """results.parquet (results.csv without pyarrow), written atomically."""
    from gridshell.core.atomic import atomic_path

    try:
        import pyarrow  # noqa: F401
        path = out / "results.parquet"
        with atomic_path(path) as tmp:
            table.to_parquet(tmp, index=False)
    except ImportError:
        path = out / "results.csv"
        with atomic_path(path) as tmp:
            table.to_csv(tmp, index=False)
    return path


def _manifest(out: Path) -> None:
    """The study directory's manifest: the sweep's own files and the variants (each with a
    manifest of its own); files a user added are not claimed."""
    from gridshell.core import manifest

    m = manifest.build(out, "sweep", "design study")
    m["files"] = {f: r for f, r in m["files"].items() if f in OWN}
    m["outputs"] = [o for o in m["outputs"] if o.startswith(VARIANTS + "/")]
    m["dirs"] = [d for d in m["dirs"] if d == VARIANTS or d.startswith(VARIANTS + "/")]
    manifest.write(out, m)


def load_results(out: str | os.PathLike) -> Any:
    """The results table of a study directory (a pandas DataFrame)."""
    _dask()
    import pandas as pd

    out = Path(out)
    if (out / "results.parquet").is_file():
        return pd.read_parquet(out / "results.parquet")
    if (out / "results.csv").is_file():
        return pd.read_csv(out / "results.csv")
    raise InputError(f"{out} holds no results table; run 'gridshell sweep' into it first")
