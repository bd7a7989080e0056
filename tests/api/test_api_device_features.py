"""The dictionary's ``features`` and ``store`` (docs/rest-api.md): what each device's services have, and that the
server refuses on a TTA-PRO what its dictionary does not list (the UI hides those tabs from this answer)."""

from __future__ import annotations

import pytest
from tests.support.profibus_line import tool_on_line, ttapro_line

ALL = ["scope", "current_loop", "phasing", "auto_tuning", "frequency_response", "sequences", "io"]
NODE = "/api/buses/pb/nodes/5"
SAVE = "0x1010,1 Store parameters.Save all parameters = 'save'"
ROLL = {"channels": ["position_actual"], "period_us": 1000, "seconds": 1}


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with ttapro_line(5) as line, tool_on_line(tmp_path_factory.mktemp("features"), line) as test_client:
        yield test_client


@pytest.mark.parametrize(
    ("device", "features", "store"),
    [
        ("xtrapulspac", ALL, SAVE),
        ("cd1k", ["scope", "phasing", "auto_tuning", "frequency_response", "io"], SAVE),  # no 'calc'
        ("encotrive", ["scope", "frequency_response", "io"], "0x1010,1 Store parameters.Store all parameters = 'save'"),
        ("ttapro", [], "PNU 729 Save parameters in EEPROM = 1"),
    ],
)  # fmt: skip
def test_each_device_says_its_features_and_what_storing_writes(client, device, features, store):
    answer = client.get(f"/api/dictionaries/{device}").json()
    assert (answer["features"], answer["store"]) == (features, store)


def test_a_ttapro_is_refused_what_its_dictionary_does_not_list(client):
    refusals = {
        "io": client.get(f"{NODE}/io"),
        "sequences": client.get(f"{NODE}/sequences"),
        "current_loop": client.post(f"{NODE}/procedures/current_loop", json={}),
        "phasing": client.post(f"{NODE}/procedures/auto_phasing", json={}),
        "auto_tuning": client.post(f"{NODE}/procedures/auto_tuning", json={}),
        "frequency_response": client.post(f"{NODE}/frequency-response", json={"loop": "plant"}),
        "scope": client.post(f"{NODE}/scope/roll", json=ROLL),
    }  # fmt: skip
    said = {name: (answer.status_code // 100, "ttapro" in answer.json()["detail"]) for name, answer in refusals.items()}
    assert said == dict.fromkeys(ALL, (4, True)), {name: answer.text for name, answer in refusals.items()}
