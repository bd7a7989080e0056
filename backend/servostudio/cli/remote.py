"""The CLI's way to a running server: ``--server URL`` and ``--token TOKEN`` (or ``SERVOSTUDIO_TOKEN``).

Commands that can work either on the data directory or through a server (``user``, ``token``) call the REST API
when ``--server`` is given. A refusal comes back as the server's error body, whose ``kind`` gives the exit code
as if the command had run here; a server that cannot be reached is ``unavailable`` (exit 5).
"""

from __future__ import annotations

import argparse
import json
import os
import urllib.error
import urllib.request
from dataclasses import dataclass
from typing import Any

from servostudio.errors import ErrorKind, ServoStudioError, Unavailable

TOKEN_VARIABLE = "SERVOSTUDIO_TOKEN"
TIMEOUT_SECONDS = 30.0


class RemoteRefusal(ServoStudioError):
    """The server refused or failed the request; its kind is the server's."""

    kind = ErrorKind.INTERNAL  # replaced by the kind of the server's answer

    def __init__(self, kind: ErrorKind, detail: str) -> None:
        super().__init__(detail)
        self.kind = kind


def add_options(parser: argparse.ArgumentParser, suppress: bool = False) -> None:
    """``--server`` and ``--token``; a sub-command's copy (``suppress``) leaves the global value alone when absent."""
    default = argparse.SUPPRESS if suppress else None
    parser.add_argument("--server", metavar="URL", default=default, help="a running server, e.g. http://127.0.0.1:8000")
    parser.add_argument(
        "--token", metavar="TOKEN", default=default, help=f"API token for --server (default: ${TOKEN_VARIABLE})"
    )


@dataclass(frozen=True)
class Remote:
    url: str
    token: str | None

    @classmethod
    def of(cls, args: argparse.Namespace) -> Remote | None:
        """The server the command names, or None to work on the data directory."""
        server = getattr(args, "server", None)
        if not server:
            return None
        return cls(server.rstrip("/"), getattr(args, "token", None) or os.environ.get(TOKEN_VARIABLE))

    def call(self, method: str, path: str, body: dict[str, Any] | None = None) -> Any:
        """The JSON answer of one REST call (None for 204)."""
        request = urllib.request.Request(self.url + path, method=method, headers=self._headers(body is not None))
        request.data = json.dumps(body).encode() if body is not None else None
        try:
            with urllib.request.urlopen(request, timeout=TIMEOUT_SECONDS) as response:
                content = response.read()
        except urllib.error.HTTPError as error:
            raise _refusal(error) from None
        except (urllib.error.URLError, OSError) as error:
            raise Unavailable(f"server {self.url} cannot be reached: {error}") from None
        return json.loads(content) if content else None

    def _headers(self, has_body: bool) -> dict[str, str]:
        headers = {"Accept": "application/json"}
        if has_body:
            headers["Content-Type"] = "application/json"
        if self.token:
            headers["Authorization"] = f"Bearer {self.token}"
        return headers


def _refusal(error: urllib.error.HTTPError) -> RemoteRefusal:
    try:
        body = json.loads(error.read())
        return RemoteRefusal(ErrorKind(body["kind"]), f"{body['detail']}")
    except (ValueError, KeyError, TypeError):
        return RemoteRefusal(ErrorKind.INTERNAL, f"HTTP {error.code} from the server without an error body")
