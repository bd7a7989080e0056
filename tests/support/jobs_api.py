"""The REST job tests' common steps (procedures, identification, frequency response): a live client that arms
node 1 of the ``sim`` bus and releases it afterwards, and a job followed until it ends."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator

NODE = "/api/buses/sim/nodes/1"


@contextlib.contextmanager
def armed(client, node: str = NODE) -> Iterator[tuple[object, dict[str, str]]]:
    """The event socket (progress and job events) of a client that armed the axis, and the header naming it."""
    with client.websocket_connect("/api/ws/events?types=progress,job") as socket:
        header = {"X-Servo-Client": socket.receive_json()["client"]}
        assert client.post(f"{node}/control/arm", headers=header).status_code == 200
        try:
            yield socket, header
        finally:
            client.post(f"{node}/control/release", headers=header)


def finished(client, job: str, timeout: float = 60.0) -> dict:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        state = client.get(f"/api/jobs/{job}").json()
        if state["state"] != "running":
            return state
        time.sleep(0.1)
    raise AssertionError(f"job {job} still running")
