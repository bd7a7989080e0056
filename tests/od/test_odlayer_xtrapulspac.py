"""The built-in XtrapulsPac dictionary against the manual (*XtrapulsPac User Guide*, object list §3.3 L15497-16464
and the body).

The expected indices and values are written here from the manual, not from the EDS.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from servostudio.od import Access, DataType, ObjectKind, SaveType, load_dictionary

REPO = Path(__file__).resolve().parents[2]

MANUAL_LIST = {
    # Communication
    0x1005,
    0x1006,
    0x100C,
    0x100D,
    0x1014,
    0x1016,
    0x1017,
    0x1018,
    0x1200,
    0x1201,
    0x1280,
    0x1281,
    0x1400,
    0x1401,
    0x1402,
    0x1403,
    0x1600,
    0x1601,
    0x1602,
    0x1603,
    0x1800,
    0x1801,
    0x1802,
    0x1803,
    0x1A00,
    0x1A01,
    0x1A02,
    0x1A03,
    0x2000,
    0x2001,
    0x2004,
    0x2006,
    0x200A,
    0x2010,
    0x205D,
    0x205E,
    0x205F,
    0x2300,
    0x2301,
    0x2310,
    # General
    0x1000,
    0x1008,
    0x1009,
    0x100A,
    0x5F80,
    0x1010,
    0x1011,
    0x6510,
    0x6502,
    0x6504,
    0x3079,
    0x33B0,
    0x3328,
    # Device control
    0x6040,
    0x6041,
    0x605A,
    0x605B,
    0x605C,
    0x305A,
    0x6060,
    0x6061,
    0x3041,
    0x3044,
    0x3045,
    0x3440,
    0x3441,
    0x306B,
    0x306E,
    0x3300,
    0x3301,
    0x3302,
    0x6085,
    0x3304,
    0x3305,
    # Factor group, motor
    0x608F,
    0x6093,
    0x6089,
    0x608A,
    0x3089,
    0x308A,
    0x6410,
    0x6072,
    0x6073,
    0x6075,
    0x6076,
    0x3410,
    0x340F,
    0x3323,
    0x3324,
    # Sensors
    0x306A,
    0x3070,
    0x3100,
    0x3101,
    0x3102,
    0x3104,
    0x3105,
    0x3107,
    0x3108,
    0x3109,
    0x310A,
    0x310C,
    0x3120,
    0x3121,
    0x3122,
    0x3124,
    0x3127,
    0x3128,
    0x3129,
    0x312A,
    0x312B,
    0x312C,
    0x312D,
    0x313E,
    0x3180,
    0x3181,
    0x3187,
    0x3188,
    0x3189,
    0x318A,
    0x318B,
    0x318C,
    0x318D,
    0x318E,
    0x3190,
    0x3191,
    0x319E,
    # Servo loops
    0x3400,
    0x3402,
    0x3408,
    0x30DA,
    0x30D1,
    0x30D2,
    0x30D4,
    0x30D5,
    0x3411,
    0x3412,
    0x60F6,
    0x30F5,
    0x6079,
    0x30F4,
    0x3413,
    0x3414,
    0x60F9,
    0x30F9,
    0x30FA,
    0x30F8,
    # Position control
    0x307B,
    0x607B,
    0x60FB,
    0x30FC,
    0x6062,
    0x60B0,
    0x6063,
    0x6064,
    0x6065,
    0x3065,
    0x60F4,
    # External feedforward, auto-tuning, error control
    0x31FF,
    0x3425,
    0x3426,
    0x3427,
    0x3022,
    0x3023,
    0x3024,
    0x3025,
    0x3404,
    # Profile position, homing, interpolated position
    0x607A,
    0x6080,
    0x6081,
    0x6082,
    0x6083,
    0x6084,
    0x6086,
    0x6067,
    0x6068,
    0x607D,
    0x607F,
    0x3360,
    0x3081,
    0x3082,
    0x3083,
    0x607C,
    0x6098,
    0x6099,
    0x609A,
    0x309C,
    0x309D,
    0x60C0,
    0x60C1,
    0x30C1,
    0x3350,
    # Profile velocity, profile torque
    0x60B1,
    0x30B1,
    0x60FF,
    0x606B,
    0x606C,
    0x306C,
    0x3069,
    0x606D,
    0x606E,
    0x606F,
    0x6070,
    0x30FF,
    0x6071,
    0x3071,
    0x6087,
    0x6088,
    0x60B2,
    0x30B2,
    0x30B3,
    0x6074,
    0x6077,
    0x6078,
    0x3078,
    # Sequence, stepper emulation, analog speed
    0x3601,
    0x3602,
    0x3603,
    0x3604,
    0x3605,
    0x360B,
    0x360C,
    0x360F,
    0x3610,
    0x3611,
    0x3612,
    0x3681,
    0x3683,
    0x604F,
    0x304F,
    # Application features
    0x60FD,
    0x3050,
    0x3051,
    0x60FE,
    0x3054,
    0x3055,
    0x3058,
    0x3043,
    0x30F1,
    0x30F2,
    0x30A1,
    0x3160,
    0x30E0,
    0x30E1,
    # Oscilloscope, firmware update
    0x5800,
    0x5804,
    0x5805,
    0x5810,
    0x5811,
    0x5812,
    0x5820,
    0x5822,
    0x5828,
    0x5829,
    0x5840,
    0x5841,
    0x5F30,
    0x5F31,
    0x5F32,
}

DEFINED_IN_BODY_ONLY = {
    0x1001,
    0x1007,
    0x23A0,
    0x23A1,
    0x603F,
    0x6402,
    0x306D,
    0x3126,
    0x3130,
    0x3131,
    0x3325,
    0x3420,
    0x3442,
    0x3218,
    0x3077,
    0x3685,
    0x3686,
    0x3901,
    0x3902,
    0x3903,
    0x3906,
    0x3910,
    0x3911,
    0x3912,
    0x3913,
    0x3915,
    0x3916,
    0x391A,
    0x391B,
    0x391C,
    0x391D,
    0x3940,
    0x3941,
    0x3942,
    0x3943,
    0x3944,
    0x3920,
    0x3921,
    0x3925,
    0x3926,
    0x3927,
    0x3928,
    0x392A,
    0x392C,
    0x392D,
    0x392F,
    0x3938,
    0x3370,
    0x3371,
    0x3372,
    0x3373,
    0x3374,
    0x337F,
    0x60B8,
    0x60B9,
    0x60BA,
    0x60BB,
    0x60BC,
    0x60BD,
    0x60D0,
    0x3821,
    0x3822,
    0x3823,
    0x3824,
    0x3825,
    0x3828,
    0x3829,
    0x30A2,
    0x3059,
    0x5801,  # the oscilloscope buffer (docs/decisions.md §2, layout in docs/eds.md)
}

MANUAL_GROUPS = {
    "Communication",
    "General",
    "Device Control",
    "Factor",
    "Motor",
    "Sensors",
    "Servo Loops",
    "Position Control",
    "Profile Position Mode",
    "Homing Mode",
    "Interpolated Position Mode",
    "Profile Velocity Mode",
    "Profile Torque Mode",
    "Sequence Mode",
    "Stepper Emulation Mode",
    "Analog Speed Mode",
    "Oscilloscope",
    "Firmware Update",
}


@pytest.fixture(scope="module")
def od():
    return load_dictionary(REPO / "eds" / "xtrapulspac.eds")


def sig(text: str) -> int:
    return int.from_bytes(text.encode("ascii"), "little")


def test_every_object_of_the_manual_list_and_body_is_present(od) -> None:
    present = {obj.index for obj in od.objects()}
    assert sorted(hex(i) for i in MANUAL_LIST - present) == []
    assert sorted(hex(i) for i in DEFINED_IN_BODY_ONLY - present) == []


def test_identity_and_sdo_channels(od) -> None:
    assert (od.vendor_id, od[0x1018, 1].default) == (0x82, 0x82)
    assert od[0x1018, 2].default == od.product_code
    assert od[0x1000, 0].default == 0x00020192
    assert (od[0x1200, 1].default_for(5), od[0x1200, 2].default_for(5)) == (0x605, 0x585)
    assert (od[0x1201, 1].default_for(5), od[0x1201, 2].default_for(5)) == (0x645, 0x5C5)
    assert od[0x1014, 0].default_for(63) == 0x80 + 63


@pytest.mark.parametrize(
    ("index", "cob", "trans", "count", "mapped"),
    [
        (0x1400, 0x200, 255, 1, 0x60400010),
        (0x1401, 0x300, 255, 1, 0x60FF0020),
        (0x1402, 0x400, 1, 1, 0x60C10120),
        (0x1403, 0x500, 0, 0, 0),
        (0x1800, 0x180, 253, 1, 0x60410010),
        (0x1801, 0x280, 253, 1, 0x606C0020),
        (0x1802, 0x380, 1, 1, 0x60640020),
        (0x1803, 0x480, 0, 0, 0),
    ],
)
def test_pdo_defaults_from_the_manual(od, index: int, cob: int, trans: int, count: int, mapped: int) -> None:
    mapping = index + 0x200
    assert od[index, 1].default_for(7) == cob + 7 and od[index, 2].default == trans
    assert (od[mapping, 0].default, od[mapping, 1].default) == (count, mapped)
    assert od[mapping, 0].high == 4 and od[mapping, 1].is_pointer


def test_default_pdo_mappings_point_at_mappable_objects_of_that_size(od) -> None:
    for index in [*range(0x1600, 0x1604), *range(0x1A00, 0x1A04)]:
        for sub in range(1, 5):
            pointer = od[index, sub].default
            if pointer:
                target = od[pointer >> 16, (pointer >> 8) & 0xFF]
                assert target.pdo_mappable and target.data_type.bits == pointer & 0xFF, hex(pointer)


def test_pointer_defaults_name_existing_objects(od) -> None:
    for var in od.variables():
        if var.is_pointer and isinstance(var.default, int) and var.default > 0xFF:
            assert ((var.default >> 16), (var.default >> 8) & 0xFF) in od, (var.label, hex(var.default))


def test_device_control_words(od) -> None:
    control, status = od[0x6040, 0], od[0x6041, 0]
    assert (control.data_type, control.access, control.pdo_mappable) == (DataType.UNSIGNED16, Access.RW, True)
    assert {b.first: b.name for b in control.bits}[7] == "Fault reset"
    status_bits = {b.first: b.name for b in status.bits}
    assert status_bits[3] == "Fault" and status_bits[15] == "Drive busy" and status.access is Access.RO
    mode = od[0x6060, 0]
    assert (mode.data_type, mode.save_type) == (DataType.INTEGER8, SaveType.DRIVEPAR)
    assert mode.enum[-3] == "Sequence" and mode.enum[1] == "Profile position" and mode.enum[-6]
    assert od[0x605A, 0].default == 1 and od[0x605B, 0].default == 0 and od[0x605C, 0].default == 1


def test_errors_and_warnings_are_decoded_bit_by_bit(od) -> None:
    word1 = {b.first: b.name for b in od[0x3022, 1].bits}
    word2 = {b.first: b.name for b in od[0x3022, 2].bits}
    assert len(word1) == 32 and len(word2) == 32
    assert "Overcurrent" in word1[17] and "Procedure" in word2[31] and "I2t" in word2[5]
    assert {b.first: b.name for b in od[0x3025, 4].bits} == word2
    assert od[0x3025, 7].default == 0x00000004
    warnings = {b.first: b.name for b in od[0x3024, 0].bits}
    assert "Undervoltage" in warnings[19] and "phasing" in warnings[30]


def test_procedures_accept_their_signatures(od) -> None:
    assert sig("save") in od[0x1010, 1].enum and sig("sseq") in od[0x1010, 1].enum
    assert {sig(s) for s in ("load", "lusr", "lseq", "mseq")} <= set(od[0x1011, 1].enum)
    for index, signature in ((0x3413, "apha"), (0x3414, "mcal"), (0x3426, "atun"), (0x3411, "calc")):
        assert sig(signature) in od[index, 0].enum, hex(index)
        assert od[index, 0].enum[5] == "Done" and od[index, 0].save_type is SaveType.NONE


def test_motor_data_and_units(od) -> None:
    motor = od.object(0x6410)
    assert motor.kind is ObjectKind.RECORD and max(motor.subs) == 25
    assert motor.subs[1].data_type is DataType.VISIBLE_STRING
    assert (motor.subs[14].low, motor.subs[14].high) == (1, 24)
    assert motor.subs[9].to_physical(2500) == pytest.approx(2.5) and motor.subs[9].unit == "A"
    assert od[0x6073, 0].to_physical(1000) == pytest.approx(100.0)  # per mille of rated current -> %
    assert od[0x6079, 0].data_type is DataType.INTEGER32 and od[0x6079, 0].to_physical(325000) == pytest.approx(325)
    assert od[0x306C, 0].default == 800 and od[0x306C, 0].to_physical(800) == pytest.approx(80.0)


def test_values_documented_in_the_manual(od) -> None:
    assert (od[0x1006, 0].low, od[0x1006, 0].high, od[0x1006, 0].default) == (0, 150000, 10000)
    assert [od[0x2006, s].default for s in range(1, 6)] == [0, 20, 2, 500, 0]
    assert od[0x2006, 1].data_type is DataType.INTEGER16
    assert (od[0x3301, 1].low, od[0x3301, 1].high, od[0x3301, 1].default) == (100, 6000, 1000)
    assert (od[0x6093, 1].default, od[0x6093, 2].default, od[0x608F, 1].default) == (4096, 4096, 0x1000)
    assert od[0x6085, 0].default == 0x00200000 and od[0x6098, 0].default == 35
    assert (od[0x6099, 1].default, od[0x6099, 2].default) == (25, 10)
    assert (od[0x30D1, 0].high, od[0x30D1, 0].default, od[0x30DA, 0].default) == (0x3FFF, 0x3FFF, 0x30D10000)
    assert (od[0x30FF, 0].default, od[0x3071, 0].default) == (0x60FF0000, 0x60710000)
    assert (od[0x60D0, 1].default, od[0x60D0, 2].default) == (3, -5)
    assert od[0x3611, 1].enum[4] == "TORQUE" and (od[0x3611, 2].low, od[0x3611, 2].high) == (-1, 127)
    assert od[0x30F1, 4].default == 256 and od[0x3160, 1].default == 0x31000400
    assert od[0x5F32, 5].data_type is DataType.DOMAIN


def test_save_types(od) -> None:
    drivepar = [
        (0x3442, 0),
        (0x306B, 0),
        (0x306E, 0),
        (0x3079, 0),
        (0x6510, 4),
        (0x6510, 5),
        (0x313E, 0),
        (0x3191, 2),
        (0x3191, 6),
        (0x3128, 0),
        (0x3188, 0),
        (0x312D, 5),
        (0x6060, 0),
        (0x60F9, 2),
        (0x3821, 1),
        (0x3828, 2),
    ]
    for key in drivepar:
        assert od[key].save_type is SaveType.DRIVEPAR, key
    for key in [(0x6040, 0), (0x6041, 0), (0x607A, 0), (0x1010, 1), (0x5828, 0), (0x6510, 1)]:
        assert od[key].save_type is SaveType.NONE, key
    assert od[0x1600, 1].save_type is SaveType.USER_PAR and od[0x1006, 0].save_type is SaveType.USER_PAR


def test_every_object_has_a_manual_group_and_a_reference(od) -> None:
    groups = {obj.group for obj in od.objects()}
    assert groups >= MANUAL_GROUPS
    for obj in od.objects():
        assert obj.group, hex(obj.index)
        assert any(var.reference for var in obj.subs.values()) or obj.subs[0].reference, hex(obj.index)


def test_oscilloscope_layout(od) -> None:
    channels = [od[0x5811, n] for n in range(1, 5)]
    assert all(c.data_type is DataType.UNSIGNED32 and c.access is Access.RW and c.is_pointer for c in channels)
    sizes = 0
    for n, channel in enumerate(channels, start=1):
        pointer = channel.default
        source = od[pointer >> 16, (pointer >> 8) & 0xFF]
        assert source.pdo_mappable and source.data_type.bits == pointer & 0xFF
        assert od[0x5810, n].default == source.data_type.value  # channel data type code
        sizes += source.data_type.size
    assert od[0x5804, 5].default == sizes  # record size in bytes
    assert od[0x5804, 3].default == 250_000 and od[0x5804, 3].to_physical(250_000) == pytest.approx(250.0)
    assert od[0x5801, 0].data_type is DataType.DOMAIN and od[0x5841, 0].data_type is DataType.DOMAIN
    assert od[0x5829, 0].enum == {
        0: "Idle",
        1: "Filling pre-trigger",
        2: "Waiting for trigger",
        3: "Recording",
        4: "Done",
    }
    assert od[0x5828, 0].enum == {0: "Stop", 1: "Arm", 2: "Force trigger"}
    assert od[0x5820, 2].enum == {0: "Immediate", 1: "Edge"}
    assert od[0x5820, 3].enum == {0: "Single", 1: "Normal", 2: "Auto"}
    assert od[0x5820, 4].data_type is DataType.UNSIGNED16 and od[0x5820, 4].unit == "ms"
    assert od[0x5828, 0].pdo_mappable and od[0x5829, 0].pdo_mappable  # arm several drives with one RPDO
    assert od[0x5822, 2].enum == {0: "Rising", 1: "Falling", 2: "Either"}
    assert od[0x5805, 0].data_type is DataType.UNSIGNED16 and od[0x5822, 1].data_type is DataType.INTEGER32
