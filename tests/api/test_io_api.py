"""The I/O routes on the server's simulated bus: read, a limit switch configured and the drive's live state reacting
to the test bench's input, a bad change refused whole (422) with nothing written."""

from __future__ import annotations

import time

import pytest
from tests.support.access import admin_app, api_client

from servostudio.api.app import Settings

XTRAPULSPAC, CD1K = "/api/buses/sim/nodes/1/io", "/api/buses/sim/nodes/2/io"


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    root = tmp_path_factory.mktemp("io")
    settings = Settings(projects_dir=root / "projects", static_dir=root / "no-ui", buses=("sim:1,2:cd1k",))
    return admin_app(settings, root / "data")


@pytest.fixture
def client(app):
    with api_client(app) as client:
        yield client


def live_until(client, path: str, key: str, expected: bool) -> dict:
    deadline = time.monotonic() + 3.0
    while (state := client.get(f"{path}/state").json())[key] is not expected:
        assert time.monotonic() < deadline, state
        time.sleep(0.02)
    return state


def test_a_limit_switch_is_configured_and_the_drive_reacts(client):
    configured = client.put(
        XTRAPULSPAC, json={"inputs": [{"name": "IN4", "function": "negative_limit", "inverted": True}]}
    )
    assert configured.status_code == 200, configured.text
    body = configured.json()
    assert body["written"] == ["0x3051,0", "0x3050,4"] and body["inputs"][3]["function"] == "negative_limit"
    assert live_until(client, XTRAPULSPAC, "negative_limit", True)["input_levels"]["IN4"] is True
    wired = client.put(f"{XTRAPULSPAC}/sim-inputs", json={"value": 0b1000})
    assert wired.status_code == 200 and wired.json()["simulated"]["value"] == 0b1000
    live_until(client, XTRAPULSPAC, "negative_limit", False)
    client.put(XTRAPULSPAC, json={"inputs": [{"name": "IN4", "function": "none", "inverted": False}]})
    client.put(f"{XTRAPULSPAC}/sim-inputs", json={"value": 0})


def test_a_bad_change_is_refused_whole(client):
    before = client.get(XTRAPULSPAC).json()
    refused = client.put(
        XTRAPULSPAC,
        json={"inputs": [{"name": "IN1", "function": "home"}, {"name": "IN11", "function": "home"}]},
    )
    assert refused.status_code == 422 and "no input 'IN11'" in refused.json()["detail"]
    assert client.get(XTRAPULSPAC).json()["inputs"] == before["inputs"]


def test_cd1k_frees_its_limit_input_and_the_check_says_it_is_unsafe(client):
    client.put(f"{CD1K}/sim-inputs", json={"value": 0b10})  # LS− active
    live_until(client, CD1K, "negative_limit", True)
    freed = client.put(CD1K, json={"inputs": [{"name": "INPUT1 / LS−", "function": "general"}]}).json()
    assert any(row["severity"] == "unsafe" and row["subject"] == "INPUT1 / LS−" for row in freed["findings"])
    live_until(client, CD1K, "negative_limit", False)
    client.put(CD1K, json={"inputs": [{"name": "INPUT1 / LS−", "function": "negative_limit"}]})
    client.put(f"{CD1K}/sim-inputs", json={"value": 0})
