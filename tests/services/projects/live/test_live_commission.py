"""Commissioning a project against the embedded simulated drives: download, compare, take, write, upload, motor."""

from __future__ import annotations

import pytest

from servostudio.services.projects import Axis, Bus, ConflictError, Motor, ParameterRefused
from servostudio.services.projects.errors import DriveMismatch, DriveUnavailable


@pytest.fixture(scope="module")
def commissioned(service, live):
    """Project 'p': axes X (node 1) and Y (node 2) edited offline, then downloaded to the simulated drives."""
    service.store.create("p", "live test", (Bus("sim", "sim"),))
    service.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    service.store.add_axis("p", Axis("Y", "xtrapulspac", 2, "sim"))
    service.parameters.set("p", "X", {"0x3051": 5, "0x6081": 8192, "0x100C": 100})
    return live.commission("p", "download")


def drive_of(live, axis: str):
    return live.link("p", axis).drive()


def differing(live, axis: str, **options) -> list[tuple[str, dict]]:
    compared = live.compare("p", axis, only_differences=True, **options)
    return [(f"0x{row.variable.index:04X},{row.variable.subindex}", row.values) for row in compared.rows]


def test_download_makes_the_drives_hold_the_project_values(commissioned, live):
    report = commissioned.as_dict()
    assert report["ok"], report
    for axis in report["axes"]:
        assert axis["status"] == "ok" and axis["identity"]["device"] == "xtrapulspac"
        files = {item["file"]: item for item in axis["files"]}
        assert list(files) == ["DRIVEPAR.TXT", "USER_PAR.TXT", "SEQUENCE.TXT"]
        assert files["DRIVEPAR.TXT"]["counts"]["verified"] > 200 and files["DRIVEPAR.TXT"]["stored"] == "save"
        assert "0x6065,0 Following error window" in files["DRIVEPAR.TXT"]["not_in_project"]  # no default, not set
    x, y = drive_of(live, "X"), drive_of(live, "Y")
    assert [x.read(key).raw for key in ("0x3051", "0x6081", "0x100C")] == [5, 8192, 100]
    assert [y.read(key).raw for key in ("0x3051", "0x6081", "0x100C")] == [0, 4096, 0]
    assert differing(live, "X") == []


def test_compare_shows_exactly_the_object_changed_on_the_drive_and_take_stores_it(commissioned, live, service):
    drive_of(live, "X").write("0x6083", 131072)
    assert differing(live, "X") == [("0x6083,0", {"drive": 131072, "project": 65536, "default": 65536})]
    assert differing(live, "X", group="Profile Position Mode") == [
        ("0x6083,0", {"drive": 131072, "project": 65536, "default": 65536})
    ]
    assert differing(live, "X", group="Motor") == []
    change = live.take("p", "X", ["0x6083"])
    assert [(row.variable.key, row.value, row.file) for row in change.rows] == [((0x6083, 0), 131072, "DRIVEPAR.TXT")]
    assert "0x6083,0=131072" in (service.store.root / "p" / "X" / "DRIVEPAR.TXT").read_text(encoding="latin-1")
    assert differing(live, "X", group="Profile Position Mode") == []


def test_take_without_addresses_takes_every_difference(commissioned, live, service):
    drive = drive_of(live, "Y")
    drive.write("0x6084", 1000)
    drive.write("0x3055", 3)
    change = live.take("p", "Y")
    assert sorted((row.variable.key, row.value) for row in change.rows) == [((0x3055, 0), 3), ((0x6084, 0), 1000)]
    assert [(row.variable.key, row.file) for row in service.parameters.rows("p", "Y", only_set=True)[0]] == [
        ((0x3055, 0), "DRIVEPAR.TXT"),
        ((0x6084, 0), "DRIVEPAR.TXT"),
    ]


def test_writing_to_the_drive_checks_the_whole_selection_before_sending(commissioned, live):
    drive = drive_of(live, "X")
    drive.write("0x6081", 1)
    drive.write("0x3051", 9)
    with pytest.raises(ParameterRefused, match=r"0x6065,0 .*no value"):
        live.write("p", "X", ["0x6081", "0x6065"])
    assert drive.read("0x6081").raw == 1  # nothing was sent
    report = live.write("p", "X", ["0x6081"]).as_dict()
    assert report["ok"] and report["objects"] == [
        {
            "address": "0x6081,0",
            "name": "0x6081,0 Profile velocity",
            "value": 8192,
            "status": "written",
            "error": None,
            "drive": 8192,
        }
    ]
    assert drive.read("0x6081").raw == 8192
    everything = live.write("p", "X")  # without addresses: every object that differs
    assert [(item.variable.key, item.status, item.read_back) for item in everything.writes] == [
        ((0x3051, 0), "written", 5)
    ]
    assert drive.read("0x3051").raw == 5


def test_upload_replaces_the_axis_files_with_the_drives(commissioned, live, service):
    drive = drive_of(live, "X")
    drive.write("0x6084", 2222)
    drive.write("0x6065", 777)  # an object the project had no value for
    before = service.store.open("p").revision
    report = live.commission("p", "upload", ["X"])
    assert report.ok and [axis.link.axis.name for axis in report.axes] == ["X"]
    assert report.revision != before and report.revision == service.store.open("p").revision
    text = (service.store.root / "p" / "X" / "DRIVEPAR.TXT").read_text(encoding="latin-1")
    assert "0x6084,0=2222" in text and "0x6065,0=777" in text
    rows, _ = service.parameters.rows("p", "X", only_set=True)
    assert {row.variable.key: row.value for row in rows}[0x6065, 0] == 777
    assert differing(live, "X") == []


def test_an_upload_into_a_project_changed_meanwhile_is_refused(commissioned, live, service):
    files = {path: path.read_bytes() for path in (service.store.root / "p" / "X").iterdir()}
    with pytest.raises(ConflictError):
        live.commission("p", "upload", ["X"], expected_revision="0" * 16)
    assert {path: path.read_bytes() for path in (service.store.root / "p" / "X").iterdir()} == files


def test_selecting_a_motor_on_the_drive_reads_back_what_the_drive_derived(commissioned, live, service):
    service.motors.add(
        Motor(
            "M1",
            "test motor",
            "values chosen for the test",
            {
                "manufacturer": "ACME",
                "max_speed": 3000,
                "stall_current": 2500,
                "peak_current": 7500,
                "pole_pairs": 4,
                "inductance": 55,
            },
        )
    )
    drive = drive_of(live, "Y")
    choice = live.select_motor("p", "Y", "M1")
    on_drive = {key: drive.read(key).raw for key in ("0x6410,9", "0x6080", "0x340F", "0x3410,1", "0x6075", "0x6073")}
    assert (on_drive["0x6410,9"], on_drive["0x6080"], on_drive["0x340F"], on_drive["0x3410,1"]) == (2500, 3000, 55, 4)
    drive_rated = drive.read("0x6510,2").raw
    assert on_drive["0x6075"] == min(2500, drive_rated) if drive_rated else 2500
    taken = {f"0x{row.variable.index:04X},{row.variable.subindex}": row.value for row in choice.change.rows}
    assert {key: taken[key if "," in key else f"{key},0"] for key in on_drive} == on_drive
    assert choice.snapshot.project.axis("Y").motor == "M1"
    assert all(not note.startswith("the drive set 0x6410") for note in choice.notes)


def test_a_wrong_device_or_a_silent_node_is_reported_and_never_written(commissioned, live, service):
    service.store.create("w", buses=(Bus("sim", "sim"),))
    service.store.add_axis("w", Axis("A", "xtrapulspac", 1, "sim"))
    service.store.add_axis("w", Axis("B", "cd1k", 3, "sim"))
    service.store.add_axis("w", Axis("C", "xtrapulspac", 5, "sim"))
    service.parameters.set("w", "B", {"0x60F9,1": 77})
    node3 = live.link("p", "Y").connection.drive(3, "xtrapulspac")
    before = node3.read("0x60F9,1").raw
    report = live.commission("w", "download", ["B", "C"])
    assert not report.ok
    statuses = {axis.link.axis.name: (axis.link.status, axis.files) for axis in report.axes}
    assert statuses == {"B": ("wrong_device", []), "C": ("no_answer", [])}
    wrong = report.axes[0].as_dict()
    assert "expected device 'cd1k', found device 'xtrapulspac'" in wrong["problem"]
    assert wrong["identity"]["vendor_id"] == 0x82
    assert node3.read("0x60F9,1").raw == before
    assert [axis.link.status for axis in live.commission("w", "check", ["A", "B"]).axes] == ["ok", "wrong_device"]
    with pytest.raises(DriveMismatch, match="expected device 'cd1k'"):
        live.compare("w", "B")
    with pytest.raises(DriveUnavailable, match="does not answer"):
        report.axes[1].link.drive()
