"""Hostile requests to the Hops server (Flask test client), as a hostile user or web page would
send them: path traversal, symbolic links and absolute paths out of the work directory, huge
and malformed bodies, NaN numbers, missing inputs, cross-origin and rebound-host requests, 20
requests at once. Every refusal is a Hops error message (or HTTP 403 / 413 with one); nothing
is written or read in a sentinel folder outside the work directory (a snapshot before and
after, and Python's audit events of every open and listing); the server answers afterwards.
"""
from __future__ import annotations

import json
import os
import shutil
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from tests.helpers.fab_cases import make_bundle

pytest.importorskip("ghhops_server")

from gridshell.design.bundle import write_bundle  # noqa: E402
from gridshell.server.components import make_app  # noqa: E402
from gridshell.server.rhino import to_mesh  # noqa: E402

FLAT = {"c": 0.0, "twist": 0.0, "stretch": 0.0}
PORT = 5000
MAX_BODY = 2 ** 20
_TOUCHED: list[str] = []        # paths under the sentinel opened or listed while watched
_WATCH: list[str] = []


def _audit(event: str, args: tuple) -> None:
    if _WATCH and event in ("open", "os.listdir", "os.scandir", "os.mkdir", "os.rename",
                            "os.remove", "os.symlink", "shutil.rmtree"):
        p = args[0] if args else None
        if isinstance(p, (str, bytes, os.PathLike)):
            p = os.fsdecode(p)
            if any(os.path.realpath(p).startswith(w) for w in _WATCH):
                _TOUCHED.append(f"{event} {p}")


sys.addaudithook(_audit)


def snapshot(root: Path) -> dict[str, bytes]:
    out = {}
    for dirpath, dirs, names in os.walk(root):
        for n in names + dirs:
            p = Path(dirpath) / n
            key = p.relative_to(root).as_posix()
            out[key] = (b"->" + os.readlink(p).encode() if p.is_symlink()
                        else p.read_bytes() if p.is_file() else b"<dir>")
    return out


def body(pointer: str, **inputs) -> dict:
    return {"pointer": pointer, "values": [{"ParamName": k, "InnerTree": {"{0}": v}}
                                           for k, v in inputs.items()]}


def text(s) -> list:
    return [{"type": "System.String", "data": json.dumps(s)}]


def number(s: str, type_: str = "System.Double") -> list:
    return [{"type": type_, "data": s}]


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    """The app on a work directory, a good bundle in it, and outside it a sentinel folder
    holding a bundle, a file and a folder the hostile requests aim at."""
    root = tmp_path_factory.mktemp("hostile")
    work, sentinel = root / "work", root / "sentinel"
    work.mkdir()
    good = write_bundle(work / "good", make_bundle("GG", **FLAT))
    outside = write_bundle(sentinel / "bundle", make_bundle("GG", **FLAT))
    (sentinel / "secret.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
    (sentinel / "fabrication").mkdir()
    links = {"link": outside}                              # a bundle that is a link out
    for name, inner, target in [("netlink", "net.obj", sentinel / "secret.obj"),
                                ("fablink", "fabrication", sentinel / "fabrication")]:
        b = Path(shutil.copytree(good, work / name))      # a bundle holding a link out
        if (b / inner).exists():
            (b / inner).unlink()
        os.symlink(target, b / inner)
    for name, target in links.items():
        os.symlink(target, work / name)
    far = Path(shutil.copytree(good, work / "fartarget"))  # design.json names a target out
    d = json.loads((far / "design.json").read_text())
    d.setdefault("params", {})["target"] = str(sentinel / "secret.obj")
    (far / "design.json").write_text(json.dumps(d))
    app = make_app(work, host="127.0.0.1", port=PORT, max_body=MAX_BODY)
    client = app.test_client()
    return {"client": client, "work": work, "sentinel": sentinel, "good": good,
            "outside": outside, "root": root}


def post(server, payload, headers=None, raw: bytes | str | None = None):
    data = raw if raw is not None else json.dumps(payload)
    h = {"Host": f"localhost:{PORT}", **(headers or {})}
    return server["client"].post("/solve", data=data, headers=h)


def alive(server) -> None:
    """The server lists its components and verifies the good bundle."""
    c = server["client"]
    assert c.get("/", headers={"Host": f"127.0.0.1:{PORT}"}).status_code == 200
    r = post(server, body("/verify", Bundle=text(str(server["good"])))).get_json()
    assert not r.get("errors") and r["values"][0]["InnerTree"]["0"][0]["data"] == "true", r


@pytest.fixture
def watched(server):
    """Snapshot the sentinel and watch it for the test; nothing changed or touched after."""
    before = snapshot(server["sentinel"])
    _TOUCHED.clear()
    _WATCH[:] = [os.path.realpath(server["sentinel"])]
    yield server
    _WATCH.clear()
    assert not _TOUCHED, _TOUCHED
    assert snapshot(server["sentinel"]) == before
    alive(server)


def _bundle_cases(s) -> dict[str, str]:
    work, sentinel = s["work"], s["sentinel"]
    return {
        "dotdot relative": "../sentinel/bundle",
        "dotdot through the bundle": f"{s['good']}/../../sentinel/bundle",
        "absolute outside": str(s["outside"]),
        "root": "/",
        "symlink to a bundle outside": str(work / "link"),
        "relative symlink name": "link",
        "a bundle file linked out": str(work / "netlink"),
        "its fabrication folder linked out": str(work / "fablink"),
        "design.json names a target outside": str(work / "fartarget"),
        "sentinel file": str(sentinel / "secret.obj"),
        "nul byte": str(work / "good") + "\x00x",
        "empty": "",
    }


BUNDLE_CASES = list(_bundle_cases({"work": Path("w"), "sentinel": Path("s"),
                                   "good": Path("g"), "outside": Path("o")}))


@pytest.mark.parametrize("component", ["/verify", "/fabricate"])
@pytest.mark.parametrize("case", BUNDLE_CASES)
def test_bundle_paths_out_of_the_work_directory_are_refused(watched, component, case):
    path = _bundle_cases(watched)[case]
    r = post(watched, body(component, Bundle=text(path), Force=number("true", "System.Boolean")))
    assert r.status_code == 200
    d = r.get_json()
    assert d["errors"] and "Traceback" not in d["errors"][0], d
    msg = d["errors"][0]
    assert "design bundle folder" in msg or "outside" in msg, msg
    assert all(not any(item["InnerTree"].values()) for item in d["values"]) or not d["values"]


def test_the_good_bundle_fabricates_inside_the_work_directory(watched):
    d = post(watched, body("/fabricate", Bundle=text(str(watched["good"])))).get_json()
    assert not d.get("errors"), d
    folder = json.loads([v for v in d["values"] if v["ParamName"] == "Folder"][0]
                        ["InnerTree"]["0"][0]["data"])
    assert Path(folder).resolve().is_relative_to(watched["work"].resolve())
    assert (Path(folder) / "manifest.json").is_file()


@pytest.mark.parametrize("headers", [
    {"Origin": "http://evil.example"}, {"Origin": "null"},
    {"Origin": f"http://localhost:{PORT + 1}"}, {"Origin": "file://"},
    {"Sec-Fetch-Site": "cross-site"}, {"Host": f"evil.example:{PORT}"},
    {"Host": f"localhost:{PORT + 1}"}, {"Host": "127.0.0.1.evil.example"}, {"Host": "[::1"}],
    ids=lambda h: "-".join(f"{k}={v}" for k, v in h.items()))
def test_cross_origin_and_rebound_host_requests_are_refused(watched, headers):
    for payload in (body("/verify", Bundle=text(str(watched["good"]))),
                    body("/gg", Target=[], Grid=number("6", "System.Int32"))):
        r = post(watched, payload, headers)
        assert r.status_code == 403
        msg = r.get_json()["errors"][0]
        assert msg.startswith("refused: ") and ("host" in msg or "web page" in msg), msg
    assert watched["client"].get("/", headers={"Host": "localhost", **headers}).status_code == 403


def test_the_servers_own_origin_and_loopback_names_are_served(watched):
    for headers in ({"Origin": f"http://localhost:{PORT}"}, {"Host": f"[::1]:{PORT}"},
                    {"Host": "127.0.0.1"}, {"Sec-Fetch-Site": "same-origin"}):
        r = post(watched, body("/verify", Bundle=text(str(watched["good"]))), headers)
        assert r.status_code == 200 and not r.get_json().get("errors"), (headers, r.data[:200])


def test_a_huge_body_is_refused_before_it_is_read(watched):
    big = json.dumps(body("/verify", Bundle=text("x" * (MAX_BODY + 10))))
    r = post(watched, None, raw=big)
    assert r.status_code == 413
    assert "over the server's limit of 1.0 MB" in r.get_json()["errors"][0]


def test_a_huge_body_of_unannounced_length_is_cut_off(watched):
    import io

    class Counting(io.BytesIO):    # how much the server reads of it
        taken = 0

        def read(self, n=-1):
            got = super().read(n)
            Counting.taken += len(got)
            return got

    stream = Counting(b"x" * (4 * MAX_BODY))
    r = watched["client"].post("/solve", input_stream=stream,
                               headers={"Host": f"localhost:{PORT}",
                                        "Transfer-Encoding": "chunked"},
                               environ_overrides={"CONTENT_LENGTH": ""})  # as a chunked POST
    assert r.status_code == 413 and Counting.taken == MAX_BODY + 1
    assert "over the server's limit" in r.get_json()["errors"][0]


MALFORMED = ["", "not json", "{", "[]", "null", '{"values": 3}', '{"values": [3]}',
             '{"values": [{"ParamName": "Bundle"}]}', '{"pointer": "/verify"}',
             '{"values": [{"ParamName": "Bundle", "InnerTree": {"{0}": [{"type": '
             '"System.String", "data": "not json"}]}}], "pointer": "/verify"}',
             "\xff\xfe garbage", '{"values": [' * 5000]


@pytest.mark.parametrize("raw", MALFORMED, ids=range(len(MALFORMED)))
def test_malformed_bodies_get_a_hops_error(watched, raw):
    r = post(watched, None, raw=raw)
    assert r.status_code in (200, 400, 404), r.status_code
    d = r.get_json(silent=True)
    if r.status_code == 200:
        assert d["errors"] and "Traceback" not in d["errors"][0], d


NAN_CASES = {
    "gg lamellae NaN": body("/gg", Target=[], Lamellae=number("NaN", "System.Int32")),
    "gg grid inf": body("/gg", Grid=number("1e309", "System.Int32")),
    "fabricate width NaN": "fab-width",
    "fabricate options NaN": "fab-options",
    "gg mesh with NaN vertices": "nan-mesh",
}


def _nan_body(case: str, good: Path) -> dict:
    if case == "fabricate width NaN":
        return body("/fabricate", Bundle=text(str(good)), Width=number("NaN"))
    if case == "fabricate options NaN":
        return body("/fabricate", Bundle=text(str(good)), Options=text('{"kerf": NaN}'))
    if case == "gg mesh with NaN vertices":
        V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, np.nan], [0, 1, 0]], float)
        mesh = json.dumps(to_mesh(V, np.array([[0, 1, 2, 3]])).Encode())
        return body("/gg", Target=[{"type": "Rhino.Geometry.Mesh", "data": mesh}])
    return NAN_CASES[case]


@pytest.mark.parametrize("case", list(NAN_CASES))
def test_nan_numbers_get_the_tools_message(watched, case):
    d = post(watched, _nan_body(case, watched["good"])).get_json()
    assert d["errors"], d
    msg = d["errors"][0]
    assert "internal error" not in msg and "Traceback" not in msg, msg


@pytest.mark.parametrize("pointer, inputs, word", [
    ("/verify", {}, "Bundle"), ("/fabricate", {}, "Bundle"), ("/gg", {}, "Target"),
    ("/ncp", {}, "Reference"), ("/nowhere", {}, None)])
def test_missing_inputs_are_named(watched, pointer, inputs, word):
    r = post(watched, body(pointer, **inputs))
    if word is None:
        assert r.status_code in (404, 200)
        return
    msg = r.get_json()["errors"][0]
    assert word in msg and "missing" in msg, msg


def test_twenty_requests_at_once(watched):
    """20 threads: good verifies, fabricates of the good bundle, hostile paths and a
    cross-origin request, each answered as alone."""
    good = str(watched["good"])
    cases = _bundle_cases(watched)
    plan = [("verify", good)] * 8 + [("fabricate", good)] * 2 + \
        [("hostile", p) for p in list(cases.values())[:8]] + [("origin", good)] * 2
    results: list = [None] * len(plan)

    def one(i: int) -> None:
        kind, path = plan[i]
        pointer = "/fabricate" if kind == "fabricate" else "/verify"
        headers = {"Origin": "http://evil.example"} if kind == "origin" else None
        r = post(watched, body(pointer, Bundle=text(path)), headers)
        results[i] = (r.status_code, r.get_json())

    threads = [threading.Thread(target=one, args=(i,)) for i in range(len(plan))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    for (kind, _), (status, d) in zip(plan, results):
        if kind in ("verify", "fabricate"):
            assert status == 200 and not d.get("errors"), d
        elif kind == "hostile":
            assert status == 200 and d["errors"], d
        else:
            assert status == 403, d
    verdicts = {json.dumps(d["values"]) for (k, _), (_, d) in zip(plan, results) if k == "verify"}
    assert len(verdicts) == 1


def test_allow_adds_a_root_and_a_missing_one_is_named(server, tmp_path):
    """--allow DIR: a bundle there is served; a missing DIR is an input error."""
    from gridshell.core.errors import InputError

    extra = tmp_path / "extra"
    b = write_bundle(extra / "b", make_bundle("GG", **FLAT))
    app = make_app(tmp_path / "w", allow=(extra,))
    d = app.test_client().post("/solve", data=json.dumps(
        body("/verify", Bundle=text(str(b))))).get_json()
    assert not d.get("errors"), d
    with pytest.raises(InputError, match="--allow .*no such folder"):
        make_app(tmp_path / "w2", allow=(tmp_path / "missing",))


@pytest.mark.parametrize("argv, code, word", [
    (["--allow", "/no/such/folder"], 2, "--allow /no/such/folder: no such folder"),
    (["--max-body", "0"], 2, "give a positive size"),
    (["--max-body", "lots"], 2, "is not a size")])
def test_serve_refuses_bad_confinement_options(capsys, tmp_path, argv, code, word):
    from gridshell.cli.main import main

    try:
        got = main(["serve", "--workdir", str(tmp_path / "w"), *argv, "-q"])
    except SystemExit as exc:     # argparse: a bad value
        got = exc.code
    err = capsys.readouterr().err
    assert got == code and word in err and "Traceback" not in err, err


def test_max_body_sizes():
    from gridshell.cli.serve import _size

    assert _size("64M") == 64 * 2 ** 20 and _size("1k") == 1024 and _size("5000") == 5000
    assert _size("1.5GB") == int(1.5 * 2 ** 30)
