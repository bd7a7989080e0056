"""Dictionaries through REST and CLI: browse the built-in library, import a user EDS, refuse a bad one."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from servostudio.api.app import Settings, create_app

SMALL_EDS = """\
[FileInfo]
FileName=acme.eds
FileVersion=1
FileRevision=0
EDSVersion=4.0
Description=Test device
CreationTime=12:00PM
CreationDate=11-21-2026
CreatedBy=Servo Studio tests

[DeviceInfo]
VendorName=Acme
VendorNumber=0x12345
ProductName=Acme Drive
ProductNumber=0x42
RevisionNumber=0x10001
BaudRate_10=0
BaudRate_20=0
BaudRate_50=0
BaudRate_125=1
BaudRate_250=1
BaudRate_500=1
BaudRate_800=0
BaudRate_1000=1
SimpleBootUpMaster=0
SimpleBootUpSlave=1
Granularity=8
DynamicChannelsSupported=0
GroupMessaging=0
NrOfRXPDO=0
NrOfTXPDO=0
LSS_Supported=0

[DummyUsage]
Dummy0001=0
Dummy0002=0
Dummy0003=0
Dummy0004=0
Dummy0005=0
Dummy0006=0
Dummy0007=0

[MandatoryObjects]
SupportedObjects=3
1=0x1000
2=0x1001
3=0x1018

[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x00020192
PDOMapping=0

[1001]
ParameterName=Error register
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=0
PDOMapping=1

[1018]
ParameterName=Identity object
ObjectType=0x9
SubNumber=3

[1018sub0]
ParameterName=Number of entries
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=2
PDOMapping=0

[1018sub1]
ParameterName=Vendor ID
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x12345
PDOMapping=0

[1018sub2]
ParameterName=Product code
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x42
PDOMapping=0

[OptionalObjects]
SupportedObjects=0

[ManufacturerObjects]
SupportedObjects=1
1=0x2000

[2000]
ParameterName=Speed limit
ObjectType=0x7
DataType=0x0006
AccessType=rw
LowLimit=10
HighLimit=6000
DefaultValue=3000
PDOMapping=0
"""

SMALL_PROPS = """\
[2000]
Group=Motor
Unit=rpm
SaveType=DRIVEPAR
Description=Maximum motor speed
"""


@pytest.fixture
def client(tmp_path: Path) -> TestClient:
    return TestClient(create_app(Settings(projects_dir=tmp_path, user_eds_dir=tmp_path / "user-eds")))


def write_small_eds(directory: Path, text: str = SMALL_EDS) -> Path:
    eds = directory / "acme.eds"
    eds.write_text(text)
    (directory / "acme.props").write_text(SMALL_PROPS)
    return eds


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


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "servostudio", *args], capture_output=True, text=True, timeout=60)


def test_cli_show_finds_an_object_by_name_and_address() -> None:
    by_address = run_cli("eds", "show", "xtrapulspac", "0x6041")
    assert by_address.returncode == 0, by_address.stderr
    entry = json.loads(by_address.stdout)
    assert (entry["index"], entry["subindex"], entry["data_type"]) == ("0x6041", 0, "UNSIGNED16")
    missing = run_cli("eds", "show", "xtrapulspac", "0x5FFF,9")
    assert missing.returncode == 4 and "error:" in missing.stderr


def test_cli_check_and_import(tmp_path: Path) -> None:
    eds = write_small_eds(tmp_path)
    checked = run_cli("eds", "check", str(eds))
    assert checked.returncode == 0, checked.stderr
    assert json.loads(checked.stdout)["product_code"] == 0x42
    user_dir = tmp_path / "lib"
    imported = run_cli("eds", "--user-dir", str(user_dir), "import", str(eds))
    assert imported.returncode == 0, imported.stderr
    listed = json.loads(run_cli("eds", "--user-dir", str(user_dir), "list").stdout)
    assert "acme" in {entry["device"] for entry in listed}


def test_cli_check_rejects_a_malformed_file_with_exit_3(tmp_path: Path) -> None:
    eds = write_small_eds(tmp_path, SMALL_EDS.replace("ParameterName=Speed limit\n", ""))
    result = run_cli("eds", "check", str(eds))
    assert result.returncode == 3
    assert "acme.eds:" in result.stderr and "[2000]" in result.stderr


def test_me_names_the_caller_and_level(client: TestClient) -> None:
    assert client.get("/api/me").json() == {"name": "local", "level": "administrator"}
