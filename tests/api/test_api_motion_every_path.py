"""Every path that can write to a drive goes through the one motion guard (issue #11, item 4).

Each path is tried twice against the server's simulated drives: without the axis's controller (refused, and the
drive read back is unchanged) and as the controller (done, and the drive read back shows it).  An *enabling*
write (a control word 0x0F to a drive in SWITCHED ON) goes through every path that can carry a control word; a
*motion object* (profile acceleration 0x6083, saved in DRIVEPAR.TXT) to an axis another client armed goes through
every path that carries parameter values, projects and commissioning included.  The CLI's own guard is tried in
tests/cli/test_cli_motion_guard.py."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator

import pytest
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings

NODE = "/api/buses/sim/nodes/1"
ACCELERATION = "0x6083"
Path = Callable[..., str | None]  # (client, headers, value) → None when done, else the refusal's text


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("paths")
    return admin_app(Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim",)), root / "data")


@pytest.fixture(scope="module")
def client(app):
    with api_client(app) as client:
        assert client.post("/api/projects/paths/scan", json={"bus": "sim", "create": True}).status_code == 200
        yield client


@pytest.fixture(autouse=True)
def disabled_afterwards(client):
    yield
    client.put(f"{NODE}/state", json={"target": "switch-on-disabled"})


@contextlib.contextmanager
def controller(client) -> Iterator[dict[str, str]]:
    """A live client (an event socket) that armed node 1; its header, for the requests made as the controller."""
    with client.websocket_connect("/api/ws/events?types=job") as socket:
        header = {"X-Servo-Client": socket.receive_json()["client"]}
        assert client.post(f"{NODE}/control/arm", headers=header).status_code == 200
        try:
            yield header
        finally:
            client.post(f"{NODE}/control/release", headers=header)


def refusal(answer) -> str | None:
    if answer.status_code == 200:
        return None
    assert answer.status_code == 409 and answer.json()["kind"] == "refused_for_safety", answer.text
    return answer.json()["detail"]


def job_refusal(client, answer) -> str | None:
    """A job's refusal: the error of its node (restore) or axis (commissioning)."""
    assert answer.status_code == 202, answer.text
    job = answer.json()
    deadline = time.monotonic() + 60
    while (job := client.get(f"/api/jobs/{job['id']}").json())["state"] == "running":
        assert time.monotonic() < deadline, job
        time.sleep(0.02)
    errors = [str(error) for error in _errors(job["result"])] + ([job["error"]] if job["error"] else [])
    return "; ".join(errors) or None


def _errors(result: object) -> Iterator[object]:
    """Every ``error`` inside a job result, however deep."""
    if isinstance(result, dict):
        if result.get("error"):
            yield result["error"]
        for value in result.values():
            yield from _errors(value)
    elif isinstance(result, list):
        for value in result:
            yield from _errors(value)


# ---- the paths ------------------------------------------------------------------------------------------------


def object_write(client, headers, key, value):
    return refusal(client.put(f"{NODE}/objects/{key}", json={"value": value}, headers=headers))


def state_route(client, headers, key, value):
    return refusal(client.put(f"{NODE}/state", json={"target": "operation-enabled"}, headers=headers))


def file_put(client, headers, key, value):
    text = f"{key},0={value}\n"
    answer = client.put(f"{NODE}/files/DRIVEPAR.TXT?store=false", content=text, headers=_text(headers))
    return refusal(answer)


def file_put_job(client, headers, key, value):
    text = f"{key},0={value}\n"
    return job_refusal(
        client, client.put(f"{NODE}/files/DRIVEPAR.TXT?store=false&job=true", content=text, headers=_text(headers))
    )


def restore_job(client, headers, key, value):
    folder = client.app.state.server.settings.projects_dir / "restores" / "node1"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "DRIVEPAR.TXT").write_text(f"{key},0={value}\n", encoding="latin-1")
    body = {"directory": str(folder.parent), "nodes": [1], "files": ["DRIVEPAR.TXT"], "store": False}
    return job_refusal(client, client.post("/api/buses/sim/restore", json=body, headers=headers))


def terminal(client, headers, key, value):
    message = {"op": "write", "bus": "sim", "node": 1, "object": key, "value": value, **_client_field(headers)}
    with client.websocket_connect("/api/ws/terminal") as socket:
        socket.send_json(message)
        answer = socket.receive_json()
    if answer["type"] == "written":
        return None
    assert answer["kind"] == "refused_for_safety", answer
    return answer["detail"]


def write_to_drive(client, headers, key, value):
    _set_in_project(client, key, value)
    body = {"addresses": [key], "store": False}
    return refusal(client.post("/api/projects/paths/axes/Axis1/write-to-drive", json=body, headers=headers))


def commissioning_download(client, headers, key, value):
    _set_in_project(client, key, value)
    body = {"direction": "download", "axes": ["Axis1"]}
    return job_refusal(client, client.post("/api/projects/paths/commission", json=body, headers=headers))


def _set_in_project(client, key, value):
    answer = client.put("/api/projects/paths/axes/Axis1/parameters", json={"values": {key: value}})
    assert answer.status_code == 200, answer.text


def _text(headers: dict[str, str]) -> dict[str, str]:
    return {**headers, "Content-Type": "text/plain"}


def _client_field(headers: dict[str, str]) -> dict[str, str]:
    return {"client": headers["X-Servo-Client"]} if headers else {}


# ---- the tests ------------------------------------------------------------------------------------------------

ENABLING = [object_write, state_route, file_put, file_put_job, restore_job, terminal]
PREPARING = [object_write, file_put, file_put_job, restore_job, terminal, write_to_drive, commissioning_download]


def state(client) -> str:
    return client.get(f"{NODE}/state").json()["state"]


@pytest.mark.parametrize("path", ENABLING, ids=lambda path: path.__name__)
def test_an_enabling_write_needs_the_armed_controller_on_every_path(client, path: Path):
    assert client.put(f"{NODE}/state", json={"target": "switched-on"}).json()["state"] == "SWITCHED ON"
    refused = path(client, {}, "0x6040", 15)
    assert refused is not None and "controller" in refused, refused
    assert state(client) == "SWITCHED ON"
    with controller(client) as header:
        assert path(client, header, "0x6040", 15) is None
        assert state(client) == "OPERATION ENABLED"


@pytest.mark.parametrize("path", PREPARING, ids=lambda path: path.__name__)
def test_a_motion_object_of_an_axis_another_client_armed_is_refused_on_every_path(client, path: Path):
    before = client.get(f"{NODE}/objects/{ACCELERATION}").json()["raw"]
    wanted = before + 4096
    with controller(client) as header:
        refused = path(client, {}, ACCELERATION, wanted)
        assert refused is not None and header["X-Servo-Client"] in refused, refused
        assert client.get(f"{NODE}/objects/{ACCELERATION}").json()["raw"] == before
        assert path(client, header, ACCELERATION, wanted) is None
        assert client.get(f"{NODE}/objects/{ACCELERATION}").json()["raw"] == wanted
        assert path(client, header, ACCELERATION, before) is None
