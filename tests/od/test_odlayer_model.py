"""The loaded dictionary: kinds, compact arrays, props inheritance, $NODEID, lookup, value checks and scaling."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.od import (
    Access,
    BitField,
    DataType,
    ObjectKind,
    OutOfRange,
    Pointer,
    SaveType,
    WrongType,
    load_dictionary,
)


@pytest.fixture
def od(write_files):
    return load_dictionary(write_files())


def test_device_identity_and_sizes(od) -> None:
    assert (od.device, od.product_name, od.vendor_id, od.product_code, od.revision) == (
        "mini",
        "Mini drive",
        0x12,
        0x34,
        1,
    )
    assert [obj.index for obj in od.objects()] == [0x1000, 0x1001, 0x1018, 0x1800, 0x2000, 0x2100, 0x6041]
    assert len(od) == 1 + 1 + 3 + 2 + 4 + 1 + 1
    assert [v.key for v in od.variables()][:3] == [(0x1000, 0), (0x1001, 0), (0x1018, 0)]
    assert 0x6041 in od and (0x1018, 2) in od and (0x1018, 3) not in od
    assert len(set(od.variables())) == len(od), "entries are hashable and distinct"


def test_entries_carry_eds_values(od) -> None:
    device_type = od[0x1000, 0]
    assert (device_type.data_type, device_type.access, device_type.default) == (
        DataType.UNSIGNED32,
        Access.RO,
        0x00020192,
    )
    assert od.object(0x1018).kind is ObjectKind.RECORD
    assert od[0x1018, 1].parent_name == "Identity" and od[0x1018, 1].name == "Vendor-ID"
    assert od[0x1001, 0].pdo_mappable and not od[0x1000, 0].pdo_mappable
    speed = od[0x2100, 0]
    assert (speed.low, speed.high, speed.default) == (10, 6000, 3000)


def test_compact_array_expands_with_names_limits_and_inherited_props(od) -> None:
    gains = od.object(0x2000)
    assert gains.kind is ObjectKind.ARRAY and gains.group == "Servo Loops"
    assert sorted(gains.subs) == [0, 1, 2, 3]
    count = gains.subs[0]
    assert (count.data_type, count.default, count.unit, count.enum) == (DataType.UNSIGNED8, 3, "", {})
    assert [gains.subs[i].name for i in (1, 2, 3)] == ["Gains1", "Middle gain", "Gains3"]
    middle = gains.subs[2]
    assert (middle.low, middle.high, middle.default, middle.access) == (-100, 100, 5, Access.RW)
    assert (middle.unit, middle.scale, middle.save_type, middle.enum) == (
        "mA",
        0.5,
        SaveType.DRIVEPAR,
        {-5: "Minus five"},
    )
    assert middle.description == "The middle one" and gains.subs[1].description == ""


def test_bits_and_other_props(od) -> None:
    status = od[0x6041, 0]
    assert status.bits == (BitField(0, 0, "Ready to switch on"), BitField(8, 9, "Manufacturer field"))
    assert status.bits[1].extract(0x0300) == 3 and status.bits[1].mask == 0x0300
    speed = od[0x2100, 0]
    assert (speed.group, speed.unit, speed.save_type, speed.reference, speed.is_pointer) == (
        "Motor",
        "rpm",
        SaveType.USER_PAR,
        "L42",
        False,
    )
    assert od[0x1000, 0].save_type is SaveType.NONE and od[0x1000, 0].group == ""


@given(st.integers(1, 127))
def test_nodeid_defaults_resolve_per_node(mini_od, node_id: int) -> None:
    od = mini_od
    cob_id = od[0x1800, 1]
    assert (cob_id.default, cob_id.default_expr) == (0x180, "$NODEID+0x180")
    assert cob_id.default_for(node_id) == 0x180 + node_id
    assert od[0x2100, 0].default_for(node_id) == 3000


@pytest.mark.parametrize(
    ("query", "key"),
    [
        ("0x6041", (0x6041, 0)),
        ("6041", (0x6041, 0)),
        ("0x1018,2", (0x1018, 2)),
        ("1018:0x2", (0x1018, 2)),
        ("0x1018sub2", (0x1018, 2)),
        ("0x2000subA", None),
        ("Statusword", (0x6041, 0)),
        ("middle GAIN", (0x2000, 2)),
        ("Identity.Product code", (0x1018, 2)),
    ],
)
def test_find_by_address_or_name(od, query: str, key) -> None:
    if key is None:
        with pytest.raises(KeyError):
            od.find(query)
    else:
        assert od.find(query).key == key


def test_find_refuses_ambiguous_names(od) -> None:
    with pytest.raises(KeyError, match="ambiguous"):
        od.find("Highest sub-index supported")


def test_check_enforces_type_and_limits(od) -> None:
    speed = od[0x2100, 0]
    speed.check(10)
    speed.check(6000)
    with pytest.raises(OutOfRange, match=r"0x2100,0 Speed limit: 6001 is outside 10..6000"):
        speed.check(6001)
    with pytest.raises(WrongType):
        speed.check(12.5)
    with pytest.raises(WrongType):
        speed.check(True)
    with pytest.raises(OutOfRange):
        od[0x1001, 0].check(256)  # no LowLimit/HighLimit: the type range applies


@given(st.integers(-100, 100))
def test_physical_scaling_round_trip(mini_od, raw: int) -> None:
    gain = mini_od[0x2000, 1]
    physical = gain.to_physical(raw)
    assert physical == raw * 0.5
    assert gain.from_physical(physical) == raw


@given(st.integers(0, 0xFFFF_FFFF))
def test_pointer_round_trip(value: int) -> None:
    pointer = Pointer.decode(value)
    assert pointer.encode() == value
    assert pointer.key == (value >> 16, (value >> 8) & 0xFF)


def test_pointer_fields_are_checked() -> None:
    assert Pointer.decode(0x60400010) == Pointer(0x6040, 0, 16)
    with pytest.raises(ValueError):
        Pointer(0x10000, 0, 0)
    with pytest.raises(ValueError):
        Pointer.decode(-1)


def test_groups_in_order_of_their_first_object(mini_od) -> None:
    assert mini_od.groups() == ["Servo Loops", "Motor", "Device Control"]
