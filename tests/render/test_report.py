"""Tests of gridshell.render.report (report.html) and the ``gridshell render`` command."""
from __future__ import annotations

import io
import json
import re
from html.parser import HTMLParser

import pytest
import rhino3dm
from PIL import Image
from tests.helpers.render_cases import write_case

from gridshell.cli.main import main
from gridshell.core.errors import InputError
from gridshell.render.report import metric_checks, write_report

VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source",
        "track", "wbr"}


class _Checker(HTMLParser):
    """Records tags, attributes and nesting errors of a document."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.errors, self.attrs, self.text = [], [], [], []

    def handle_starttag(self, tag, attrs):
        self.attrs.append((tag, dict(attrs)))
        if tag not in VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.attrs.append((tag, dict(attrs)))

    def handle_endtag(self, tag):
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes <{self.stack[-1] if self.stack else None}>")
        else:
            self.stack.pop()

    def handle_data(self, data):
        self.text.append(data)


def _png_bytes(size=(40, 30)) -> bytes:
    buf = io.BytesIO()
    Image.new("RGB", size, (200, 40, 40)).save(buf, format="PNG")
    return buf.getvalue()


SVG = ('<?xml version="1.0" encoding="UTF-8"?>\n<!-- a sheet -->\n'
       '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
       'width="600mm" height="400mm" viewBox="0 0 600 400"><title>sheet_01</title>'
       '<g id="CUT" stroke="#ff0000"><polyline points="0,0 10,10" fill="none"/></g>'
       '<image xlink:href="https://example.com/x.png" width="1" height="1"/>'
       '<use href="#CUT"/></svg>\n')


@pytest.fixture()
def bundle(tmp_path):
    extra = {"preview.png": _png_bytes(), "fabrication/plan.png": _png_bytes((50, 20)),
             "fabrication/sheet_01.svg": SVG.encode(),
             "fabrication/fabrication.json": json.dumps({"n_sheets": 1,
                                                         "utilisation": 0.4}).encode()}
    return write_case(tmp_path / "gg", "GG", extra=extra)


def _parse(text: str) -> _Checker:
    c = _Checker()
    c.feed(text)
    c.close()
    assert not c.errors, c.errors[:5]
    assert c.stack == [], f"unclosed: {c.stack}"
    return c


def test_report_is_self_contained_valid_html(bundle):
    out = write_report(bundle)
    assert out == bundle / "report.html"
    text = out.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    assert not re.search(r"https?://", text), "no network references at all"
    c = _parse(text)
    tags = [t for t, _ in c.attrs]
    assert "link" not in tags
    scripts = [a for t, a in c.attrs if t == "script"]  # the viewer's: scene, three.js, viewer
    assert scripts[:1] == [{"type": "application/gzip", "id": "gridshell-scene"}]
    assert scripts[1]["type"] == "application/gzip" and scripts[1]["id"] == "gridshell-three"
    assert scripts[2:] == [{}]
    srcs = [a["src"] for t, a in c.attrs if "src" in a]
    assert len(srcs) == 2 and all(s.startswith("data:image/png;base64,") for s in srcs)
    hrefs = [a["href"] for _, a in c.attrs if "href" in a]
    assert hrefs == ["#s0-CUT"]  # the sheet's internal reference, id prefixed
    assert 'id="s0-CUT"' in text and "<svg" in text  # sheet inlined
    assert not list(bundle.glob(".report.html*"))  # atomic


def test_report_metrics_and_lamellae(bundle):
    text = write_report(bundle).read_text(encoding="utf-8")
    body = " ".join(_parse(text).text)
    assert "GG alignable lamella gridshell" in body
    assert "Delta_a, straight edges" in body and "0.42" in body and "1.7" in body
    assert "mean < 1 %, max < 3 %" in body
    assert body.count("\u2713 pass") == 2 and "\u2717 fail" not in body
    assert "within the paper's thresholds" in body
    assert "geodesic_turning" in body and "nested.b" in body  # other metrics and params
    rows = re.findall(r"<tr><td class=num>(\d+)</td><td>C([13])</td>", text)
    assert [(int(i), int(f)) for i, f in rows] == [(i, 1) for i in range(4)] + \
        [(i, 3) for i in range(4, 8)]


def test_failed_threshold_is_marked(tmp_path):
    d = write_case(tmp_path / "ncp", "NCP")
    body = " ".join(_parse(write_report(d).read_text(encoding="utf-8")).text)
    assert "1 of 3 checks fail" in body  # Delta_l max 1.5 % >= 1 %
    rows = {r["key"]: r["status"] for r in metric_checks(
        {"delta_l": {"mean": 0.2, "max": 1.5}, "delta_a_before": {"mean": 5, "max": 9},
         "delta_a_after": {"mean": 0.5, "max": float("nan")}})}
    assert rows == {"delta_a_before": "info", "delta_a_after": "pass", "delta_l": "fail"}


def test_report_of_a_non_bundle(tmp_path):
    with pytest.raises(InputError, match="not a design bundle"):
        write_report(tmp_path)


def test_cli_render_everything(tmp_path, capsys):
    d = write_case(tmp_path / "ncp", "NCP", sequence=True)
    rc = main(["render", str(d), "--report", "--3dm", str(tmp_path / "m.3dm"), "--width", "30",
               "--size", "320", "240", "-q", "--json"])
    assert rc == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ok"] and summary["kind"] == "NCP"
    for name in ("render.png", "alignment.gif", "report.html", "sequence/frame_002.png"):
        assert (d / name).is_file(), name
    assert "data:image/gif;base64," in (d / "report.html").read_text(encoding="utf-8")
    assert rhino3dm.File3dm.Read(str(tmp_path / "m.3dm")) is not None
    # a second run keeps the up-to-date GIF
    assert main(["render", str(d), "--size", "320", "240", "-q"]) == 0
    assert "up to date" in capsys.readouterr().out


def test_cli_render_errors(tmp_path, capsys):
    assert main(["render", str(tmp_path), "-q"]) == 2
    assert "not a design bundle" in capsys.readouterr().err
    d = write_case(tmp_path / "gg", "GG")
    assert main(["render", str(d), "--width", "-3", "-q"]) == 2
    assert "--width" in capsys.readouterr().err
