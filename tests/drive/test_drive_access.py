"""Drive access against the simulated XtrapulsPac drives over socketcand and the RS-232 link: scan, typed values."""

from __future__ import annotations

import pytest

from servostudio.drive.access import DriveAccessError
from servostudio.drive.sdo import SdoAbortError
from servostudio.od.datatypes import DataType
from servostudio.od.model import Access
from servostudio.services.bus import ConnectionManager
from servostudio.services.scan import scan


class FrameCounter:
    """A station on the simulated bus that counts every frame (to prove that nothing was sent)."""

    def __init__(self) -> None:
        self.frames = []

    def receive(self, frame, timestamp) -> None:
        self.frames.append(frame)


@pytest.fixture(scope="module")
def connection(endpoint):
    manager = ConnectionManager()
    bus = manager.open(endpoint.spec)
    assert bus.link.connected
    scan(bus)
    yield bus
    manager.close_all()


def test_scan_finds_and_identifies_every_drive(connection):
    assert sorted(connection.nodes) == [1, 2, 3]
    for info in connection.nodes.values():
        assert info.device == "xtrapulspac"
        assert info.vendor_id == 0x82
        assert info.device_name


def _sample_variable(drive, data_type: DataType):
    """A writable object of this type without side effects on other objects."""
    for var in drive.dictionary.variables():
        if (
            var.data_type is data_type
            and var.access is Access.RW
            and var.index >= 0x2000
            and var.index not in (0x6040, 0x6060, 0x3410, 0x6410, 0x2004)
            and not var.is_pointer
            and var.minimum is not None
            and var.maximum is not None
            and var.maximum > var.minimum
        ):
            return var
    pytest.skip(f"no plain rw {data_type.name} object in the dictionary")


@pytest.mark.parametrize(
    "data_type",
    [
        DataType.INTEGER8,
        DataType.INTEGER16,
        DataType.INTEGER32,
        DataType.UNSIGNED8,
        DataType.UNSIGNED16,
        DataType.UNSIGNED32,
    ],
)
def test_write_and_read_back_every_integer_type(connection, data_type):
    drive = connection.drive(2)
    var = _sample_variable(drive, data_type)
    for value in {var.minimum, var.maximum, (var.minimum + var.maximum) // 2}:
        written = drive.write(var, value)
        assert written.raw == value
        assert drive.read(var).raw == value


def test_text_object_round_trip(connection):
    drive = connection.drive(1)
    name = drive.variable("0x2004")
    assert name.data_type is DataType.VISIBLE_STRING
    drive.write(name, "Axis X, a longer name")  # segmented download and upload
    assert drive.read(name).raw.rstrip("\0") == "Axis X, a longer name"


def test_enumeration_label_and_physical_value(connection):
    drive = connection.drive(1)
    mode = drive.variable("modes_of_operation")
    label, key = next((label, key) for key, label in mode.enum.items() if key != 0)
    assert drive.write(mode, label).raw == key
    assert drive.read(mode).text == label


def test_refused_writes_send_nothing(connection, sim_network):
    drive = connection.drive(1)
    counter = FrameCounter()
    sim_network.attach(counter)
    try:
        with pytest.raises(DriveAccessError, match=r"node 1: 0x6041,0 Statusword is read-only"):
            drive.write("statusword", 6)
        with pytest.raises(DriveAccessError, match=r"node 1: 0x3410,1 .*Pole pairs: 99 is outside 1..24"):
            drive.write("0x3410,1", 99)
        with pytest.raises(DriveAccessError, match="is not a number"):
            drive.write("0x3410,1", "many")
        with pytest.raises(DriveAccessError, match="not in the xtrapulspac dictionary"):
            drive.write("0x2FFE,7", 1)
        with pytest.raises(DriveAccessError, match=r"Pole pairs: 99 is outside 1..24"):  # one bad write of a batch
            drive.submit_write_all([(drive.variable("0x3410,1"), 4), (drive.variable("0x3410,1"), 99)])
    finally:
        sim_network.detach(counter)
    assert [frame for frame in counter.frames if frame.can_id in (0x601, 0x641)] == []  # (others: the bus monitor)


def test_drive_refusal_is_a_readable_abort(connection):
    drive = connection.drive(1)
    with pytest.raises(SdoAbortError, match=r"node 1, object 0x2FFE,0: object does not exist"):
        connection.engine.upload(1, 0x2FFE, 0).result(2)
    assert drive.read("0x1000").raw > 0  # the node is still served after the abort
