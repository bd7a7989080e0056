"""REST and WebSocket API of the communication server against the simulated drives (socketcand)."""

from __future__ import annotations

import threading
import time

import httpx
import pytest
import uvicorn
from tests.support.access import admin_app, api_client, bearer, token

from servostudio.api.app import Settings, create_app


@pytest.fixture(scope="module")
def client(socketcand, tmp_path_factory):
    projects, exports = tmp_path_factory.mktemp("projects"), tmp_path_factory.getbasetemp()  # tests' tmp_path
    settings = Settings(projects_dir=projects, export_dir=exports, buses=[socketcand.spec])
    app = admin_app(settings, tmp_path_factory.mktemp("data"))
    with api_client(app) as test_client:
        deadline = time.monotonic() + 5
        while not test_client.get("/api/buses").json()[0]["connected"] and time.monotonic() < deadline:
            time.sleep(0.05)
        assert test_client.post("/api/buses/socketcand/scan").status_code == 200
        yield test_client


def test_bus_listing_and_scan(client, socketcand):
    buses = client.get("/api/buses").json()
    assert buses[0]["spec"] == socketcand.spec + "/can0" and buses[0]["connected"]
    nodes = client.post("/api/buses/socketcand/scan").json()
    assert [node["node"] for node in nodes] == [1, 2, 3]
    assert nodes[0]["device"] == "xtrapulspac"


def test_read_write_and_refusals(client):
    value = client.get("/api/buses/socketcand/nodes/1/objects/statusword").json()
    assert value["index"] == 0x6041 and value["access"] == "ro"
    written = client.put("/api/buses/socketcand/nodes/1/objects/0x60F9,2", json={"value": 123}).json()
    assert written["raw"] == 123
    assert client.get("/api/buses/socketcand/nodes/1/objects/0x60F9,2").json()["raw"] == 123
    refused = client.put("/api/buses/socketcand/nodes/1/objects/0x3410,1", json={"value": 99})
    assert refused.status_code == 422
    assert "99 is outside 1..24" in refused.json()["detail"]
    assert client.put("/api/buses/socketcand/nodes/1/objects/statusword", json={"value": 1}).status_code == 422
    assert client.get("/api/buses/socketcand/nodes/1/objects/0x2FFE").status_code == 404
    assert client.get("/api/buses/nope/nodes/1/objects/0x1000").status_code == 404
    many = client.post("/api/buses/socketcand/nodes/2/read", json={"objects": ["0x1000", "0x2FFE"]}).json()
    assert many[0]["value"]["raw"] > 0 and "not in the xtrapulspac dictionary" in many[1]["error"]


def test_state_and_faults(client):
    with client.websocket_connect("/api/ws/events?types=job") as socket:
        motion_client = {"X-Servo-Client": socket.receive_json()["client"]}
        assert client.post("/api/buses/socketcand/nodes/2/control/arm", headers=motion_client).status_code == 200
        enabled = client.put(
            "/api/buses/socketcand/nodes/2/state", json={"target": "operation-enabled"}, headers=motion_client
        ).json()
        assert enabled["state"] == "OPERATION ENABLED"
        disabled = client.put("/api/buses/socketcand/nodes/2/state", json={"target": "switch-on-disabled"}).json()
        assert disabled["state"] == "SWITCH ON DISABLED"
    faults = client.get("/api/buses/socketcand/nodes/2/faults").json()
    assert faults["fault"] is False and faults["faults"] == []


def test_file_download_and_corrupted_upload(client):
    text = client.get("/api/buses/socketcand/nodes/3/files/USER_PAR.TXT").text
    assert text.startswith("; USER_PAR.TXT of node 3")
    lines = text.splitlines()
    lines[3] = lines[3].split("=")[0] + "=not-a-number"
    answer = client.put(
        "/api/buses/socketcand/nodes/3/files/USER_PAR.TXT",
        content="\n".join(lines),
        headers={"content-type": "text/plain"},
    )
    assert answer.status_code == 422
    assert "USER_PAR.TXT:4:" in answer.json()["detail"]
    good = client.put(
        "/api/buses/socketcand/nodes/3/files/USER_PAR.TXT?store=false",
        content=text,
        headers={"content-type": "text/plain"},
    ).json()
    assert good["ok"] is True


def test_backup_job_with_progress_events(client, tmp_path):
    with client.websocket_connect("/api/ws/events?types=progress,job") as socket:
        job = client.post(
            "/api/buses/socketcand/backup",
            json={"directory": str(tmp_path), "nodes": [1, 2], "files": ["USER_PAR.TXT"]},
        ).json()
        assert job["state"] == "running"
        seen = []
        while True:
            event = socket.receive_json()
            seen.append(event)
            if event["type"] == "job":
                break
    assert event["state"] == "done", event
    assert any(item["type"] == "progress" and item["done"] == item["total"] for item in seen)
    assert (tmp_path / "node1" / "USER_PAR.TXT").is_file() and (tmp_path / "node2" / "USER_PAR.TXT").is_file()
    assert client.get(f"/api/jobs/{job['id']}").json()["state"] == "done"


def test_terminal_watch_read_and_write(client):
    with client.websocket_connect("/api/ws/terminal") as socket:
        items = [{"bus": "socketcand", "node": node, "object": "statusword"} for node in (1, 2, 3)]
        socket.send_json({"op": "watch", "items": items, "period_ms": 100})
        first, second = socket.receive_json(), socket.receive_json()
        assert first["type"] == second["type"] == "values"
        assert [row["node"] for row in second["rows"]] == [1, 2, 3]
        socket.send_json({"op": "write", "bus": "socketcand", "node": 1, "object": "0x60F9,2", "value": 77})
        while (answer := socket.receive_json())["type"] == "values":
            pass
        assert answer["type"] == "written" and answer["value"]["raw"] == 77
        too_many = [{"bus": "socketcand", "node": node, "object": "0x1000"} for node in range(1, 6)]
        socket.send_json({"op": "watch", "items": too_many})
        while (answer := socket.receive_json())["type"] == "values":
            pass
        assert answer["type"] == "error" and "up to 4 axes" in answer["detail"]


def test_real_http_through_uvicorn(socketcand, tmp_path):
    app = create_app(Settings(projects_dir=tmp_path, buses=[socketcand.spec], data_dir=tmp_path / "data"))
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=0, log_level="warning"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    try:
        deadline = time.monotonic() + 10
        while not (server.started and server.servers) and time.monotonic() < deadline:
            time.sleep(0.05)
        port = server.servers[0].sockets[0].getsockname()[1]
        headers = bearer(token(tmp_path / "data"))  # a script with an API token
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", headers=headers, timeout=10) as http:
            while not http.get("/api/buses").json()[0]["connected"] and time.monotonic() < deadline:
                time.sleep(0.05)
            assert [node["node"] for node in http.post("/api/buses/socketcand/scan").json()] == [1, 2, 3]
            assert http.get("/api/buses/socketcand/nodes/2/objects/0x1000").json()["raw"] > 0
            assert "/api/buses/{bus}/nodes/{node}/objects/{key}" in http.get("/openapi.json").json()["paths"]
    finally:
        server.should_exit = True
        thread.join(10)


def test_enabling_needs_a_live_client_and_its_axes_stop_when_it_goes(client):
    refused = client.put("/api/buses/socketcand/nodes/3/state", json={"target": "operation-enabled"})
    assert refused.status_code == 409 and "live client" in refused.json()["detail"]
    forged = client.put(
        "/api/buses/socketcand/nodes/3/state",
        json={"target": "operation-enabled"},
        headers={"X-Servo-Client": "not-a-connected-client"},
    )
    assert forged.status_code == 409
    # one command from enabled: a control word 0x0F would enable it
    assert client.put("/api/buses/socketcand/nodes/3/state", json={"target": "switched-on"}).status_code == 200
    raw_enable = client.put("/api/buses/socketcand/nodes/3/objects/controlword", json={"value": 0x0F})
    assert raw_enable.status_code == 409 and "live client" in raw_enable.json()["detail"]
    with client.websocket_connect("/api/ws/terminal") as terminal:
        terminal.send_json({"op": "write", "bus": "socketcand", "node": 3, "object": "controlword", "value": 15})
        answer = terminal.receive_json()
        assert answer["type"] == "error" and "live client" in answer["detail"]
    assert client.get("/api/buses/socketcand/nodes/3/state").json()["state"] == "SWITCHED ON"

    with client.websocket_connect("/api/ws/events?types=job") as socket:
        hello = socket.receive_json()
        assert hello["type"] == "hello"
        arming = client.post("/api/buses/socketcand/nodes/3/control/arm", headers={"X-Servo-Client": hello["client"]})
        assert arming.json()["holder"]["client"] == hello["client"]
        enabled = client.put(
            "/api/buses/socketcand/nodes/3/state",
            json={"target": "operation-enabled"},
            headers={"X-Servo-Client": hello["client"]},
        ).json()
        assert enabled["state"] == "OPERATION ENABLED"
    # The client went away: the server quick-stops the axis it enabled.
    deadline = time.monotonic() + 10
    state = "OPERATION ENABLED"
    while state == "OPERATION ENABLED" and time.monotonic() < deadline:
        time.sleep(0.05)
        state = client.get("/api/buses/socketcand/nodes/3/state").json()["state"]
    assert state in ("QUICK STOP ACTIVE", "SWITCH ON DISABLED"), state
    client.put("/api/buses/socketcand/nodes/3/state", json={"target": "switch-on-disabled"})
