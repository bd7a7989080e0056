"""Dictionaries through REST: browse the built-in library, import a user EDS, refuse a bad one; the caller."""

from __future__ import annotations

from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from tests.support.access import admin_app, api_client
from tests.support.small_eds import SMALL_EDS, SMALL_PROPS, write_small_eds

from servostudio.api.app import Settings


@pytest.fixture
def client(tmp_path: Path) -> TestClient:
    return api_client(admin_app(Settings(projects_dir=tmp_path, user_eds_dir=tmp_path / "user-eds"), tmp_path / "data"))


def test_builtin_xtrapulspac_is_listed_and_browsable(client: TestClient) -> None:
    devices = {entry["device"]: entry for entry in client.get("/api/dictionaries").json()}
    assert devices["xtrapulspac"]["builtin"] is True
    od = client.get("/api/dictionaries/xtrapulspac").json()
    objects = {obj["index"]: obj for obj in od["objects"]}
    statusword = objects[0x6041]["subs"][0]
    assert statusword["data_type"] == "UNSIGNED16"
    assert statusword["access"].startswith("r")
    assert statusword["bits"], "the status word's bits are described in the companion file"
    assert any(sub["name"] for sub in objects[0x60F9]["subs"])
    assert "Servo Loops" in od["groups"]


@pytest.mark.parametrize(
    ("device", "fieldbus", "named"),
    [
        (
            "xtrapulspac",
            "CANopen",
            {"statusword": [0x6041, 0], "dc_link_voltage": [0x6079, 0], "torque_actual": [0x6077, 0]},
        ),
        ("ttapro", "PROFIBUS-DP", {"statusword": [0x801, 0], "position_actual": [774, 0], "dc_bus_voltage": [706, 0]}),
    ],
)
def test_a_dictionary_names_its_entries_by_the_device_profiles_meaning(
    client: TestClient, device: str, fieldbus: str, named: dict[str, list[int]]
) -> None:
    """The dashboard finds the status word and the measurements by name: 0x6041 on a CANopen drive, the PZD status
    word on a TTA-PRO; only names whose entry the dictionary has (the TTA-PRO has no 0x6061 mode display)."""
    od = client.get(f"/api/dictionaries/{device}").json()
    assert od["fieldbus"] == fieldbus
    assert named.items() <= od["names"].items()
    present = {(obj["index"], sub["subindex"]) for obj in od["objects"] for sub in obj["subs"]}
    assert all(tuple(address) in present for address in od["names"].values())
    assert ("modes_of_operation_display" in od["names"]) == (fieldbus == "CANopen")


@pytest.mark.parametrize(
    ("device", "files"),
    [
        ("xtrapulspac", ["DRIVEPAR.TXT", "USER_PAR.TXT", "SEQUENCE.TXT"]),
        ("cd1k", ["DRIVEPAR.TXT"]),
        ("ttapro", ["TTAPAR.TXT", "TTASEQ.TXT"]),
    ],
)
def test_a_dictionary_names_the_files_a_backup_of_its_device_holds(
    client: TestClient, device: str, files: list[str]
) -> None:
    """The backup page offers these files; each one downloads from a drive of the device (tested per device)."""
    assert client.get(f"/api/dictionaries/{device}").json()["files"] == files


def test_unknown_dictionary_is_404_naming_the_known_ones(client: TestClient) -> None:
    response = client.get("/api/dictionaries/nosuchdrive")
    assert response.status_code == 404
    assert "xtrapulspac" in response.json()["detail"]


def test_import_user_eds_over_rest(client: TestClient, tmp_path: Path) -> None:
    eds = write_small_eds(tmp_path)
    response = client.post(
        "/api/dictionaries",
        files={"eds": ("acme.eds", eds.read_bytes()), "props": ("acme.props", SMALL_PROPS.encode())},
    )
    assert response.status_code == 201, response.text
    assert response.json()["builtin"] is False
    od = client.get("/api/dictionaries/acme").json()
    speed = next(obj for obj in od["objects"] if obj["index"] == 0x2000)["subs"][0]
    assert (speed["low"], speed["high"], speed["unit"], speed["save_type"]) == (10, 6000, "rpm", "DRIVEPAR")
    assert (tmp_path / "user-eds" / "acme.eds").is_file()


def test_bad_eds_is_refused_with_line_and_nothing_kept(client: TestClient, tmp_path: Path) -> None:
    broken = SMALL_EDS.replace(
        "DataType=0x0006\nAccessType=rw\nLowLimit=10", "DataType=0x0006\nAccessType=rw\nLowLimit=-10"
    )
    response = client.post("/api/dictionaries", files={"eds": ("acme.eds", broken.encode())})
    assert response.status_code == 422
    detail = response.json()["detail"]
    line = broken.splitlines().index("LowLimit=-10") + 1
    assert detail.startswith(f"acme.eds:{line}: [2000]"), detail
    assert not (tmp_path / "user-eds" / "acme.eds").exists()


def test_me_names_the_caller_and_level(client: TestClient) -> None:
    me = client.get("/api/me").json()  # the test client's API token, made in the data directory: no user's
    assert me["name"].startswith("token-") and me["level"] == "administrator"
