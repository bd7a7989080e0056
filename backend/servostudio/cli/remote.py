"""The CLI's way to a running server: ``--server URL`` and ``--token TOKEN``, or the defaults of the environment
(``SERVOSTUDIO_SERVER``, ``SERVOSTUDIO_TOKEN``) and of the configuration file (``server = "…"``, ``token = "…"``
in ``$SERVOSTUDIO_CONFIG``, else ``$XDG_CONFIG_HOME/servostudio/config.toml``, else
``~/.config/servostudio/config.toml``).

A command names its target explicitly or takes the default: ``--server`` (the server), ``--bus`` (a bus this
process opens itself: headless use, no server) or ``--data-dir`` (the data directory) win over the environment and
the file, so a script that names its bus never goes through a server by surprise.  Every command that can work
through a server calls :meth:`Remote.of`.  A refusal comes back as the server's error body, whose ``kind`` gives the
exit code as if the command had run here; a server that cannot be reached is ``unavailable`` (exit 5).
"""

from __future__ import annotations

import argparse
import json
import os
import tomllib
import urllib.error
import urllib.parse
import urllib.request
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from servostudio.errors import ErrorKind, InvalidInput, NotFound, ServoStudioError, Unavailable
from servostudio.transport.spec import parse_bus_spec

TOKEN_VARIABLE = "SERVOSTUDIO_TOKEN"
SERVER_VARIABLE = "SERVOSTUDIO_SERVER"
CONFIG_VARIABLE = "SERVOSTUDIO_CONFIG"
TIMEOUT_SECONDS = 30.0
#: what names a target of its own on the command line: then no default server is used
_LOCAL_TARGETS = ("bus", "data_dir")


class RemoteRefusal(ServoStudioError):
    """The server refused or failed the request; its kind is the server's."""

    kind = ErrorKind.INTERNAL  # replaced by the kind of the server's answer

    def __init__(self, kind: ErrorKind, detail: str) -> None:
        super().__init__(detail)
        self.kind = kind


class BadConfig(InvalidInput):
    """The configuration file cannot be read as TOML with text values."""


class NoSuchServerBus(NotFound):
    """``--bus`` names no bus the server has open (by name or by spec)."""


def add_options(parser: argparse.ArgumentParser, suppress: bool = False) -> None:
    """``--server`` and ``--token``; a sub-command's copy (``suppress``) leaves the global value alone when absent."""
    default = argparse.SUPPRESS if suppress else None
    parser.add_argument(
        "--server",
        metavar="URL",
        default=default,
        help=f"a running server, e.g. http://127.0.0.1:8000 (default: ${SERVER_VARIABLE}, else the config file)",
    )
    parser.add_argument(
        "--token", metavar="TOKEN", default=default, help=f"API token for --server (default: ${TOKEN_VARIABLE})"
    )


def config_path() -> Path:
    """Where the CLI's defaults live: ``$SERVOSTUDIO_CONFIG``, else the XDG configuration directory."""
    if os.environ.get(CONFIG_VARIABLE):
        return Path(os.environ[CONFIG_VARIABLE])
    base = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(base) / "servostudio" / "config.toml"


def configured(key: str) -> str | None:
    """A text value of the configuration file (None when the file or the key is absent)."""
    path = config_path()
    try:
        values = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as error:
        raise BadConfig(f"{path}: {error}") from None
    value = values.get(key)
    if value is not None and not isinstance(value, str):
        raise BadConfig(f'{path}: {key} must be a text, e.g. {key} = "…"')
    return value


@dataclass(frozen=True)
class Remote:
    url: str
    token: str | None

    @classmethod
    def of(cls, args: argparse.Namespace) -> Remote | None:
        """The server the command works through, or None to work here (on its own bus or the data directory).

        ``--server`` first; a command that names a bus or data directory of its own works here; otherwise the
        default server of the environment or the configuration file, if any."""
        server = getattr(args, "server", None)
        if not server:
            if any(getattr(args, name, None) is not None for name in _LOCAL_TARGETS):
                return None
            server = os.environ.get(SERVER_VARIABLE) or configured("server")
        if not server:
            return None
        token = getattr(args, "token", None) or os.environ.get(TOKEN_VARIABLE) or configured("token")
        return cls(server.rstrip("/"), token)

    def call(self, method: str, path: str, body: dict[str, Any] | None = None) -> Any:
        """The JSON answer of one REST call (None for 204)."""
        data = json.dumps(body).encode() if body is not None else None
        content, _ = self.exchange(method, path, data, "application/json" if body is not None else None)
        return json.loads(content) if content else None

    def exchange(
        self, method: str, path: str, data: bytes | None = None, content_type: str | None = None
    ) -> tuple[bytes, dict[str, str]]:
        """One REST call with any body: the answer's bytes and headers (a refusal raises with the server's kind)."""
        headers = self._headers(data is not None)
        if content_type is not None:
            headers["Content-Type"] = content_type
        request = urllib.request.Request(self.url + path, data=data, method=method, headers=headers)
        try:
            with urllib.request.urlopen(request, timeout=TIMEOUT_SECONDS) as response:
                return response.read(), dict(response.headers.items())
        except urllib.error.HTTPError as error:
            raise _refusal(error) from None
        except (urllib.error.URLError, OSError) as error:
            raise Unavailable(f"server {self.url} cannot be reached: {error}") from None

    def bus(self, given: str | None) -> str:
        """The server's name of the bus ``--bus`` gives: its name, or the spec of a bus the server has open (any
        spelling of it); without ``--bus``, the server's only bus."""
        buses = self.call("GET", "/api/buses")
        names = [str(bus["id"]) for bus in buses]
        if given is None:
            if len(names) == 1:
                return names[0]
            raise NoSuchServerBus(f"server {self.url} has {len(names)} buses open ({', '.join(names) or 'none'}): "
                                  "name one with --bus")  # fmt: skip
        if given in names:
            return given
        wanted = _spec_or_none(given)
        for bus in buses:
            if wanted is not None and _spec_or_none(str(bus["spec"])) == wanted:
                return str(bus["id"])
        raise NoSuchServerBus(f"server {self.url} has no bus {given!r} open (open: {', '.join(names) or 'none'})")

    def _headers(self, has_body: bool) -> dict[str, str]:
        headers = {"Accept": "application/json"}
        if has_body:
            headers["Content-Type"] = "application/json"
        if self.token:
            headers["Authorization"] = f"Bearer {self.token}"
        return headers


def quoted(text: str) -> str:
    """A name as one path segment of a REST URL."""
    return urllib.parse.quote(text, safe="")


def _spec_or_none(text: str) -> object:
    try:
        return parse_bus_spec(text)
    except ServoStudioError:
        return None


def _refusal(error: urllib.error.HTTPError) -> RemoteRefusal:
    try:
        body = json.loads(error.read())
        return RemoteRefusal(ErrorKind(body["kind"]), f"{body['detail']}")
    except (ValueError, KeyError, TypeError):
        return RemoteRefusal(ErrorKind.INTERNAL, f"HTTP {error.code} from the server without an error body")
