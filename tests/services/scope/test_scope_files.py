"""The capture file format (CSV + JSON sidecar): exact text, round trip for any capture, damage refused with file and
line, and captures saved in a project under their axis."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.od import builtin_library
from servostudio.od.datatypes import DataType
from servostudio.services.projects import ProjectService
from servostudio.services.scope import (
    Capture,
    CaptureDefinition,
    CaptureFileError,
    CaptureStore,
    ChannelInfo,
    DriveIdentity,
    Trigger,
    capture_csv,
    capture_html,
    capture_sidecar,
    parse_capture,
)
from servostudio.services.scope.capture import FORMATS

DEMO = Path(__file__).resolve().parents[3] / "projects" / "demo"
IDENTITY = DriveIdentity("sim", 1, "xtrapulspac", "XtrapulsPac", 0x82, 0x58504143, 1, 7, "1.0")


def small_capture() -> Capture:
    return Capture(
        definition=CaptureDefinition(
            ("0x606C,0", "0x6078,0"), samples=3, trigger=Trigger("0x606C,0", "rising", 100), pre_trigger_pct=34
        ),
        channels=(
            ChannelInfo("0x606C,0", "Velocity actual value", "user unit/s", "INTEGER32"),
            ChannelInfo("0x6078,0", "Current actual value", "% rated current", "INTEGER16", 0.1),
        ),
        period_ns=250_000,
        trigger_index=1,
        trigger="0x606C,0 rising 100 user unit/s",
        columns=((0, 150, 300), (-5, 123, 7)),
        drive=IDENTITY,
        captured_at="2025-05-01T12:30:05Z",
    )


def test_the_csv_text_is_as_documented():
    assert capture_csv(small_capture()) == (
        "# period: 250 us\n"
        "# samples: 3\n"
        "# trigger: 0x606C,0 rising 100 user unit/s\n"
        "# pre-trigger: 34 % (1 samples)\n"
        "# units: s,user unit/s,% rated current\n"
        "# drive: xtrapulspac XtrapulsPac (vendor 0x00000082, product 0x58504143, revision 0x00000001, "
        "serial 0x00000007, software 1.0)\n"
        "# node: 1\n"
        "# bus: sim\n"
        "# captured: 2025-05-01T12:30:05Z\n"
        "# source: recorder\n"
        'time_s,"0x606C,0","0x6078,0"\n'
        "-0.00025,0,-0.5\n"
        "0,150,12.3\n"
        "0.00025,300,0.7\n"
    )


# ---- round trip -------------------------------------------------------------------------------------------------

SCALES = st.sampled_from([(1.0, 0.0), (0.1, 0.0), (0.001, 0.0), (0.0625, 0.0), (0.5, -40.0), (2.0, 0.0)])


def values_of(data_type: DataType) -> st.SearchStrategy:
    if data_type is DataType.REAL32:
        return st.floats(width=32, allow_nan=False, allow_infinity=False)
    low, high = data_type.integer_range
    return st.integers(low, high)


@st.composite
def captures(draw) -> Capture:
    types = draw(st.lists(st.sampled_from(sorted(FORMATS)), min_size=1, max_size=4))
    samples = draw(st.integers(1, 30))
    channels = []
    for number, data_type in enumerate(types):
        scale, offset = (1.0, 0.0) if data_type is DataType.REAL32 else draw(SCALES)
        unit = draw(st.sampled_from(["", "V", "user unit/s", "% rated, current", "°C"]))
        channels.append(ChannelInfo(f"0x{0x6000 + number:04X},{number}", f"ch {number}", unit, data_type.name,
                                    scale, offset))  # fmt: skip
    columns = tuple(tuple(draw(st.lists(values_of(t), min_size=samples, max_size=samples))) for t in types)
    return Capture(
        definition=CaptureDefinition(tuple(channel.key for channel in channels), samples=samples),
        channels=tuple(channels),
        period_ns=250_000 * draw(st.integers(1, 65535)),
        trigger_index=draw(st.integers(0, samples - 1)),
        trigger="immediate",
        columns=columns,
        drive=IDENTITY,
        captured_at="2025-05-01T12:30:05Z",
        alignment_ns=draw(st.none() | st.integers(0, 10**9)),
    )


@settings(max_examples=150, deadline=None)
@given(captures())
def test_any_capture_reads_back_exactly_from_its_two_files(made):
    text, sidecar = capture_csv(made), capture_sidecar(made, "a.csv")
    opened = parse_capture(text, sidecar, "a.csv", "a.json")
    assert opened == made and opened.alignment_ns == made.alignment_ns  # the sidecar states the alignment too


# ---- damage -----------------------------------------------------------------------------------------------------


def damaged(change) -> tuple[str, str]:
    made = small_capture()
    lines = capture_csv(made).splitlines(keepends=True)
    sidecar = capture_sidecar(made, "a.csv")
    return change(lines, sidecar)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda lines, s: ("".join(lines[:-1]), s), r"^a\.csv:13: 2 samples, the sidecar says 3$"),
        (lambda lines, s: ("".join([*lines[:12], "-0.00025,0\n", *lines[13:]]), s), r"^a\.csv:13: 2 fields"),
        (lambda lines, s: ("".join([*lines[:12], "0,abc,12.3\n", *lines[13:]]), s), r"^a\.csv:13: 0x606C,0 value"),
        (lambda lines, s: ("".join([*lines[:12], "0.001,150,12.3\n", *lines[13:]]), s), r"^a\.csv:13: time 0\.001 s"),
        (lambda lines, s: ("".join([*lines[:12], "0,150,12.35\n", *lines[13:]]), s), r"a\.csv:13: .*no INTEGER16"),
        (lambda lines, s: ("".join([*lines[:12], "0,3000000000,1\n", *lines[13:]]), s), r"a\.csv:13: .*no INTEGER32"),
        (lambda lines, s: ("".join([*lines[:10], 'time_s,"0x606C,0"\n', *lines[11:]]), s), r"^a\.csv:11: header"),
        (lambda lines, s: ("".join([*lines, "0.0005,1,1\n"]), s), r"^a\.csv:15: more rows than the 3 samples"),
        (lambda lines, s: ("".join(lines), s[:-20]), r"^a\.json:\d+: not JSON"),
        (lambda lines, s: ("".join(lines), s.replace('"period_ns": 250000', '"period_ns": "fast"')),
         r"^a\.json:\d+: 'period_ns' is missing or not int"),
        (lambda lines, s: ("".join(lines), s.replace('"version": 1', '"version": 9')), r"^a\.json:3: .*version 1"),
        (lambda lines, s: ("".join(lines), "[]"), r"^a\.json:1: not a capture sidecar"),
        (lambda lines, s: ("".join(lines), s.replace('"alignment_ns": null', '"alignment_ns": -1')),
         r"^a\.json:\d+: 'alignment_ns' is not a count of ns"),
        (lambda lines, s: ("".join(lines), s.replace("INTEGER16", "INTEGER99")), r"unknown data type 'INTEGER99'"),
    ],
)  # fmt: skip
def test_a_damaged_file_is_refused_with_file_and_line(change, message):
    text, sidecar = damaged(change)
    with pytest.raises(CaptureFileError, match=message):
        parse_capture(text, sidecar, "a.csv", "a.json")


def test_the_sidecar_line_named_is_the_damaged_key():
    text, sidecar = damaged(lambda lines, s: ("".join(lines), s.replace('"samples": 3', '"samples": null')))
    line = next(number for number, row in enumerate(sidecar.splitlines(), 1) if '"samples"' in row)
    with pytest.raises(CaptureFileError, match=rf"^a\.json:{line}: 'samples' is missing or not int$"):
        parse_capture(text, sidecar, "a.csv", "a.json")


# ---- in the project ---------------------------------------------------------------------------------------------


@pytest.fixture
def projects(tmp_path) -> ProjectService:
    shutil.copytree(DEMO, tmp_path / "demo")
    return ProjectService(tmp_path, builtin_library())


def test_saved_under_the_axis_listed_and_reopened_without_changing_the_revision(projects):
    store = CaptureStore(projects.store)
    before = projects.store.open("demo").revision
    saved = store.save("demo", "X", small_capture())
    again = store.save("demo", "X", small_capture(), "step 1")
    assert (saved.name, again.name) == ("2025-05-01 12-30-05", "step 1")
    folder = projects.store.root / "demo" / "X" / "captures"
    assert sorted(path.name for path in folder.iterdir()) == [
        "2025-05-01 12-30-05.csv", "2025-05-01 12-30-05.json", "step 1.csv", "step 1.json",
    ]  # fmt: skip
    assert json.loads((folder / "step 1.json").read_text())["data"] == "step 1.csv"
    assert [item.name for item in store.list("demo", "X")] == ["2025-05-01 12-30-05", "step 1"]
    assert store.open("demo", "X", "step 1") == small_capture()
    assert store.save("demo", "X", small_capture()).name == "2025-05-01 12-30-05-2"
    assert projects.store.open("demo").revision == before


def test_a_damaged_saved_capture_is_refused_naming_its_file_and_line(projects):
    store = CaptureStore(projects.store)
    store.save("demo", "X", small_capture(), "step")
    path = projects.store.root / "demo" / "X" / "captures" / "step.csv"
    path.write_text(path.read_text().replace("0,150,12.3", "0,150,x"))
    with pytest.raises(CaptureFileError, match=r"^X/captures/step\.csv:13: 0x6078,0 value 'x' is not a number$"):
        store.open("demo", "X", "step")
    (path.with_suffix(".json")).write_bytes(b'{\n"format": "servostudio-capture",\n"\xff"}')
    listed = store.list("demo", "X")
    assert listed[0].name == "step" and listed[0].error is not None and "X/captures/step.json:3" in listed[0].error


def test_taken_names_unknown_captures_and_delete(projects):
    store = CaptureStore(projects.store)
    store.save("demo", "X", small_capture(), "step")
    with pytest.raises(Exception, match="has a capture named 'STEP' already"):
        store.save("demo", "X", small_capture(), "STEP")
    with pytest.raises(Exception, match="no saved capture 'other'"):
        store.open("demo", "X", "other")
    with pytest.raises(Exception, match=r"capture name '\.\./x' is not allowed"):
        store.open("demo", "X", "../x")
    store.delete("demo", "X", "step")
    assert store.list("demo", "X") == []


def test_the_html_export_is_standalone_with_a_y_axis_per_channel():
    page = capture_html(small_capture())
    assert page.startswith("<!doctype html>") and "scattergl" in page and "<script src=" not in page
    assert '"yaxis2"' in page and "% rated current" in page and len(page) > 1_000_000  # plotly.js inlined
