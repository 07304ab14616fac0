"""What the Hops server trusts (:class:`Guard`): the folders it reads and writes, who may talk
to it, how much.

* **Folders.** A ``Bundle`` input is resolved (symbolic links first, ``..`` after them; a
  relative path is taken inside the work directory) and accepted only inside the server's work
  directory or a root given with ``gridshell serve --allow DIR``. Every file and folder of the
  bundle must resolve inside them too (a symbolic link out of the bundle is refused, so
  ``/fabricate`` never writes through one), and so must the target mesh ``design.json``
  records (``/verify`` reads it).
* **Requests.** The ``Host`` header must name the address the server listens on (a loopback
  server: ``localhost``, ``127.0.0.1``, ``::1``; a server on every interface: an IP address
  or this machine's name), on its port: a page whose DNS name was rebound to 127.0.0.1 is
  refused. A request with an ``Origin`` (a web page's request: Grasshopper sends none) other
  than the server's own, or that a browser marks as cross-site (``Sec-Fetch-Site``), is
  refused. Both with HTTP 403.
* **Size.** A request body over ``max_body`` bytes is refused with HTTP 413 before it is read
  (:data:`MAX_BODY`; a 200k-triangle mesh is a 7.7 MB Hops request, measured).
* **One design at a time.** Solves run one after the other (:meth:`Guard.serial`); a request
  that waited :data:`QUEUE_TIMEOUT` seconds is answered that the server is busy.

Every refusal is a Hops reply (``{"values": [], "errors": [message]}``) that names the
problem and the fix.
"""
from __future__ import annotations

import contextlib
import io
import ipaddress
import json
import os
import socket
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

from gridshell.core.errors import InputError

#: the default request body limit, bytes: 8 x the Hops request of a 200k-triangle mesh
MAX_BODY = 64 * 2 ** 20
#: seconds a solve waits for the one before it
QUEUE_TIMEOUT = 600.0
_LOOPBACK = frozenset({"localhost", "127.0.0.1", "::1"})
_WILDCARD = frozenset({"0.0.0.0", "::", ""})


def _split_host(value: str) -> tuple[str, int | None]:
    """``(name, port)`` of a ``Host`` header or an origin's netloc (``"[::1]:5000"`` ->
    ``("::1", 5000)``); port None when absent; ValueError when malformed."""
    value = value.strip().lower()
    if value.startswith("["):
        name, closed, rest = value[1:].partition("]")
        if not closed:
            raise ValueError(value)
        port = rest[1:] if rest.startswith(":") else ("" if not rest else None)
        if port is None:
            raise ValueError(value)
    elif value.count(":") == 1:
        name, port = value.split(":")
    else:
        name, port = value, ""
    return name, (int(port) if port else None)


def _is_ip(name: str) -> bool:
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


@dataclass
class Guard:
    """The confinement of one Hops server: ``roots`` (resolved; the first is the work
    directory), the address it listens on (``host``, ``port``; port None: not checked) and
    the body limit ``max_body`` (bytes)."""

    roots: tuple[Path, ...]
    host: str = "127.0.0.1"
    port: int | None = None
    max_body: int = MAX_BODY
    queue_timeout: float = QUEUE_TIMEOUT
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    @classmethod
    def make(cls, workdir: Path, allow: Iterable[str | os.PathLike] = (), **kw: Any) -> "Guard":
        """The guard of a server writing into ``workdir`` that may also read and write the
        folders ``allow`` (each must exist); InputError naming a missing one."""
        roots = [Path(workdir).resolve()]
        for a in allow:
            p = Path(a).expanduser()
            if not p.is_dir():
                raise InputError(f"--allow {a}: no such folder; give an existing folder of "
                                 "design bundles")
            roots.append(p.resolve())
        if kw.get("max_body") is not None and not int(kw["max_body"]) > 0:
            raise InputError(f"--max-body must be a positive number of bytes, got "
                             f"{kw['max_body']}")
        return cls(tuple(roots), **{k: v for k, v in kw.items() if v is not None})

    # ------------------------------------------------------------------ folders

    def inside(self, path: Path) -> bool:
        """Whether the resolved ``path`` lies in one of the roots."""
        return any(path == r or path.is_relative_to(r) for r in self.roots)

    def _where(self) -> str:
        extra = [str(r) for r in self.roots[1:]]
        return (f"its work directory {self.roots[0]}"
                + (f" and the --allow folders {', '.join(extra)}" if extra else ""))

    def bundle_dir(self, text: Any) -> Path:
        """The resolved design bundle folder a ``Bundle`` input names, inside the roots with
        all it holds; InputError (the component's message) otherwise."""
        raw = str(text if text is not None else "").strip()
        if not raw or "\x00" in raw:
            raise InputError(f"{raw!r} is not a design bundle folder; connect the Bundle "
                             "output of a GG or NCP component")
        p = Path(raw)
        real = (p if p.is_absolute() else self.roots[0] / p).resolve()
        if not self.inside(real):
            raise InputError(f"{raw!r} is not a design bundle folder this server may use: it "
                             f"lies outside {self._where()}; connect the Bundle output of a "
                             "component of this server, or start it with --allow DIR")
        if not (real / "design.json").is_file():
            raise InputError(f"{raw!r} is not a design bundle folder (no design.json); "
                             "connect the Bundle output of a GG or NCP component")
        self._check_links(raw, real)
        self._check_target(raw, real)
        return real

    def _check_links(self, raw: str, real: Path) -> None:
        """InputError for an entry of the bundle ``real`` that resolves outside the roots."""
        for dirpath, dirs, files in os.walk(real):
            for name in dirs + files:
                entry = Path(dirpath) / name
                if entry.is_symlink() and not self.inside(entry.resolve()):
                    raise InputError(f"{raw}: {entry.relative_to(real)} is a link to "
                                     f"{os.readlink(entry)}, outside {self._where()}; the "
                                     "server reads and writes only there (copy the file in)")

    def _check_target(self, raw: str, real: Path) -> None:
        """InputError when the target mesh design.json records lies outside the roots (a
        design.json that cannot be read is left to the verification, which names it)."""
        try:
            target = (json.loads((real / "design.json").read_text()).get("params")
                      or {}).get("target")
        except (OSError, ValueError, AttributeError):
            return
        if isinstance(target, str) and target.strip() and \
                not self.inside(Path(target).resolve()):
            raise InputError(f"{raw}: design.json reads its target mesh {target}, outside "
                             f"{self._where()}; start the server with --allow on its folder")

    # ------------------------------------------------------------------ requests

    def _hosts(self) -> frozenset[str] | None:
        """The names a ``Host`` header may give (None: any IP address too)."""
        h = self.host.strip("[]").lower()
        if h in _WILDCARD:
            return None
        return _LOOPBACK | {h}

    def _host_ok(self, value: str) -> bool:
        try:
            name, port = _split_host(value)
        except ValueError:
            return False
        hosts = self._hosts()
        known = (name in _LOOPBACK or _is_ip(name) or name == socket.gethostname().lower()) \
            if hosts is None else name in hosts
        return known and (port is None or self.port is None or port == self.port)

    def refusal(self, environ: dict) -> tuple[int, str] | None:
        """``(status, message)`` of a request the server must not serve, or None."""
        host = environ.get("HTTP_HOST") or environ.get("SERVER_NAME", "")
        if not self._host_ok(host):
            return 403, (f"refused: the request is addressed to host {host!r}, not to this "
                         f"server ({self.host}); point the Hops component at "
                         f"http://localhost:{self.port or 'PORT'}/")
        origin = environ.get("HTTP_ORIGIN")
        site = environ.get("HTTP_SEC_FETCH_SITE", "").lower()
        if (origin is not None and not self._same_origin(origin)) or \
                site in ("cross-site", "same-site"):
            return 403, (f"refused: a request from the web page {origin or site!r}; the server "
                         "answers Grasshopper (Hops) only, never a browser page")
        size = environ.get("CONTENT_LENGTH") or ""
        if size.strip().isdigit() and int(size) > self.max_body:
            return 413, self._too_big(int(size))
        return None

    def _same_origin(self, origin: str) -> bool:
        scheme, sep, netloc = origin.partition("://")
        if not sep or scheme.lower() not in ("http", "https"):
            return False
        try:
            name, port = _split_host(netloc.rstrip("/"))
        except ValueError:
            return False
        port = port or (443 if scheme.lower() == "https" else 80)
        return self._host_ok(name) and (self.port is None or port == self.port)

    def _too_big(self, size: int | None) -> str:
        """The 413 message of a body of ``size`` bytes (None: unannounced, cut off)."""
        said = f"is {_size(size)}" if size is not None else "runs on"
        return (f"refused: the request body {said}, over the server's limit of "
                f"{_size(self.max_body)}; send a coarser mesh or start the server with a "
                "larger --max-body")

    @contextlib.contextmanager
    def serial(self) -> Iterator[None]:
        """One solve at a time; InputError when the one before takes over
        ``queue_timeout`` seconds."""
        if not self._lock.acquire(timeout=self.queue_timeout):
            raise InputError(f"the server is busy with another design for over "
                             f"{self.queue_timeout:g} s; try again when it is done")
        try:
            yield
        finally:
            self._lock.release()


def _size(n: int) -> str:
    return f"{n / 2 ** 20:.1f} MB" if n >= 2 ** 20 else f"{n} bytes"


def _hops_reply(start_response: Callable, status: int, message: str) -> list[bytes]:
    body = json.dumps({"values": [], "errors": [message]}).encode()
    reason = {403: "Forbidden", 413: "Request Entity Too Large"}.get(status, "Error")
    start_response(f"{status} {reason}", [("Content-Type", "application/json"),
                                          ("Content-Length", str(len(body)))])
    return [body]


class GuardMiddleware:
    """WSGI middleware refusing what :meth:`Guard.refusal` refuses, and reading a body of
    unannounced length (chunked) no further than ``max_body`` bytes."""

    def __init__(self, app: Callable, guard: Guard) -> None:
        self.app, self.guard = app, guard

    def __call__(self, environ: dict, start_response: Callable) -> Any:
        refused = self.guard.refusal(environ)
        if refused is not None:
            return _hops_reply(start_response, *refused)
        if not (environ.get("CONTENT_LENGTH") or "").strip() and \
                "chunked" in environ.get("HTTP_TRANSFER_ENCODING", "").lower():
            body = environ["wsgi.input"].read(self.guard.max_body + 1)
            if len(body) > self.guard.max_body:
                return _hops_reply(start_response, 413, self.guard._too_big(None))
            environ["wsgi.input"] = io.BytesIO(body)
            environ["CONTENT_LENGTH"] = str(len(body))
        return self.app(environ, start_response)
