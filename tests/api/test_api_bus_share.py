"""A bus of the server shared with the user's own scripts (issue #14 point 10): python ``canopen`` reads and writes
a drive through the server's socketcand endpoint while the UI's live polling (the values socket) goes on; its SDO
transfers are the server's in turn, its writes pass the motion guard, its PDOs never reach the bus."""

from __future__ import annotations

import json
import threading
import time

import canopen
import httpx
import pytest
from websockets.sync.client import connect

WATCHED = ["statusword", "0x6064", "0x606C"]


@pytest.fixture
def share(live_server):
    answer = httpx.put(f"{live_server.url}/api/buses/sim/share", json={"port": 0}, timeout=15)
    assert answer.status_code == 200, answer.text
    yield answer.json()
    httpx.delete(f"{live_server.url}/api/buses/sim/share", timeout=15)


class Polling:
    """The dashboard's live values: a terminal watch of node 1 every 50 ms, every answer kept."""

    def __init__(self, url: str) -> None:
        self.rows: list[dict] = []
        self._stop = threading.Event()
        self._socket = connect(url.replace("http", "ws") + "/api/ws/terminal")
        items = [{"bus": "sim", "node": 1, "object": key} for key in WATCHED]
        self._socket.send(json.dumps({"op": "watch", "items": items, "period_ms": 50}))
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self) -> None:
        while not self._stop.is_set():
            try:
                message = json.loads(self._socket.recv(timeout=0.5))
            except TimeoutError:
                continue
            if message["type"] == "values":
                self.rows.extend(message["rows"])

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        self._socket.close()


@pytest.fixture
def network(share):
    network = canopen.Network()
    network.connect(interface="socketcand", channel=share["channel"], host=share["host"], port=share["port"])
    yield network
    network.disconnect()


def test_canopen_reads_and_writes_through_the_share_while_the_ui_polls(live_server, share, network):
    assert (share["bus"], share["host"], share["channel"]) == ("sim", "127.0.0.1", "can0")
    polling = Polling(live_server.url)
    try:
        node = network.add_node(1, canopen.ObjectDictionary())
        time.sleep(0.3)
        before = len(polling.rows)
        names = {node.sdo.upload(0x1008, 0) for _ in range(20)}  # segmented: 11 bytes
        words = {int.from_bytes(node.sdo.upload(0x6041, 0), "little") & 0x4F for _ in range(50)}
        node.sdo.download(0x60F9, 2, (88).to_bytes(2, "little"))
        during = len(polling.rows) - before
    finally:
        polling.close()
    assert names == {b"XtrapulsPac"} and words == {0x40}  # switch on disabled, read 50 times without a mix-up
    read = httpx.get(f"{live_server.url}/api/buses/sim/nodes/1/objects/0x60F9,2", timeout=15).json()
    assert read["raw"] == 88
    assert during >= 3 * len(WATCHED) and not [row for row in polling.rows if row.get("error")]


def test_the_share_keeps_the_motion_guard_and_drops_pdos(live_server, share, network):
    node = network.add_node(2, canopen.ObjectDictionary())
    node.sdo.download(0x6040, 0, (0x06).to_bytes(2, "little"))  # shutdown, switch on: no motion yet
    node.sdo.download(0x6040, 0, (0x07).to_bytes(2, "little"))
    with pytest.raises(canopen.SdoAbortedError) as refused:
        node.sdo.download(0x6040, 0, (0x0F).to_bytes(2, "little"))  # enable operation: needs an armed client
    assert refused.value.code == 0x08000022
    state = httpx.get(f"{live_server.url}/api/buses/sim/nodes/2/state", timeout=15).json()
    assert state["state"] != "OPERATION ENABLED"
    network.send_message(0x202, b"\x0f\x00")  # an RPDO with the same control word
    deadline = time.monotonic() + 5
    while httpx.get(f"{live_server.url}/api/buses/sim/share", timeout=15).json()["dropped"] < 1:
        assert time.monotonic() < deadline, "the RPDO was not dropped"
        time.sleep(0.05)
    node.sdo.download(0x6040, 0, (0x00).to_bytes(2, "little"))


def test_a_share_binds_to_loopback_only(live_server):
    answer = httpx.put(f"{live_server.url}/api/buses/sim/share", json={"host": "0.0.0.0"}, timeout=15)
    assert answer.status_code == 422 and "loopback" in answer.json()["detail"]
    assert httpx.get(f"{live_server.url}/api/buses/sim/share", timeout=15).status_code == 404


def test_serve_share_opts_a_bus_in_at_start(tmp_path):
    from tests.support.live_server import LiveServer, free_port

    port = free_port()
    (tmp_path / "projects").mkdir()
    server = LiveServer(tmp_path / "projects", ["--share", f"sim=127.0.0.1:{port}"])
    try:
        server.wait_ready()
        shared = httpx.get(f"{server.url}/api/buses/sim/share", timeout=15).json()
        assert (shared["host"], shared["port"]) == ("127.0.0.1", port)
        network = canopen.Network()
        network.connect(interface="socketcand", channel="can0", host="127.0.0.1", port=port)
        try:
            assert network.add_node(3, canopen.ObjectDictionary()).sdo.upload(0x1000, 0) == (0x00020192).to_bytes(
                4, "little"
            )
        finally:
            network.disconnect()
    finally:
        server.stop()
