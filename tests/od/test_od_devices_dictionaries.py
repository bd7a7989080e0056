"""The built-in CD1-k and encoTRive dictionaries (eds/cd1k.*, eds/encotrive.*) against their manuals.

The expected object lists and values below were written from the manuals (Infranor *CD1-k CANopen communication
profile*, TR-Electronic *encoTRive MD-025*; manuals 001 and 004 in docs/devices.md), independently of the EDS files.
The `.props` line references are checked against the manuals' text editions when ``SERVOSTUDIO_MANUALS`` names the
directory that holds them (they are not part of the repository).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.od import Access, DataType, ObjectKind, OutOfRange, SaveType, load_dictionary

REPO = Path(__file__).resolve().parents[2]
EDS_DIR = REPO / "eds"
#: the manuals' text editions, whose line numbers the `.props` references use (set by whoever has them)
MANUALS = Path(os.environ["SERVOSTUDIO_MANUALS"]) if os.environ.get("SERVOSTUDIO_MANUALS") else None
NO_MANUALS = "set SERVOSTUDIO_MANUALS to the directory of the manuals' text editions"
DEVICES = ("cd1k", "encotrive")
PROJECT_OBJECTS = {0x3428}
"""Objects the project defines on top of the manual (0x3428 "Identified plant", issue #13's contract): referenced to
docs/, not to a manual line."""

CD1K_INDICES = PROJECT_OBJECTS | {
    0x1000,
    0x1001,
    0x1005,
    0x1006,
    0x1007,
    0x1008,
    0x1009,
    0x100A,
    0x100C,
    0x100D,
    0x1010,
    0x1014,
    0x1018,
    0x1200,
    0x1400,
    0x1401,
    0x1402,
    0x1600,
    0x1601,
    0x1602,
    0x1800,
    0x1801,
    0x1802,
    0x1A00,
    0x1A01,
    0x1A02,
    0x2500,
    0x2501,
    0x2502,
    0x3006,
    0x3020,
    0x3021,
    0x3031,
    0x3033,
    0x305A,
    0x3067,
    0x306A,
    0x306C,
    0x3070,
    0x3078,
    0x307F,
    0x3080,
    0x308F,
    0x3090,
    0x3091,
    0x3098,
    0x309B,
    0x309C,
    0x30C0,
    0x30C1,
    0x30C2,
    0x30C3,
    0x30C4,
    0x30D0,
    0x30D1,
    0x30D4,
    0x30D5,
    0x30E0,
    0x30F5,
    0x30F9,
    0x30FB,
    0x30FD,
    0x30FF,
    0x3210,
    0x3211,
    0x3212,
    0x3213,
    0x3214,
    0x3215,
    0x3216,
    0x3217,
    0x3218,
    0x3219,
    0x3300,
    0x3301,
    0x3302,
    0x3304,
    0x3305,
    0x3310,
    0x3320,
    0x3321,
    0x3330,
    0x3331,
    0x3350,
    0x3360,
    0x3361,
    0x3380,
    0x3381,
    0x3382,
    0x3383,
    0x3384,
    0x3385,
    0x3386,
    0x3387,
    0x3388,
    0x3389,
    0x338A,
    0x33A0,
    0x33A1,
    0x3410,
    0x3414,
    0x3420,
    0x3421,
    0x3422,
    0x3430,
    0x3487,
    0x3491,
    0x3492,
    0x3496,
    0x6040,
    0x6041,
    0x604F,
    0x605A,
    0x6060,
    0x6061,
    0x6063,
    0x6064,
    0x6065,
    0x6067,
    0x6069,
    0x606A,
    0x606B,
    0x606C,
    0x606D,
    0x606E,
    0x606F,
    0x6070,
    0x6071,
    0x6078,
    0x607A,
    0x607C,
    0x607D,
    0x607E,
    0x6080,
    0x6081,
    0x6082,
    0x6083,
    0x6084,
    0x6086,
    0x6087,
    0x6088,
    0x608F,
    0x6098,
    0x6099,
    0x609A,
    0x60C0,
    0x60C1,
    0x60C4,
    0x60F6,
    0x60F9,
    0x60FB,
    0x60FD,
    0x60FE,
    0x60FF,
    0x6402,
    0x6410,
    0x6502,
    0x6504,
    0x6510,
}

ENCOTRIVE_INDICES = {
    0x1000,
    0x1001,
    0x1003,
    0x1005,
    0x1008,
    0x1009,
    0x100A,
    0x100C,
    0x100D,
    0x1010,
    0x1011,
    0x1014,
    0x1015,  # sections 4.2.4.4.13/14: not in the excerpt, implied by the EMCY service (CiA 301)
    0x1016,
    0x1017,
    0x1018,
    *range(0x1400, 0x1406),
    *range(0x1600, 0x1606),
    *range(0x1800, 0x1806),
    *range(0x1A00, 0x1A06),
    0x2DFE,
    0x2E04,
    0x2F02,  # the current-controller record, its index the project's reading (docs/decisions.md §6)
    0x6007,
    0x603F,
    0x6040,
    0x6041,
    0x604D,
    0x605A,
    0x605B,
    0x605C,
    0x605D,
    0x605E,
    0x6060,
    0x6061,
    0x6062,
    0x6064,
    0x6065,
    0x6066,
    0x6067,
    0x6068,
    0x6069,
    0x606B,
    0x606C,
    0x6071,
    0x6072,
    0x6073,
    0x6074,
    0x6075,
    0x6076,
    0x6077,
    0x6078,
    0x6079,
    0x607A,
    0x607B,
    0x607D,
    0x607E,
    0x607F,
    0x6080,
    0x6081,
    0x6083,
    0x6084,
    0x6085,
    0x6087,
    0x608F,
    0x6090,
    0x6093,
    0x6094,
    0x6097,
    0x60C5,
    0x60C6,
    0x60FD,
    0x60FE,
    0x60FF,
    0x6402,
    0x6502,
}
# 1004h (number of PDOs) is in the manual but left out: its sub-index 0 is UNSIGNED32, which CiA 306 cannot express.
ENCOTRIVE_LEFT_OUT = {0x1004}

# Objects whose manual default is "eeprom" (CD1-k appendix 1), plus 3219h ("saved in the amplifier EEPROM").
CD1K_EEPROM = {
    (0x1006, 0),
    (0x3031, 0),
    (0x3033, 0),
    (0x3070, 0),
    (0x3080, 0),
    (0x308F, 0),
    (0x3090, 0),
    (0x3091, 0),
    (0x309B, 0),
    (0x30C2, 0),
    (0x30F5, 0),
    (0x30FB, 0),
    (0x3219, 0),
    (0x3320, 1),
    (0x3320, 2),
    (0x3320, 3),
    (0x3420, 1),
    (0x3421, 0),
    (0x3422, 0),
    (0x3430, 0),
    (0x3487, 1),
    (0x3487, 2),
    (0x3487, 3),
    (0x3487, 4),
    (0x3491, 0),
    (0x604F, 0),
    (0x6065, 0),
    (0x6080, 0),
    (0x608F, 1),
    (0x6410, 1),
    (0x6410, 2),
    (0x6410, 3),
    (0x6410, 4),
    (0x6410, 6),
    (0x6510, 5),
    (0x6510, 6),
    (0x6510, 7),
    *((0x60F6, sub) for sub in range(1, 5)),
    *((0x60F9, sub) for sub in range(1, 9)),
    *((0x60FB, sub) for sub in range(1, 5)),
}

# Signature procedures of the CD1-k manual: object -> ASCII signatures, with the hex value the manual prints.
CD1K_SIGNATURES = {
    (0x3098, 0): {"fdbk": 0x6B626466},
    (0x30C4, 0): {"offa": 0x6166666F},
    (0x3410, 0): {"apha": 0x61687061},
    (0x3414, 0): {"mcal": 0x6C61636D},
    (0x3420, 2): {"atun": 0x6E757461},
    (0x3492, 0): {"coga": 0x61676F63},
    (0x3496, 0): {"scmp": 0x706D6373},
    (0x3215, 0): {"razp": 0x707A6172, "setp": 0x70746573},
}


def eds_path(device: str) -> Path:
    return EDS_DIR / f"{device}.eds"


@pytest.fixture(scope="module")
def cd1k():
    return load_dictionary(eds_path("cd1k"))


@pytest.fixture(scope="module")
def encotrive():
    return load_dictionary(eds_path("encotrive"))


# --- standard tools -----------------------------------------------------------------------------------------------


def dcfchk() -> str:
    beside_python = Path(sys.executable).with_name("dcfchk")
    found = str(beside_python) if beside_python.exists() else shutil.which("dcfchk")
    assert found, "dcfchk (PyPI dcf-tools) must be installed"
    return found


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("node_id", [1, 127])
def test_dcfchk_accepts_the_eds_without_any_warning(device: str, node_id: int) -> None:
    # dcfchk needs a node-ID to resolve the $NODEID COB-IDs; -p also resolves every default PDO mapping entry.
    result = subprocess.run(
        [dcfchk(), "-n", str(node_id), "-p", str(eds_path(device))], capture_output=True, text=True, timeout=60
    )
    assert (result.returncode, result.stderr) == (0, "")


@pytest.mark.parametrize("device", DEVICES)
def test_dcf_lint_raises_no_warning(device: str) -> None:
    from dcf.lint import lint
    from dcf.parse import parse_file

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert lint(parse_file(str(eds_path(device))))
    assert [str(w.message) for w in caught] == []


# --- object lists ------------------------------------------------------------------------------------------------


def test_cd1k_has_exactly_the_manuals_objects(cd1k) -> None:
    indices = {obj.index for obj in cd1k.objects()}
    assert sorted(map(hex, indices - CD1K_INDICES)) == []
    assert sorted(map(hex, CD1K_INDICES - indices)) == []


def test_encotrive_has_exactly_the_manuals_objects(encotrive) -> None:
    indices = {obj.index for obj in encotrive.objects()}
    assert sorted(map(hex, indices - ENCOTRIVE_INDICES)) == []
    assert sorted(map(hex, ENCOTRIVE_INDICES - indices)) == []
    assert not indices & ENCOTRIVE_LEFT_OUT


@pytest.mark.parametrize("device", DEVICES)
def test_every_entry_has_a_group_and_a_line_reference(device: str) -> None:
    od = load_dictionary(eds_path(device))
    for var in od.variables():
        where = f"0x{var.index:04X},{var.subindex}"
        assert var.group, where
        if var.index in PROJECT_OBJECTS:
            assert var.reference.startswith("docs/"), where
            continue
        assert var.reference.startswith("L") and var.reference[1:].isdigit(), where


@pytest.mark.skipif(MANUALS is None, reason=NO_MANUALS)
def test_cd1k_references_point_at_the_objects_lines(cd1k) -> None:
    lines = (MANUALS / "001_c18fe7dc514993d8.txt").read_text(encoding="utf-8").splitlines()
    for var in cd1k.variables():
        if var.index in PROJECT_OBJECTS:
            continue
        line = lines[int(var.reference[1:]) - 1]
        sub = var.subindex
        on_topic = (
            f"{var.index:04X}" in line.upper()
            or f"Sub Index\t{sub}" in line
            or f"\t{sub}\t" in line
            or f"\t{sub} " in line
            or "Number of" in line
        )
        assert on_topic, f"0x{var.index:04X},{sub} -> {var.reference}: {line[:80]!r}"


@pytest.mark.skipif(MANUALS is None, reason=NO_MANUALS)
def test_encotrive_references_are_manual_pages(encotrive) -> None:
    lines = (MANUALS / "004_763c81f3de1dfaca.txt").read_text(encoding="utf-8").splitlines()
    for var in encotrive.variables():
        number = int(var.reference[1:])
        assert number <= 115 or lines[number - 1].startswith("Page "), f"0x{var.index:04X},{var.subindex}"


# --- identity ----------------------------------------------------------------------------------------------------


def test_cd1k_identity(cd1k) -> None:
    assert (cd1k.device, cd1k.vendor_id, cd1k.product_code) == ("cd1k", 0x82, 0)
    assert sorted(cd1k.object(0x1018).subs) == [0, 1]  # the CD1-k implements only the vendor-ID
    assert cd1k[(0x1018, 1)].default == 0x82
    assert cd1k[(0x1000, 0)].default == 0x00020192
    assert cd1k[(0x1008, 0)].default == "CD1-k"
    assert cd1k[(0x6504, 0)].default == "Infranor"
    assert cd1k[(0x6510, 1)].default == 2 and cd1k[(0x6510, 1)].enum[2] == "CD1-k"


def test_encotrive_identity(encotrive) -> None:
    assert (encotrive.device, encotrive.vendor_id, encotrive.product_code, encotrive.revision) == (
        "encotrive",
        0,
        736025,
        0x00040003,
    )
    identity = {sub: var.default for sub, var in encotrive.object(0x1018).subs.items()}
    assert identity == {0: 4, 1: 0, 2: 736025, 3: 0x00040003, 4: 1}
    assert encotrive[(0x1000, 0)].default == 0x00020192
    assert encotrive[(0x100A, 0)].default == "V4.3 28 Feb 2006"


# --- communication -----------------------------------------------------------------------------------------------


def test_cd1k_default_pdos_suit_the_interpolated_position_mode(cd1k) -> None:
    mapping = {
        index: (cd1k[(index, 0)].default, cd1k[(index, 1)].default)
        for index in (0x1600, 0x1601, 0x1602, 0x1A00, 0x1A01, 0x1A02)
    }
    assert mapping == {
        0x1600: (1, 0x60400010),
        0x1601: (1, 0x60FF0020),
        0x1602: (1, 0x60C10120),
        0x1A00: (1, 0x60410010),
        0x1A01: (1, 0x606C0020),
        0x1A02: (1, 0x60640020),
    }
    types = {index: cd1k[(index, 2)].default for index in (0x1400, 0x1401, 0x1402, 0x1800, 0x1801, 0x1802)}
    assert types == {0x1400: 253, 0x1401: 253, 0x1402: 1, 0x1800: 253, 0x1801: 253, 0x1802: 1}
    assert all(cd1k[(0x1600, sub)].is_pointer for sub in range(1, 5))
    assert cd1k[(0x1600, 0)].high == 4
    assert sorted(cd1k.object(0x1800).subs) == [0, 1, 2]  # no inhibit time, no event timer


def test_encotrive_pdos_are_unmapped_with_a_tenth_of_ms_event_timer(encotrive) -> None:
    for index in [*range(0x1600, 0x1606), *range(0x1A00, 0x1A06)]:
        assert encotrive[(index, 0)].default == 0 and encotrive[(index, 0)].high == 8
        assert all(encotrive[(index, sub)].default == 0 for sub in range(1, 9))
    timer = encotrive[(0x1800, 5)]
    assert (timer.unit, timer.scale, timer.to_physical(10)) == ("ms", 0.1, pytest.approx(1.0))
    assert sorted(encotrive.object(0x1800).subs) == [0, 1, 2, 3, 5]
    assert encotrive[(0x1400, 2)].default == 255


@given(node=st.integers(min_value=1, max_value=127))
def test_default_cob_ids_follow_the_predefined_connection_set(cd1k, encotrive, node: int) -> None:
    expected = {
        (0x1014, 0): 0x80,
        (0x1200, 1): 0x600,
        (0x1200, 2): 0x580,
        (0x1400, 1): 0x200,
        (0x1401, 1): 0x300,
        (0x1402, 1): 0x400,
        (0x1800, 1): 0x180,
        (0x1801, 1): 0x280,
        (0x1802, 1): 0x380,
    }
    assert {key: cd1k[key].default_for(node) for key in expected} == {k: v + node for k, v in expected.items()}
    assert encotrive[(0x1400, 1)].default_for(node) == 0x200 + node
    assert encotrive[(0x1800, 1)].default_for(node) == 0x180 + node
    assert encotrive[(0x1014, 0)].default_for(node) == 0x80 + node


# --- device control ------------------------------------------------------------------------------------------------


def test_modes_of_operation(cd1k, encotrive) -> None:
    assert cd1k[(0x6060, 0)].access is Access.WO and encotrive[(0x6060, 0)].access is Access.WO
    assert set(cd1k[(0x6061, 0)].enum) == {1, 3, 4, 6, 7, -1, -2}
    assert cd1k[(0x6061, 0)].default == 7  # interpolated position is the CD1-k default mode
    assert cd1k[(0x6502, 0)].default == 0x6D
    assert set(encotrive[(0x6060, 0)].enum) == {1, 3}


def test_control_and_status_word_quirks(cd1k, encotrive) -> None:
    cd1k_cw = {bit.first: bit.name for bit in cd1k[(0x6040, 0)].bits}
    assert 8 not in cd1k_cw and "Out of limit" in cd1k_cw[11]
    cd1k_sw = {bit.first: bit.name for bit in cd1k[(0x6041, 0)].bits}
    assert "Low speed" in cd1k_sw[14] and "busy" in cd1k_sw[15].lower()
    enco_cw = {bit.first: bit.name for bit in encotrive[(0x6040, 0)].bits}
    assert "Halt" in enco_cw[8]
    enco_sw = {bit.first: bit.name for bit in encotrive[(0x6041, 0)].bits}
    assert "parameter access via CAN" in enco_sw[9] and "working range" in enco_sw[11]


def test_stop_options(cd1k, encotrive) -> None:
    assert set(cd1k[(0x605A, 0)].enum) == {0, 1, 3} and cd1k[(0x605A, 0)].default == 3
    assert cd1k[(0x3331, 0)].default == 0x41
    assert set(encotrive[(0x605E, 0)].enum) == {0, 1, 2, 3, 4}
    assert set(encotrive[(0x6007, 0)].enum) == {0, 1, 2, 3}
    assert encotrive[(0x6085, 0)].default == 9000


def test_cd1k_homing_methods(cd1k) -> None:
    methods = set(cd1k[(0x6098, 0)].enum)
    assert methods == {*range(1, 15), *range(17, 31), 33, 34, 35, -1, -2, -3, -4}
    assert cd1k[(0x6098, 0)].default == 35
    assert 0x6098 not in {obj.index for obj in load_dictionary(eds_path("encotrive")).objects()}


# --- procedures, save ----------------------------------------------------------------------------------------------


def test_cd1k_signatures_are_the_manuals_hex_values(cd1k) -> None:
    for key, signatures in CD1K_SIGNATURES.items():
        var = cd1k[key]
        assert var.data_type is DataType.UNSIGNED32 and var.access is Access.RW  # status read-back (decisions 4)
        for ascii_code, printed in signatures.items():
            assert int.from_bytes(ascii_code.encode(), "little") == printed
            assert ascii_code in var.enum[printed]
        assert {0, 2, 5} <= set(var.enum)  # never executed / abort, running, done


def test_cd1k_save_type_marks_the_eeprom_parameters(cd1k) -> None:
    saved = {(var.index, var.subindex) for var in cd1k.variables() if var.save_type is SaveType.DRIVEPAR}
    assert sorted(saved - CD1K_EEPROM) == [] and sorted(CD1K_EEPROM - saved) == []
    assert cd1k[(0x3006, 1)].save_type is SaveType.NONE  # "not saved" (L801)


def test_encotrive_store_and_restore_signatures(encotrive) -> None:
    for sub in range(1, 5):
        assert encotrive[(0x1010, sub)].enum == {0x65766173: "Store ('save')"}
        assert encotrive[(0x1011, sub)].enum == {0x64616F6C: "Restore ('load')"}
    assert encotrive[(0x6072, 0)].save_type is SaveType.DRIVEPAR
    for setpoint in (0x6040, 0x607A, 0x60FF, 0x6071):
        assert encotrive[(setpoint, 0)].save_type is SaveType.NONE


# --- units and limits ----------------------------------------------------------------------------------------------


def test_cd1k_current_and_analog_scalings(cd1k) -> None:
    assert cd1k[(0x6510, 5)].to_physical(0x3FFF) == pytest.approx(100.0)
    assert cd1k[(0x30D1, 0)].to_physical(0x3FFF) == pytest.approx(100.0)
    assert cd1k[(0x30C1, 0)].to_physical(-0x7FFF) == pytest.approx(-10.0)
    assert cd1k[(0x6510, 4)].to_physical(1250) == pytest.approx(12.5)
    assert cd1k[(0x309B, 0)].to_physical(0x8000) == pytest.approx(180.0)
    assert cd1k[(0x6080, 0)].unit == "rpm" and cd1k[(0x6081, 0)].unit == "inc/s"


def test_documented_ranges_are_enforced(cd1k, encotrive) -> None:
    resolution = cd1k[(0x608F, 1)]
    resolution.check(400)
    resolution.check(4_000_000)
    for bad in (399, 4_000_001):
        with pytest.raises(OutOfRange):
            resolution.check(bad)
    with pytest.raises(OutOfRange):
        cd1k[(0x3420, 1)].check(9)  # bandwidth 0..8
    with pytest.raises(OutOfRange):
        encotrive[(0x6072, 0)].check(10001)  # max torque 0..10000 per mille


def test_encotrive_factor_group_defaults_give_rpm(encotrive) -> None:
    assert (encotrive[(0x608F, 1)].default, encotrive[(0x608F, 2)].default) == (4096, 1)
    assert (encotrive[(0x6090, 1)].default, encotrive[(0x6090, 2)].default) == (2**31, 5000)
    assert (encotrive[(0x6094, 1)].default, encotrive[(0x6094, 2)].default) == (2**31, 300000)
    assert (encotrive[(0x6097, 1)].default, encotrive[(0x6097, 2)].default) == (2**31, 300000)
    # 1 rpm = (1/60) rev/s = 2^31/5000/60 speed increments per second = the default speed factor
    assert pytest.approx(2**31 / 300000) == 2**31 / 5000 / 60


def test_record_kinds(cd1k, encotrive) -> None:
    assert cd1k.object(0x60F9).kind is ObjectKind.RECORD and len(cd1k.object(0x60F9).subs) == 9
    assert cd1k.object(0x2501).kind is ObjectKind.RECORD and len(cd1k.object(0x2501).subs) == 21
    assert encotrive.object(0x1003).kind is ObjectKind.ARRAY and len(encotrive.object(0x1003).subs) == 9
    assert encotrive[(0x2DFE, 0)].data_type is DataType.DOMAIN


def test_the_library_matches_a_scanned_identity_to_the_right_dictionary() -> None:
    from servostudio.od import EdsLibrary

    library = EdsLibrary(builtin_dir=EDS_DIR)
    assert {"cd1k", "encotrive"} <= set(library.devices())
    assert library.match(0x82, 0) == "cd1k"  # a CD1-k aborts the read of 1018h/2: product code 0
    assert library.match(0, 736025) == "encotrive"
    assert library.match(0x82, 736025) is None


def _label(name: str) -> str:
    """The first word of a bit's name: what a panel with one short label per bit shows."""
    return name.replace("/", " ").replace("(", " ").split()[0]


def test_cd1k_io_bits_carry_the_manuals_own_input_and_output_names(cd1k) -> None:
    inputs = {field.first: field.name for field in cd1k[0x60FD, 0].bits}
    outputs = {field.first: field.name for field in cd1k[0x60FE, 1].bits}
    assert [_label(inputs[bit]) for bit in range(16, 22)] == [
        "INPUT0",
        "INPUT1",
        "INHIBIT",
        "INPUT3",
        "INPUT4",
        "INPUT5",
    ]
    assert [_label(outputs[bit]) for bit in (0, 16, 17, 18, 19)] == ["Brake", "DO0", "DO1", "DO2", "DO3"]
    for word in (inputs, outputs):
        labels = [_label(name) for name in word.values()]
        assert len(set(labels)) == len(labels), labels
