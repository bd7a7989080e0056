"""The CLI as a live client of a running server (``--server URL``): what a browser tab is, from a terminal.

Motion through a server needs an armed, live controller (``docs/motion-safety.md``): an open ``/api/ws/events``
socket whose hello names the client id that every motion request carries (``X-Servo-Client``).  A command that
moves an axis through ``--server`` opens one with :class:`LiveClient`, arms the axis, and while it runs sends the
hold-to-run keepalive (``{"type": "keepalive", "bus", "node"}`` every ``KEEPALIVE_PERIOD`` seconds) from a thread
of its own, so a command that is killed, hangs or loses the network stops sending it and the server quick-stops the
axis within the hold timeout; closing the socket (or the process dying) makes the server quick-stop what it held.

The socket is opened like the REST calls of ``cli.remote``: the same URL (``http`` → ``ws``, ``https`` → ``wss``),
the API token as ``Authorization: Bearer`` (password-less servers need none), no ``Origin`` (a script is no page of
a foreign origin; the server's Host check sees the URL's host).
"""

from __future__ import annotations

import contextlib
import json
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from websockets.exceptions import WebSocketException
from websockets.sync.client import ClientConnection, connect

from servostudio.cli.remote import Remote
from servostudio.errors import ServoStudioError, Unavailable
from servostudio.services.motion.hold import KEEPALIVE_PERIOD

#: seconds to wait for the socket to open and say hello
OPEN_TIMEOUT = 10.0
#: the events the socket subscribes to: few, so an unread backlog never builds up
EVENT_TYPES = "control,control_request,motion"
CLIENT_HEADER = "X-Servo-Client"


class LiveClientError(Unavailable):
    """The event socket could not be opened, did not say hello, or closed while the command needed it."""


@dataclass(frozen=True)
class ClientRemote(Remote):
    """REST calls that name the live client (``X-Servo-Client``), as every motion request must."""

    client: str = ""

    def _headers(self, has_body: bool) -> dict[str, str]:
        return super()._headers(has_body) | {CLIENT_HEADER: self.client}


class LiveClient:
    """One event socket of a CLI command: its client id, REST calls in its name, keepalives while it holds axes.

    Use it as a context manager; leaving the block stops the keepalives and closes the socket, after which the
    server quick-stops every axis the client still held."""

    def __init__(self, remote: Remote, period: float = KEEPALIVE_PERIOD) -> None:
        self.remote = remote
        self.period = period
        self.client = ""
        self.events: list[dict[str, Any]] = []
        self._socket: ClientConnection | None = None
        self._held: set[tuple[str, int]] = set()
        self._lock = threading.Lock()
        self._stopping = threading.Event()
        self._threads: list[threading.Thread] = []

    # ---- the socket --------------------------------------------------------------------------------------------

    def open(self) -> LiveClient:
        """Connect and read the hello; starts the reader (events) and the keepalive sender."""
        try:
            self._socket = connect(
                _events_url(self.remote.url),
                additional_headers=_auth(self.remote),
                open_timeout=OPEN_TIMEOUT,
                max_size=2**20,
                legacy=True,  # the socket outlives this call (open … close), so no `with connect(...)` block
            )
            hello = json.loads(self._socket.recv(timeout=OPEN_TIMEOUT))
        except (OSError, TimeoutError, WebSocketException, ValueError) as error:
            raise LiveClientError(f"the event socket of {self.remote.url} cannot be opened: {error}") from None
        if not isinstance(hello, dict) or hello.get("type") != "hello" or not hello.get("client"):
            raise LiveClientError(f"the event socket of {self.remote.url} did not say hello: {hello!r}")
        self.client = str(hello["client"])
        self._start(self._read, "live-client-events")
        self._start(self._send_keepalives, "live-client-keepalive")
        return self

    def close(self) -> None:
        """Stop the keepalives and close the socket: the server quick-stops what this client still held."""
        self._stopping.set()
        if self._socket is not None:
            self._socket.close()
        for thread in self._threads:
            thread.join(timeout=2.0)

    def __enter__(self) -> LiveClient:
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _start(self, target: Any, name: str) -> None:
        thread = threading.Thread(target=target, name=name, daemon=True)
        self._threads.append(thread)
        thread.start()

    def _read(self) -> None:
        """Keep the socket read (events are kept for the command); ends when it closes."""
        assert self._socket is not None
        with contextlib.suppress(WebSocketException, OSError):
            for message in self._socket:
                event = json.loads(message)
                if isinstance(event, dict):
                    self.events.append(event)

    def _send_keepalives(self) -> None:
        """Every ``period`` seconds, one keepalive per held axis, until the client closes."""
        while not self._stopping.wait(self.period):
            with self._lock:
                held = sorted(self._held)
            for bus, node in held:
                if not self._send({"type": "keepalive", "bus": bus, "node": node}):
                    return

    def _send(self, message: dict[str, object]) -> bool:
        assert self._socket is not None
        try:
            self._socket.send(json.dumps(message))
        except (WebSocketException, OSError):
            return False
        return True

    # ---- in the client's name ---------------------------------------------------------------------------------

    @property
    def rest(self) -> ClientRemote:
        """The server's REST API, each call naming this client."""
        if not self.client:
            raise LiveClientError("the live client is not open")
        return ClientRemote(self.remote.url, self.remote.token, self.client)

    def call(self, method: str, path: str, body: dict[str, Any] | None = None) -> Any:
        return self.rest.call(method, path, body)

    def arm(self, bus: str, node: int) -> Any:
        """Become the axis's controller (409 naming the holder if another client has it)."""
        return self.call("POST", f"{axis_path(bus, node)}/control/arm")

    def release(self, bus: str, node: int) -> Any:
        """Disarm the axis (the server quick-stops it if it is still enabled)."""
        self.unhold(bus, node)
        return self.call("POST", f"{axis_path(bus, node)}/control/release")

    def hold(self, bus: str, node: int) -> None:
        """Send keepalives for the axis from now on (one right away, so a hold-to-run motion starts held)."""
        with self._lock:
            self._held.add((bus, node))
        self._send({"type": "keepalive", "bus": bus, "node": node})

    def unhold(self, bus: str, node: int) -> None:
        with self._lock:
            self._held.discard((bus, node))

    @contextlib.contextmanager
    def holding(self, bus: str, node: int) -> Iterator[LiveClient]:
        """Arm the axis and keep it alive for the block; released afterwards (a quick stop if still enabled)."""
        self.arm(bus, node)
        self.hold(bus, node)
        try:
            yield self
        finally:
            with contextlib.suppress(ServoStudioError):  # already gone (taken over, server down): nothing to do
                self.release(bus, node)


def axis_path(bus: str, node: int) -> str:
    return f"/api/buses/{bus}/nodes/{node}"


def _events_url(url: str) -> str:
    scheme, _, rest = url.partition("://")
    socket_scheme = {"http": "ws", "https": "wss"}.get(scheme.lower(), scheme)
    return f"{socket_scheme}://{rest.rstrip('/')}/api/ws/events?types={EVENT_TYPES}"


def _auth(remote: Remote) -> dict[str, str]:
    return {"Authorization": f"Bearer {remote.token}"} if remote.token else {}
