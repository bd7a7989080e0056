"""The REST tests' common steps of a live client (procedures, identification, frequency response, the quick test's
motions, sequences): an axis armed over the client's event socket and released afterwards (or lost with the socket),
the keepalives of a held motion, and a job followed until it ends."""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator

from tests.support.waits import wait_for

NODE = "/api/buses/sim/nodes/1"


@contextlib.contextmanager
def armed(
    client, node: str = NODE, events: str = "progress,job", release: bool = True
) -> Iterator[tuple[object, dict[str, str]]]:
    """The event socket (subscribed to the ``events`` types) of a client that armed the axis, and the header naming
    it. The axis is released on exit; with ``release=False`` it is not, so leaving closes the socket of its armed
    controller: the controller is lost, as a closed browser tab loses it (what the controller-loss tests try)."""
    with client.websocket_connect(f"/api/ws/events?types={events}") as socket:
        header = {"X-Servo-Client": socket.receive_json()["client"]}
        assert client.post(f"{node}/control/arm", headers=header).status_code == 200
        try:
            yield socket, header
        finally:
            if release:
                client.post(f"{node}/control/release", headers=header)


@contextlib.contextmanager
def holding(socket, bus: str, node: int) -> Iterator[None]:
    """Keepalives of node ``node`` on ``bus`` every 20 ms from a thread of their own while the block runs, as a held
    button sends them (also while the motion's request is on its way)."""
    stop = threading.Event()

    def send() -> None:
        while not stop.wait(0.02):
            socket.send_json({"type": "keepalive", "bus": bus, "node": node})

    sender = threading.Thread(target=send, daemon=True)
    sender.start()
    try:
        yield
    finally:
        stop.set()
        sender.join()


def finished(client, job: str, timeout: float = 60.0) -> dict:
    """The job's answer once it no longer runs."""
    return wait_for(
        lambda: client.get(f"/api/jobs/{job}").json(),
        lambda state: state["state"] != "running",
        f"job {job} ended",
        timeout,
        0.1,
        lambda state: f"still {state['state']}",
    )
