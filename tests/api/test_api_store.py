"""``POST …/nodes/{node}/store`` (docs/rest-api.md): the device's own save, judged on the simulated drives — an
XtrapulsPac's flash file DRIVEPAR.TXT holds the value written before the store; a TTA-PRO's PNU 729 = 1 puts the
value into its EEPROM, so it survives a simulated power cycle (which keeps only EEPROM values), and an enabled
TTA-PRO is refused with nothing stored."""

from __future__ import annotations

import pytest
from tests.support.access import admin_app, api_client
from tests.support.jobs_api import armed
from tests.support.profibus_line import tool_on_line, ttapro_line

from servostudio.api.app import Settings
from servostudio.formats.objectfile import parse_object_file

TTA = "/api/buses/pb/nodes/5"


@pytest.fixture(scope="module")
def line():
    with ttapro_line(5) as line:
        yield line


@pytest.fixture(scope="module")
def client(tmp_path_factory, line):
    with tool_on_line(tmp_path_factory.mktemp("api-store"), line) as test_client:
        yield test_client


def flash_value(sim_network, node: int, address: tuple[int, int]) -> object:
    text = sim_network.node(node).flash.read_text("DRIVEPAR.TXT") or ""
    return {(entry.index, entry.sub): entry.value for entry in parse_object_file(text)}.get(address)


def test_an_xtrapulspac_stores_the_value_it_holds_in_its_flash_file(socketcand, sim_network, tmp_path):
    app = admin_app(Settings(projects_dir=tmp_path, buses=[socketcand.spec]), tmp_path / "data")
    kpv = 301 if flash_value(sim_network, 1, (0x60F9, 2)) == 300 else 300  # not what the flash holds
    with api_client(app) as client:
        node = "/api/buses/socketcand/nodes/1"
        assert client.put(f"{node}/objects/0x60F9,2", json={"value": kpv}).status_code == 200
        stored = client.post(f"{node}/store")
    assert stored.status_code == 200, stored.text
    assert stored.json()["wrote"] == "0x1010,1 Store parameters.Save all parameters = 'save'"
    assert flash_value(sim_network, 1, (0x60F9, 2)) == kpv


def test_a_ttapro_stores_in_eeprom_and_the_value_survives_a_power_cycle(client, line):
    slave = line.slaves[5]
    kp = slave.memory.get(730) % 500 + 17
    assert client.put(f"{TTA}/objects/PNU730", json={"value": kp}).status_code == 200
    stored = client.post(f"{TTA}/store")
    assert stored.status_code == 200, stored.text
    assert stored.json() | {"seconds": 0} == {
        "node": 5, "stored": "save", "wrote": "PNU 729 Save parameters in EEPROM = 1", "seconds": 0
    }  # fmt: skip
    with line.line.lock:
        slave.power_cycle()
        assert slave.memory.get(730) == kp
    assert client.get(f"{TTA}/objects/PNU730").json()["raw"] == kp


def test_a_value_not_stored_is_lost_at_a_power_cycle(client, line):
    """The check of the test above: without the store, the power cycle brings the EEPROM's value back."""
    slave = line.slaves[5]
    kept = slave.memory.get(730)
    assert client.put(f"{TTA}/objects/PNU730", json={"value": kept + 1}).status_code == 200
    with line.line.lock:
        slave.power_cycle()
        assert slave.memory.get(730) == kept


def test_an_enabled_ttapro_is_refused_and_nothing_is_stored(client, line):
    slave = line.slaves[5]
    kept = slave.memory.get(730)
    assert client.put(f"{TTA}/objects/PNU730", json={"value": kept + 2}).status_code == 200
    with armed(client, TTA, "motion") as (_, header):
        enabled = client.put(f"{TTA}/state", json={"target": "operation-enabled"}, headers=header)
        assert enabled.status_code == 200, enabled.text
        try:
            refused = client.post(f"{TTA}/store")
        finally:
            client.put(f"{TTA}/state", json={"target": "switch-on-disabled"})
    assert refused.status_code == 409, refused.text
    assert refused.json()["detail"] == (
        "node 5: TTA-PRO stores parameters only with the drive disabled; disable it first — nothing was written"
    )
    with line.line.lock:
        slave.power_cycle()
        assert slave.memory.get(730) == kept
