"""A recorder capture of two axes through the REST routes (docs/scope.md §8): the check states both axes' channels,
the job arms both recorders with one broadcast frame and says so in its result, the capture joins both."""

from __future__ import annotations

import time

from tests.support.access import admin_app, api_client
from tests.support.jobs_api import finished

from servostudio.services.settings import Settings

DEFINITION = {"channels": ["0x6064,0", "0x6041,0@2"], "samples": 100, "source": "recorder"}


def test_a_two_axis_recorder_capture_job_says_how_it_was_armed(tmp_path, sim_opener):
    app = admin_app(Settings(projects_dir=tmp_path, static_dir=tmp_path / "no-ui", buses=[]), tmp_path / "data")
    with api_client(app) as client:
        sim_opener(app.state.server.connections, "sim:1,2")
        bus = app.state.server.connections.list()[0].id
        scope = f"/api/buses/{bus}/nodes/1/scope"
        plan = client.post(f"{scope}/check", json=DEFINITION).json()
        assert plan["source"] == "recorder" and [c["key"] for c in plan["channels"]] == ["0x6064,0", "0x6041,0@2"]
        job = finished(client, client.post(f"{scope}/captures", json=DEFINITION).json()["id"])
        assert job["state"] == "done", job
        result = job["result"]
        assert result["arm"] == "broadcast" and result["alignment_ns"] == 250_000, result
        made = client.get(f"{scope}/captures/{result['capture']}").json()
        assert made["samples"] == 100 and made["alignment_ns"] == 250_000 and made["source"] == "recorder"
        assert [channel["key"] for channel in made["channels"]] == ["0x6064,0", "0x6041,0@2"]
        normal = {**DEFINITION, "trigger": {"source": "0x6064,0", "edge": "rising", "level": 1}, "mode": "normal"}
        refused = client.post(f"{scope}/check", json=normal)
        assert refused.status_code == 422 and "single mode only" in refused.json()["detail"]


def test_a_two_axis_capture_triggered_on_the_other_axis_is_forced_there_and_followed(tmp_path, sim_opener):
    """The trigger on node 2 (standing: never crossed), the capture's node 1 following it; a force on the capture's
    node forces the trigger drive, and node 1 follows: the job says so."""
    app = admin_app(Settings(projects_dir=tmp_path, static_dir=tmp_path / "no-ui", buses=[]), tmp_path / "data")
    with api_client(app) as client:
        sim_opener(app.state.server.connections, "sim:1,2")
        bus = app.state.server.connections.list()[0].id
        scope = f"/api/buses/{bus}/nodes/1/scope"
        trigger = {"source": "0x6041,0@2", "edge": "rising", "level": 0xFFFF}  # the status word never reaches it
        definition = {**DEFINITION, "trigger": trigger, "pre_trigger_pct": 10, "timeout_s": 20}
        started = client.post(f"{scope}/captures", json=definition)
        assert started.status_code == 202, started.text
        _until(client, f"/api/buses/{bus}/nodes/2/scope/status", "waiting")
        assert client.post(f"{scope}/force").status_code == 200
        job = finished(client, started.json()["id"])
        assert job["state"] == "done", job
        result = job["result"]
        assert result["arm"] == "relay" and result["alignment_ns"] == 250_000, result
        assert "node 2's recorder triggered" in result["arm_note"]
        made = client.get(f"{scope}/captures/{result['capture']}").json()
        assert made["samples"] == 100 and made["trigger_index"] == 10, made
        assert made["trigger"].startswith("0x6041,0@2 rising 65535")


def _until(client, route: str, status: str) -> None:
    deadline = time.monotonic() + 10
    while (now := client.get(route).json()["status"]) != status:
        assert time.monotonic() < deadline, now
        time.sleep(0.02)
