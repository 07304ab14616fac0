"""Every applicable pipeline and mode on every reference of the corpus (gridshell.corpus,
issue 13), through the command line as a user would run it, and one table of the outcome.

For each reference its mesh is written as an OBJ file in a temporary directory, then for each
of its runs (``Reference.modes``: ``gg`` on all; ``ncp`` ``--mode phlw`` / ``cnc`` on the
saddle-like and dome-like ones, ``--mode aa`` where K < 0):

    python -m gridshell gg  REF.obj -o DIR --json
    python -m gridshell ncp REF.obj -o DIR --mode phlw|cnc|aa --json

with the defaults, each in its own process with a time limit (``--timeout``, default 180 s,
recorded as a timeout). A run that exits 0 is checked as a user would: ``gridshell verify DIR``
and ``gridshell fabricate DIR -o DIR/fab`` (the defaults: 1:10, 20 x 1 mm polypropylene strips
on 600 x 400 mm sheets).

A run **succeeds** when it exits 0, every figure of design.json is within the paper's
thresholds (:func:`gridshell.measure.quality.design_gates`), ``verify`` says ``ok: true`` and
``fabricate`` exits 0. The summary gives the success rate per pipeline and mode, the runs that
exit 0 while a figure fails (must be none), the runs that say ``ok: true`` in verify while a
recomputed figure fails, the runs whose reports say converged while an optimizer's energy ended
above where it started (every ``history`` with energies in design.json / report.json), and the
five slowest runs. ``--no-net`` adds the runs that must answer "no net exists" (``aa`` on
K > 0 references: exit 3); ``--phlw`` adds ``gridshell phlw REF.obj --mode M`` on the NCP
references (success: exit 0, converged, no energy increase).

    .venv/bin/python benchmarks/corpus.py                       # everything (hours on 2 cores)
    .venv/bin/python benchmarks/corpus.py --subset fast         # a few minutes
    .venv/bin/python benchmarks/corpus.py --only gg --every 2 --jobs 2 --json out/corpus.json
    .venv/bin/python benchmarks/corpus.py --subset saddle,dome-01 --only ncp
    .venv/bin/python benchmarks/corpus.py --list                # the references and their runs
    .venv/bin/python benchmarks/corpus.py --report a.json b.json  # the table of saved runs

The runs are tasks of a Dask cluster (the engine of ``gridshell sweep``): ``--jobs N`` local
worker processes, or ``--scheduler tcp://HOST:8786`` for a running one.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from _measure import gridshell_env as _env  # noqa: E402

from gridshell.corpus import MODES, Reference, select  # noqa: E402
from gridshell.corpus.files import target_name  # noqa: E402
from gridshell.measure.quality import design_gates, gate_summary, passed  # noqa: E402

#: extra runs: the PHLW step alone (``--phlw``)
PHLW_MODES = {"phlw-phlw": ["phlw", "--mode", "phlw"], "phlw-cnc": ["phlw", "--mode", "cnc"],
              "phlw-aa": ["phlw", "--mode", "aa"]}
#: success-rate goals of issue 13 (fraction of the runs of a pipeline / mode)
GOALS = {"gg": 0.95, "ncp-phlw": 0.80, "ncp-cnc": 0.80, "ncp-aa": 0.80}
#: design kind of each NCP mode (design.json "kind")
KIND = {"gg": "GG", "ncp-phlw": "NCP", "ncp-cnc": "CNC", "ncp-aa": "AA"}


# ----------------------------------------------------------------------------- running


def _call(argv: list[str], timeout: float) -> dict[str, Any]:
    """``python -m gridshell ARGV`` in its own process group: exit code (None: timed out),
    seconds, stdout, stderr. A timed-out run's group is killed."""
    t0 = time.perf_counter()
    p = subprocess.Popen([sys.executable, "-m", "gridshell", *argv], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=_env(), start_new_session=True)
    try:
        out, err = p.communicate(timeout=timeout)
        code: int | None = p.returncode
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, err = p.communicate()
        code = None
    return {"code": code, "time": time.perf_counter() - t0, "stdout": out, "stderr": err}


def _message(res: dict[str, Any]) -> str:
    """First line of a failed command's message: the JSON error, else the last
    ``gridshell ...: error:`` line, else the last line of stderr."""
    try:
        d = json.loads(res["stdout"])
        if isinstance(d, dict) and d.get("message"):
            return str(d["message"]).strip().splitlines()[0]
    except (json.JSONDecodeError, ValueError):
        pass
    lines = [ln for ln in res["stderr"].splitlines() if ln.strip()]
    for ln in reversed(lines):
        if ": error:" in ln:
            return ln.split(": error:", 1)[1].strip()
    return lines[-1].strip() if lines else ""


def _json(text: str) -> Any:
    try:
        return json.loads(text)
    except (json.JSONDecodeError, ValueError):
        return None


def _up(e0: Any, e1: Any) -> bool:
    """``e1`` above ``e0`` (both numbers), beyond rounding."""
    return (isinstance(e0, (int, float)) and isinstance(e1, (int, float))
            and e1 > e0 * (1 + 1e-9) + 1e-300)


def energy_increases(doc: Any, where: str = "") -> list[str]:
    """Places in a report where an optimizer says converged while its energy ended above
    where it started: every dict with a ``history`` list of rounds holding ``energy`` (and
    ``energy0``), and ``converged`` true in it or in an enclosing dict (first ``energy0`` to
    last ``energy``, and every round's ``energy0`` to its ``energy``); and PHLW's
    ``report_before`` / ``report_after`` ``E_PHLW`` totals."""
    found: list[str] = []

    def walk(d: Any, path: str, conv: Any) -> None:
        if isinstance(d, dict):
            conv = d.get("converged", conv)
            h = d.get("history")
            if isinstance(h, list) and h and all(isinstance(r, dict) for r in h):
                e0 = h[0].get("energy0", h[0].get("energy"))
                e1 = h[-1].get("energy")
                if conv is True and _up(e0, e1):
                    found.append(f"{path or '/'}: energy {e0:.3g} -> {e1:.3g}")
                for r in h:  # no round may end above where it started
                    if conv is True and _up(r.get("energy0"), r.get("energy")):
                        found.append(f"{path or '/'} round {r.get('round', '?')}: energy "
                                     f"{r['energy0']:.3g} -> {r['energy']:.3g}")
            b, a = d.get("report_before"), d.get("report_after")
            if conv is True and isinstance(b, dict) and isinstance(a, dict):
                eb, ea = (b.get("E_PHLW") or {}).get("total"), (a.get("E_PHLW") or {}).get("total")
                if isinstance(eb, (int, float)) and isinstance(ea, (int, float)) and ea > eb:
                    found.append(f"{path or '/'}: E_PHLW {eb:.3g} -> {ea:.3g}")
            for k, v in d.items():
                walk(v, f"{path}/{k}", conv)
        elif isinstance(d, list):
            for i, v in enumerate(d):
                walk(v, f"{path}[{i}]", conv)
    walk(doc, where, None)
    return found


def _figures(mode: str, metrics: dict[str, Any]) -> dict[str, Any]:
    """The table's figures of a design's metrics (percent)."""
    def get(key, sub="max"):
        v = metrics.get(key)
        v = v.get(sub) if isinstance(v, dict) else v
        return float(v) if isinstance(v, (int, float)) else None
    da = "alignability" if mode == "gg" else "delta_a_after"
    coll = metrics.get("aligned_radius_error", metrics.get("aligned_line_error"))
    # GG: no Delta_l / Delta_n gate (its delta_l is the chords' lengthening to the arcs)
    return {"da_mean": get(da, "mean"), "da_max": get(da),
            "dl": None if mode == "gg" else get("delta_l"),
            "dn": None if mode == "gg" else get("delta_n"),
            "collapse": coll if isinstance(coll, (int, float)) else None,
            "deviation": get("deviation")}


def _target(ref: Reference, work: Path) -> tuple[Path, Path, list[str]]:
    """``(folder, target file, --units words)`` of ``ref`` in ``work`` (the file written once;
    ``--units`` as a user passes it: not for a .3dm, which carries its own)."""
    d = work / ref.name
    d.mkdir(parents=True, exist_ok=True)
    target = d / target_name(ref)
    if not target.exists():
        ref.write_target(d)
    return d, target, [] if ref.file_format == "3dm" else ["--units", ref.units]


def _record(ref: Reference, mode: str, res: dict[str, Any]) -> dict[str, Any]:
    """The record of ``mode`` on ``ref`` after its command's result ``res``, checks empty."""
    return {"reference": ref.name, "family": ref.family, "mode": mode,
            "mesh": f"{ref.mesh[0]}{ref.rows}x{ref.cols}", "size": ref.size,
            "curvature": ref.curvature, "expect_no_net": mode in ref.no_net,
            "tried": mode in ref.tried, "file": f"{ref.file_format} {ref.units}",
            "code": res["code"], "time": res["time"], "message": "", "gates": [],
            "verify_ok": None, "verify_gates_ok": None, "fabricate": None, "energy_up": [],
            "converged": None}


def run_one(ref: Reference, mode: str, work: Path, timeout: float,
            fab_args: list[str] = ()) -> dict[str, Any]:
    """One run of ``mode`` on ``ref`` in ``work``, with its checks; a JSON-able record."""
    d, target, units = _target(ref, work)
    out = d / mode
    words = {**MODES, **PHLW_MODES}[mode]
    res = _call([words[0], str(target), "-o", str(out), "--json", *units, *words[1:]], timeout)
    rec = _record(ref, mode, res)
    if res["code"] is None:
        rec["message"] = f"timeout after {timeout:g} s"
        return rec
    summary = _json(res["stdout"]) or {}
    if res["code"] != 0:
        rec["message"] = _message(res)
        return rec
    rec["converged"] = summary.get("converged", summary.get("surface optimization"))
    for name in ("design.json", "report.json"):
        doc = _json((out / name).read_text()) if (out / name).is_file() else None
        if doc is not None:
            rec["energy_up"] += energy_increases(doc, name)
    if mode.startswith("phlw-"):
        rec["energy_up"] += energy_increases(summary, "summary")
        return rec
    design = _json((out / "design.json").read_text()) if (out / "design.json").is_file() else None
    if not design:
        rec["message"] = "exit 0 but no readable design.json"
        return rec
    metrics = design.get("metrics") or {}
    rec.update(_figures(mode, metrics))
    gates = design_gates(design.get("kind", KIND[mode]), metrics)
    rec["gates"] = [g.as_dict() for g in gates]
    if not passed(gates):
        rec["message"] = gate_summary(gates)
    v = _call(["verify", str(out), "--json"], timeout)
    rec["verify_time"] = v["time"]
    vj = _json(v["stdout"]) if v["code"] == 0 else None
    if vj is None:
        rec["verify_ok"] = False
        rec["message"] = rec["message"] or "verify: " + (_message(v) or f"exit {v['code']}")
    else:
        rec["verify_ok"] = bool(vj.get("ok"))
        rec["verify_gates_ok"] = passed(design_gates(vj.get("kind", KIND[mode]), vj))
        if not rec["verify_ok"] and not rec["message"]:
            rec["message"] = "verify: ok false " + str(vj.get("failing", vj.get("mismatch", "")))
    f = _call(["fabricate", str(out), "-o", str(out / "fab"), "-q", *fab_args], timeout)
    rec["fabricate"] = f["code"]
    rec["fabricate_time"] = f["time"]
    if f["code"] != 0 and not rec["message"]:
        rec["message"] = "fabricate: " + (_message(f) or f"exit {f['code']}"
                                          if f["code"] is not None else "timeout")
    return rec


def run_recommended(ref: Reference, mode: str, work: Path, timeout: float,
                    fab_args: list[str] = ()) -> dict[str, Any]:
    """``gridshell analyze`` on ``ref`` (its GG trial included), then the run it recommends
    (:func:`run_one`), its record marked ``recommended`` with the analysis's time and why."""
    _, target, units = _target(ref, work)
    a = _call(["analyze", str(target), "--json", "--no-files", "-q", *units], timeout)
    words = ((_json(a["stdout"]) or {}).get("recommended") or "").split()
    pick = ("gg" if words[1:2] == ["gg"] else
            f"ncp-{words[words.index('--mode') + 1]}" if "--mode" in words else None)
    if a["code"] != 0 or pick not in MODES:
        rec = dict(_record(ref, "analyze", a), message=_message(a) or "no recommendation")
    else:
        rec = run_one(ref, pick, work, timeout, fab_args)
    rec.update(recommended=True, analyze_time=a["time"],
               why=(_json(a["stdout"]) or {}).get("why", ""))
    return rec


def success(rec: dict[str, Any]) -> bool:
    """Exit 0, every figure within the thresholds, verify ok, fabricate exit 0 (phlw runs:
    exit 0, converged, no energy increase)."""
    if rec["code"] != 0:
        return False
    if rec["mode"].startswith("phlw-"):
        return rec["converged"] is True and not rec["energy_up"]
    return (bool(rec["gates"]) and all(g["ok"] for g in rec["gates"])
            and rec["verify_ok"] is True and rec["fabricate"] == 0)


# ----------------------------------------------------------------------------- report


def _f(x: Any, nd: int = 3) -> str:
    if x is None:
        return "-"
    if isinstance(x, float) and not math.isfinite(x):
        return "nan"
    return f"{x:.{nd}g}"


def table(records: list[dict[str, Any]]) -> str:
    """The one table (Markdown), then the summary lines."""
    head = ["reference", "mesh", "size m", "run", "exit", "time s", "Da mean", "Da max",
            "Dl", "Dn", "collapse", "dev", "verify", "fab", "ok", "message"]
    rows = []
    for r in records:
        code = "T/O" if r["code"] is None else str(r["code"])
        rows.append([r["reference"], r["mesh"], _f(r["size"], 3), r["mode"], code,
                     f"{r['time']:.1f}", _f(r.get("da_mean")), _f(r.get("da_max")),
                     _f(r.get("dl")), _f(r.get("dn")), _f(r.get("collapse")),
                     _f(r.get("deviation")),
                     "-" if r["verify_ok"] is None else ("ok" if r["verify_ok"] else "FAIL"),
                     "-" if r["fabricate"] is None else str(r["fabricate"]),
                     "yes" if success(r) else "no", r["message"].replace("|", "/")[:160]])
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def summary(records: list[dict[str, Any]]) -> str:
    out = []
    rank = {m: i for i, m in enumerate([*MODES, *PHLW_MODES])}
    modes = sorted(dict.fromkeys(r["mode"] for r in records), key=lambda m: rank.get(m, 99))
    out.append("\nSuccess (exit 0, every figure within the paper's thresholds, verify ok, "
               "fabricate exit 0):")
    for m in modes:
        rs = [r for r in records if r["mode"] == m and not r["expect_no_net"]
              and not r.get("tried")]
        if not rs:
            continue
        ok = sum(success(r) for r in rs)
        codes: dict[str, int] = {}
        for r in rs:
            k = "timeout" if r["code"] is None else f"exit {r['code']}"
            codes[k] = codes.get(k, 0) + 1
        goal = GOALS.get(m)
        goal_s = f", goal >= {goal:.0%}: {'met' if ok / len(rs) >= goal else 'NOT met'}" \
            if goal else ""
        design = sum(r["code"] == 0 and bool(r["gates"]) and all(g["ok"] for g in r["gates"])
                     and r["verify_ok"] is True for r in rs)
        out.append(f"  {m:10s} {ok:3d} / {len(rs):3d} = {ok / len(rs):6.1%}{goal_s}  "
                   f"({', '.join(f'{k}: {v}' for k, v in sorted(codes.items()))}; "
                   f"design and verify alone, without fabricate: {design})")
    picked = [r for r in records if r.get("recommended")]
    if picked:
        ok = sum(success(r) for r in picked)
        kinds = {m: sum(r["mode"] == m for r in picked) for m in dict.fromkeys(
            r["mode"] for r in picked)}
        design = sum(r["code"] == 0 and bool(r["gates"]) and all(g["ok"] for g in r["gates"])
                     and r["verify_ok"] is True for r in picked)
        out.append(f"  the run 'gridshell analyze' recommends: {ok} / {len(picked)} = "
                   f"{ok / len(picked):6.1%} succeed (goal >= 90 %: "
                   f"{'met' if ok >= 0.9 * len(picked) else 'NOT met'}; design and verify "
                   f"alone, without fabricate: {design}; recommended "
                   + ", ".join(f"{m} {n}" for m, n in kinds.items()) + ")")
    tried = [r for r in records if r.get("tried")]
    if tried:
        ok = sum(success(r) for r in tried)
        refused = sum(r["code"] in (3, 4) and bool(r["message"]) for r in tried)
        other = len(tried) - ok - refused
        out.append(f"  runs a user would try where the surface does not admit the mode "
                   f"(umbilic, K of both signs): {len(tried)}: {ok} succeed, {refused} refused "
                   f"with a reason (exit 3/4), {other} otherwise (must be 0)")
    nn = [r for r in records if r["expect_no_net"]]
    if nn:
        good = sum(r["code"] == 3 for r in nn)
        out.append(f"  no-net runs answering exit 3: {good} / {len(nn)}")
    fams = list(dict.fromkeys(r["family"] for r in records))
    out.append("\nSuccess per family (" + ", ".join(modes) + "):")
    for fam in fams:
        cells = []
        for m in modes:
            rs = [r for r in records if r["family"] == fam and r["mode"] == m
                  and not r["expect_no_net"]]
            cells.append(f"{sum(success(r) for r in rs)}/{len(rs)}" if rs else "-")
        out.append(f"  {fam:18s} " + "  ".join(f"{c:>5s}" for c in cells))
    causes: dict[str, int] = {}
    for r in records:
        if not success(r) and not (r["expect_no_net"] and r["code"] == 3) \
                and not (r.get("tried") and r["code"] in (3, 4)):
            key = re.sub(r"[-+]?\d[\d.e+-]*", "#", r["message"] or f"exit {r['code']}")[:70]
            causes[f"{r['mode']}: {key}"] = causes.get(f"{r['mode']}: {key}", 0) + 1
    out.append("\nFailure causes (numbers replaced by #):")
    out += [f"  {n:3d}  {k}" for k, n in sorted(causes.items(), key=lambda kv: -kv[1])]
    lying = [r for r in records if r["code"] == 0 and r["gates"]
             and not all(g["ok"] for g in r["gates"])]
    out.append(f"\nRuns that exit 0 while a figure fails (must be 0): {len(lying)}"
               + "".join(f"\n  {r['reference']} {r['mode']}: {r['message']}" for r in lying))
    vlie = [r for r in records if r["verify_ok"] is True and r["verify_gates_ok"] is False]
    out.append(f"Runs whose verify says ok while a recomputed figure fails: {len(vlie)}"
               + "".join(f"\n  {r['reference']} {r['mode']}" for r in vlie))
    fab = [r for r in records if r["code"] == 0 and r["fabricate"] not in (0, None)]
    out.append(f"Exit-0 runs whose bundle fabricate refuses: {len(fab)}")
    up = [r for r in records if r["energy_up"]]
    out.append(f"Runs reporting converged with a higher final than initial energy (must be 0): "
               f"{len(up)}" + "".join(f"\n  {r['reference']} {r['mode']}: "
                                      f"{'; '.join(r['energy_up'][:3])}" for r in up))
    slow = sorted(records, key=lambda r: -r["time"])[:5]
    out.append("Slowest five runs: " + "; ".join(
        f"{r['reference']} {r['mode']} {r['mesh']} {r['time']:.1f} s"
        + (" (timeout)" if r["code"] is None else "") for r in slow))
    over = sum(r["time"] > 60 for r in records)
    out.append(f"Runs over 60 s: {over} of {len(records)}")
    return "\n".join(out)


def _run_on_dask(jobs: list[tuple[Reference, str]], work: Path, args: Any,
                 t0: float) -> list[dict[str, Any]]:
    """Every job as a task of a Dask cluster (:func:`gridshell.workflow.sweep.open_client`:
    ``--jobs`` local worker processes, or ``--scheduler``), the records in the jobs' order;
    one progress line per finished run, the records so far in ``--json`` after each."""
    from distributed import as_completed

    from gridshell.workflow.sweep import open_client

    client, cluster = open_client(max(1, min(args.jobs, len(jobs) or 1)), args.scheduler)
    done: dict[int, dict[str, Any]] = {}
    try:
        futures = {client.submit(run_recommended if mode == "recommended" else run_one, ref,
                                 mode, work, args.timeout, args.fab_args.split(),
                                 key=f"corpus-{i}-{ref.name}-{mode}", pure=False): i
                   for i, (ref, mode) in enumerate(jobs)}
        for fut in as_completed(list(futures)):
            rec = fut.result()
            done[futures[fut]] = rec
            print(f"[{time.perf_counter() - t0:7.0f}s] {len(done):3d}/{len(jobs)} "
                  f"{rec['reference']} {rec['mode']}: "
                  f"{'timeout' if rec['code'] is None else 'exit ' + str(rec['code'])} "
                  f"{rec['time']:.1f} s {'ok' if success(rec) else rec['message'][:100]}",
                  file=sys.stderr, flush=True)
            if args.json:  # partial results survive an interrupted run
                Path(args.json).write_text(json.dumps([done[i] for i in sorted(done)],
                                                      indent=1, default=str))
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return [done[i] for i in sorted(done)]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--subset", help="references: names, families or 'fast', comma-separated")
    ap.add_argument("--only", choices=("gg", "ncp", "phlw"), help="one pipeline")
    ap.add_argument("--modes", nargs="+", help="runs, e.g. gg ncp-cnc (default: all that apply)")
    ap.add_argument("--limit", type=int, help="at most this many references")
    ap.add_argument("--every", type=int, default=1, help="every N-th reference (default 1)")
    ap.add_argument("--start", type=int, default=0,
                    help="first reference for --every (e.g. --every 2 --start 1: the other half)")
    ap.add_argument("--jobs", type=int, default=1,
                    help="runs at a time: worker processes of a local Dask cluster (default 1)")
    ap.add_argument("--scheduler", metavar="tcp://HOST:8786",
                    help="run on a running Dask cluster instead (its workers need this "
                         "checkout and --keep DIR on a shared filesystem)")
    ap.add_argument("--timeout", type=float, default=180.0, help="seconds per command")
    ap.add_argument("--no-net", action="store_true",
                    help="also the runs that must answer 'no net exists' (aa on K > 0)")
    ap.add_argument("--phlw", action="store_true", help="also 'gridshell phlw' alone")
    ap.add_argument("--fab-args", default="", metavar="ARGS",
                    help="extra options of 'gridshell fabricate', e.g. '--scale 1:1' (default: "
                         "none, the 1:10 polypropylene defaults)")
    ap.add_argument("--keep", metavar="DIR", help="work in DIR and keep it (default: a temp dir)")
    ap.add_argument("--json", metavar="OUT", help="write the raw records to OUT")
    ap.add_argument("--list", action="store_true", help="list the references and their runs")
    ap.add_argument("--recommended", action="store_true",
                    help="per reference: 'gridshell analyze', then only the run it recommends "
                         "(issue 29: the recommended pipeline succeeds on >= 90 %%)")
    ap.add_argument("--report", nargs="+", metavar="JSON",
                    help="print the table and summary of saved records (--json files) instead "
                         "of running")
    args = ap.parse_args(argv)
    if args.report:
        records = [r for p in args.report for r in json.loads(Path(p).read_text())]
        order = {n: i for i, n in enumerate(r.name for r in select(None))}
        rank = {m: i for i, m in enumerate([*MODES, *PHLW_MODES])}
        records.sort(key=lambda r: (order.get(r["reference"], 1e9), rank.get(r["mode"], 99)))
        print(table(records))
        print(summary(records))
        return 0

    refs = select(args.subset)[args.start:: max(1, args.every)]
    if args.limit:
        refs = refs[: args.limit]
    jobs: list[tuple[Reference, str]] = []
    for r in refs:
        runs = list(r.modes) + list(r.tried) + (list(r.no_net) if args.no_net else [])
        if args.phlw or args.only == "phlw":
            runs += [f"phlw-{m.split('-')[1]}" for m in r.modes if m.startswith("ncp-")]
        if args.only:
            runs = [m for m in runs if m.split("-")[0] == args.only]
        if args.modes:
            runs = [m for m in runs if m in args.modes]
        jobs += [(r, m) for m in runs] if not args.recommended else [(r, "recommended")]
    if args.list:
        for r in refs:
            print(f"{r.name:22s} {r.mesh:4s} {r.rows:3d}x{r.cols:<3d} {r.size:6.2f} m "
                  f"{r.orientation:8s} {r.curvature:6s} revolution={r.revolution!s:5s} "
                  f"{r.file_format} {r.units:2s} runs: {' '.join(r.modes)}"
                  + (f"  tried: {' '.join(r.tried)}" if r.tried else "")
                  + (f"  no-net: {' '.join(r.no_net)}" if r.no_net else ""))
        print(f"{len(refs)} references, {len(jobs)} runs")
        return 0
    print(f"{len(refs)} references, {len(jobs)} runs, {args.jobs} at a time, "
          f"timeout {args.timeout:g} s", file=sys.stderr, flush=True)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="gridshell-corpus-") as tmp:
        work = Path(args.keep) if args.keep else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        records = _run_on_dask(jobs, work, args, t0)
    if args.json:
        Path(args.json).write_text(json.dumps(records, indent=1, default=str))
    print(table(records))
    print(summary(records))
    print(f"\n{len(records)} runs in {time.perf_counter() - t0:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
