"""A PROFIBUS-DP bus through the unchanged REST routes (docs/profibus.md §9): open it by its spec, scan finds the
simulated TTA-PRO at station 5, PNUs read and written by address and by profile name, refusals before sending and
negative PKW replies as readable errors, the parameter file downloaded, and scope roll refused."""

from __future__ import annotations

import pytest
from tests.support.jobs_api import armed, finished
from tests.support.profibus_line import tool_on_line, ttapro_line

NODE = "/api/buses/pb/nodes/5"


@pytest.fixture(scope="module")
def line():
    with ttapro_line(5) as line:
        yield line


@pytest.fixture(scope="module")
def client(tmp_path_factory, line):
    with tool_on_line(tmp_path_factory.mktemp("api-profibus"), line) as test_client:
        bus = test_client.get("/api/buses/pb").json()
        assert bus["kind"] == "profibus" and bus["connected"]
        yield test_client


def test_a_scan_finds_station_5_as_a_ttapro(client):
    found = client.post("/api/buses/pb/scan")
    assert found.status_code == 200
    assert found.json() == [
        {"node": 5, "device": "ttapro", "device_type": None, "vendor_id": 0, "product_code": 0x00C7, "revision": None,
         "serial_number": None, "device_name": "TTA-PRO", "hardware_version": None, "software_version": None}
    ]  # fmt: skip
    assert [node["node"] for node in client.get("/api/buses/pb").json()["nodes"]] == [5]


def test_pnus_are_read_and_written_by_address_and_by_profile_name(client, line):
    read = client.get(f"{NODE}/objects/PNU700").json()
    assert (read["label"], read["raw"]) == ("PNU 700 Number of motor pole pairs", 4)
    written = client.put(f"{NODE}/objects/kp_speed", json={"value": 321})
    assert written.status_code == 200 and written.json()["label"] == "PNU 730 Proportional speed loop gain KP2"
    assert line.slaves[5].memory.get(730) == 321
    assert client.get(f"{NODE}/objects/828,1").json()["raw"] == 0x1308


def test_refusals_before_sending_and_from_the_drive_are_readable(client, line):
    out_of_range = client.put(f"{NODE}/objects/PNU700", json={"value": 99})
    assert (
        out_of_range.status_code == 422
        and "PNU 700 Number of motor pole pairs: 99 is outside 1..32" in (out_of_range.json()["detail"])
    )
    refused = client.put(f"{NODE}/objects/positioner_mode", json={"value": 3})
    assert refused.status_code == 409
    assert refused.json()["detail"] == "node 5, PNU 720: lower or upper limit exceeded (PKW error 2)"
    assert client.get(f"{NODE}/objects/PNU918").status_code == 404  # no such PNU in the TTA-PRO's list


def test_the_parameter_file_downloads_and_uploads_in_its_own_syntax(client, line):
    text = client.get(f"{NODE}/files/TTAPAR.TXT")
    assert text.status_code == 200
    lines = text.text.splitlines()
    assert lines[0].startswith("; TTAPAR.TXT of node 5 (TTA-PRO)") and "700,0=4" in lines and len(lines) == 81
    bad = client.put(f"{NODE}/files/TTAPAR.TXT", content=b"760,0=1200\n761,0=x\n")
    assert bad.status_code == 422 and bad.json()["detail"].startswith("TTAPAR.TXT:2: value 'x' is not an integer")
    assert line.slaves[5].memory.get(760) != 1200  # refused whole: the valid first line was not written either
    good = client.put(f"{NODE}/files/TTAPAR.TXT", params={"store": "false"}, content=b"760,0=1200\n")
    assert good.status_code == 200 and good.json()["ok"] and line.slaves[5].memory.get(760) == 1200


def test_a_restore_is_refused_while_the_drive_is_enabled_and_writes_nothing(client, line):
    """The TTA-PRO saves (PNU 729) and takes its motor data only with the drive disabled (``save_needs_disabled``):
    the upload is refused before its first write, whatever the file holds."""
    memory = line.slaves[5].memory
    before = memory.get(730)
    upload = f"721,0={memory.get(721)}\n730,0={before + 1}\n".encode()
    with armed(client, NODE, "motion") as (_, header):
        enabled = client.put(f"{NODE}/state", json={"target": "operation-enabled"}, headers=header)
        assert enabled.status_code == 200, enabled.text
        try:
            refused = client.put(f"{NODE}/files/TTAPAR.TXT", content=upload)
            assert refused.status_code == 409, refused.text
            assert refused.json()["detail"] == (
                "node 5: TTA-PRO stores parameters only with the drive disabled; disable it first — nothing was written"
            )
            assert client.get(f"{NODE}/state").json()["state"] == "OPERATION ENABLED"  # the restore left it so
        finally:
            client.put(f"{NODE}/state", json={"target": "switch-on-disabled"})
    assert int(client.get(f"{NODE}/objects/kp_speed").json()["raw"]) == before == memory.get(730)


def test_the_bus_wide_backup_and_restore_jobs_carry_ttapar_and_ttaseq(client, line):
    sequences = line.slaves[5].sequences
    sequences.eeprom[7] = {**sequences.eeprom[7], 782: 1, 783: 4321, 784: 900, 785: 50, 786: 60, 788: -1}
    sequences.stored_checksum = sequences.checksum()
    directory = client.app.state.server.settings.projects_dir / "line-backup"
    backup = client.post("/api/buses/pb/backup", json={"directory": str(directory), "nodes": [5]})
    assert backup.status_code == 202 and finished(client, backup.json()["id"])["state"] == "done"
    saved = (directory / "node5" / "TTAPAR.TXT").read_text().splitlines()
    assert len(saved) == 81 and f"760,0={line.slaves[5].memory.get(760)}" in saved
    table = (directory / "node5" / "TTASEQ.TXT").read_text().splitlines()
    assert table[1:5] == ["782,7=1", "783,7=4321", "784,7=900", "785,7=50"] and len(table) == 14
    client.put(f"{NODE}/objects/PNU760", json={"value": 777})
    sequences.eeprom[7] = {**sequences.eeprom[7], 783: 1}
    restore = client.post("/api/buses/pb/restore", json={"directory": str(directory), "nodes": [5]})
    assert restore.status_code == 202 and finished(client, restore.json()["id"])["state"] == "done"
    assert f"760,0={line.slaves[5].memory.get(760)}" in saved and line.slaves[5].memory.get(760) != 777
    assert sequences.eeprom[7][783] == 4321 and sequences.checksum_valid


def test_a_bad_sequence_table_upload_is_refused_with_its_line(client, line):
    refused = client.put(f"{NODE}/files/TTASEQ.TXT", content="; table\n782,3=1\n785,3=0\n")
    assert refused.status_code == 422, refused.text
    assert refused.json()["detail"].startswith("TTASEQ.TXT:3: sequence 3: PNU 785 Sequence acceleration: 0 is outside")


def test_scope_roll_and_nmt_are_refused_with_the_reason(client):
    roll = client.post(f"{NODE}/scope/roll", json={"channels": ["position_actual"], "period_us": 1000, "seconds": 1})
    assert roll.status_code == 422
    assert roll.json()["detail"].startswith("node 5 is a PROFIBUS-DP drive (ttapro): the scope's captures and roll")
    nmt = client.post("/api/buses/pb/nmt", json={"command": "start", "node": 5})
    assert nmt.status_code == 409 and nmt.json()["detail"].startswith("bus pb is a PROFIBUS-DP line: an NMT command")


def test_a_project_axis_edits_the_ttapro_offline(client, line):
    created = client.post("/api/projects", json={"name": "pb", "buses": [{"name": "pb", "interface": line.spec}]})
    assert created.status_code == 201, created.text
    axis = {"name": "X", "device": "ttapro", "node_id": 5, "bus": "pb", "revision": created.json()["revision"]}
    added = client.post("/api/projects/pb/axes", json=axis)
    assert added.status_code == 201, added.text
    values = {"PNU721": 3000, "730": 100, "PNU700": 8}
    written = client.put("/api/projects/pb/axes/X/parameters", json={"values": values})
    assert written.status_code == 200 and {row["file"] for row in written.json()["parameters"]} == {"TTAPAR.TXT"}
    refused = client.put("/api/projects/pb/axes/X/parameters", json={"values": {"PNU700": 99}})
    assert refused.status_code == 422 and "99 is outside 1..32" in refused.json()["detail"]
    store = client.app.state.server.settings.projects_dir
    assert (store / "pb" / "X" / "TTAPAR.TXT").read_text().splitlines() == ["700,0=8", "721,0=3000", "730,0=100"]
