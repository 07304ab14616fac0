"""The Hops middleware of ``gridshell serve``: ghhops-server's Flask middleware with replies
that always reach the component.

``ghhops-server`` answers a failing handler with HTTP 404/500 and a traceback, which Hops
shows as a dead component. Here every solve answers 200 with the tool's message in
``errors`` (a :class:`~gridshell.core.errors.GridshellError`: its one line; anything else: its
type and message) and the warnings of the handler's :class:`~.components.Reply` in
``warnings``; missing optional inputs take the handler's defaults.
"""
from __future__ import annotations

import contextlib
import io
import json
from typing import Any

import logging

_root = logging.getLogger()
_level, _handlers = _root.level, list(_root.handlers)
from ghhops_server.base import _HopsEncoder  # noqa: E402 - its logger configures the root
from ghhops_server.middlewares.hopsflask import HopsFlask  # noqa: E402

for _h in [h for h in _root.handlers if h not in _handlers]:   # undo its basicConfig
    _root.removeHandler(_h)
_root.setLevel(_level)

from gridshell.core.errors import GridshellError  # noqa: E402


class GridshellHops(HopsFlask):
    """HopsFlask whose solve replies carry errors and warnings instead of failing."""

    def __init__(self, flask_app, debug: bool = False, guard=None):
        from ghhops_server import params
        from ghhops_server.logger import hlogger

        self.guard = guard   # a gridshell.server.guard.Guard: solves one at a time

        hlogger.setLevel(logging.DEBUG if debug else logging.WARNING)
        params._init_rhino3dm()      # what ghhops_server.Hops() does before its middleware
        super().__init__(flask_app)

    def _reply(self, comp, values: tuple = (), errors: list[str] | None = None,
               warnings: list[str] | None = None) -> str:
        outputs = [p.from_result(v) for p, v in zip(comp.outputs, values)]
        body: dict[str, Any] = {"values": outputs}
        if errors:
            body["errors"] = list(errors)
        if warnings:
            body["warnings"] = list(warnings)
        return json.dumps(body, cls=_HopsEncoder)

    def solve(self, uri, payload) -> tuple[bool, str]:
        """ghhops-server's solve, with a body that is not a solve request (not JSON, nested
        too deep, no ``pointer``) answered with a Hops error instead of a traceback."""
        if uri == "/solve":
            try:
                data = json.loads(payload)
                if not isinstance(data["pointer"], str):
                    raise TypeError
            except (ValueError, TypeError, KeyError, RecursionError):
                return True, json.dumps({"values": [], "errors": [
                    "the request is not a Hops solve request (a JSON object with 'pointer' and "
                    "'values'); send it from a Hops component"]})
        return super().solve(uri, payload)

    def _prepare_inputs(self, comp, payload) -> tuple[bool, Any]:
        """Inputs in the handler's order; a missing optional input takes its default."""
        import inspect

        try:
            data = json.loads(payload)
            given = {item["ParamName"]: item for item in data.get("values", [])}
        except (ValueError, TypeError, KeyError, AttributeError, RecursionError):
            return False, "the request is not a Hops solve request (JSON with 'values')"
        inputs = []
        defaults = list(inspect.signature(comp.handler).parameters.values())
        for param, fparam in zip(comp.inputs, defaults):
            item = given.get(param.name)
            tree = (item or {}).get("InnerTree") or {}
            if item is None or not any(tree.values()):
                if fparam.default is inspect.Parameter.empty:
                    return False, f"input {param.name} is missing; connect it"
                inputs.append(fparam.default)
                continue
            try:
                with contextlib.redirect_stdout(io.StringIO()):   # from_input pprints
                    inputs.append(param.from_input(item))
            except Exception as exc:   # noqa: BLE001 - any decoding failure is the input's
                return False, f"input {param.name} could not be read ({exc}); connect a " \
                              f"{param.param_type}"
            if inputs[-1] is None:
                return False, f"input {param.name} could not be read; connect a " \
                              f"{param.param_type}"
        return True, inputs

    def _process_solve_request(self, comp, payload) -> tuple[bool, str]:
        ok, inputs = self._prepare_inputs(comp, payload)
        if not ok:
            return True, self._reply(comp, errors=[inputs])
        try:
            with self.guard.serial() if self.guard is not None else contextlib.nullcontext():
                result = comp.handler(*inputs)
        except GridshellError as exc:
            return True, self._reply(comp, errors=[str(exc)])
        except Exception as exc:   # noqa: BLE001 - never a dead component
            return True, self._reply(comp, errors=[f"internal error ({type(exc).__name__}: "
                                                   f"{exc}); please report it"])
        values = getattr(result, "values", result)
        if not isinstance(values, tuple):
            values = (values,)
        return True, self._reply(comp, values, warnings=getattr(result, "warnings", None))
