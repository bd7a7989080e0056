"""The holes issue #11 found in the motion guard, one test each (every one failed before the guard judged what the
drive will do): an enabling control word spelled as text or with bit 7 set, hidden in a drive file or a restore
job, sent through the terminal; another client moving or enabling an axis someone else answers for.

Each test reads the result back from the simulated drive: the axis did not enable, the target did not change."""

from __future__ import annotations

import pytest
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings

NODE = "/api/buses/sim/nodes/1"


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("holes")
    return admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",)), root / "data")


@pytest.fixture
def client(app):
    with api_client(app) as client:
        assert client.post("/api/buses/sim/scan").status_code == 200
        yield client
        client.put(f"{NODE}/state", json={"target": "switch-on-disabled"})


def switched_on(client) -> None:
    """Node 1 one command away from Operation enabled: a single control word 0x0F enables it."""
    answer = client.put(f"{NODE}/state", json={"target": "switched-on"})
    assert answer.json()["state"] == "SWITCHED ON", answer.text


def state(client) -> str:
    return client.get(f"{NODE}/state").json()["state"]


def refused(answer) -> str:
    assert answer.status_code == 409, answer.text
    assert answer.json()["kind"] == "refused_for_safety", answer.text
    return answer.json()["detail"]


@pytest.mark.parametrize("spelled", ["15.0", "1.5e1", 0x8F, "0x8F", 15.0])
def test_an_enabling_control_word_in_any_spelling_needs_the_controller(client, spelled):
    switched_on(client)
    refused(client.put(f"{NODE}/objects/controlword", json={"value": spelled}))
    assert state(client) == "SWITCHED ON"


def test_a_drive_file_that_enables_is_refused(client):
    switched_on(client)
    answer = client.put(
        f"{NODE}/files/DRIVEPAR.TXT?store=false", content="0x6040,0=15\n", headers={"Content-Type": "text/plain"}
    )
    refused(answer)
    assert state(client) == "SWITCHED ON"


def test_a_restore_job_that_enables_is_refused(client, app):
    folder = app.state.server.settings.projects_dir / "restore-holes" / "node1"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "DRIVEPAR.TXT").write_text("0x6040,0=15\n", encoding="latin-1")
    switched_on(client)
    job = client.post(
        "/api/buses/sim/restore",
        json={"directory": str(folder.parent), "nodes": [1], "files": ["DRIVEPAR.TXT"], "store": False},
    ).json()
    while (job := client.get(f"/api/jobs/{job['id']}").json())["state"] == "running":
        pass
    assert job["state"] == "failed", job
    assert "controller" in job["result"]["1"]["error"], job
    assert state(client) == "SWITCHED ON"


def test_the_terminal_cannot_enable_without_the_controller(client):
    switched_on(client)
    with client.websocket_connect("/api/ws/terminal") as terminal:
        terminal.send_json({"op": "write", "bus": "sim", "node": 1, "object": "controlword", "value": "15.0"})
        answer = terminal.receive_json()
    assert answer["type"] == "error" and answer["kind"] == "refused_for_safety", answer
    assert state(client) == "SWITCHED ON"


def _enabled_by_a(client, socket) -> dict[str, str]:
    """Client A (an event socket) arms node 1 and enables it; returns A's header."""
    a = {"X-Servo-Client": socket.receive_json()["client"]}
    assert client.post(f"{NODE}/control/arm", headers=a).status_code == 200
    answer = client.put(f"{NODE}/state", json={"target": "operation-enabled"}, headers=a)
    assert answer.json()["state"] == "OPERATION ENABLED", answer.text
    return a


def test_another_client_cannot_move_an_axis_someone_else_enabled(client):
    before = client.get(f"{NODE}/objects/target_velocity").json()["raw"]
    with client.websocket_connect("/api/ws/events?types=control") as a_socket:
        a = _enabled_by_a(client, a_socket)
        with client.websocket_connect("/api/ws/events?types=control") as b_socket:
            b = {"X-Servo-Client": b_socket.receive_json()["client"]}
            detail = refused(client.put(f"{NODE}/objects/target_velocity", json={"value": 500}, headers=b))
            assert a["X-Servo-Client"] in detail, detail
            refused(client.put(f"{NODE}/objects/target_velocity", json={"value": 500}))
        assert client.get(f"{NODE}/objects/target_velocity").json()["raw"] == before
        assert client.put(f"{NODE}/objects/target_velocity", json={"value": before}, headers=a).status_code == 200


def test_a_second_client_cannot_silently_take_over_an_enabled_axis(client):
    with client.websocket_connect("/api/ws/events?types=control") as a_socket:
        a = _enabled_by_a(client, a_socket)
        with client.websocket_connect("/api/ws/events?types=control") as b_socket:
            b = {"X-Servo-Client": b_socket.receive_json()["client"]}
            assert a["X-Servo-Client"] in refused(client.post(f"{NODE}/control/arm", headers=b))
            detail = refused(client.put(f"{NODE}/state", json={"target": "operation-enabled"}, headers=b))
            assert a["X-Servo-Client"] in detail, detail
        holder = client.get(f"{NODE}/control").json()["holder"]
        assert holder["client"] == a["X-Servo-Client"]
        assert state(client) == "OPERATION ENABLED"
