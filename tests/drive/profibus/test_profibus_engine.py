"""The PKW engine (docs/profibus.md §9): a `Drive` on the TTA-PRO parameter list reads and writes PNUs of the
simulated slave over its TCP stream exactly as it does CANopen objects — width and sign from the list, IND as the
subindex, a procedure waited for, a negative reply as a readable error naming the PNU, a value out of range refused
before anything is sent, and what only CANopen does refused."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from tests.support.profibus_line import TtaProLine, ttapro_line

from servostudio.drive.access import Drive, DriveAccessError
from servostudio.drive.profibus.engine import PkwEngine, PkwRefusal, StationOutOfRange
from servostudio.drive.profibus.link import NoCanFrames, ProfibusLink
from servostudio.drive.profiles import profile_for
from servostudio.drive.sdo import SdoAbortError
from servostudio.errors import ErrorKind
from servostudio.od.pnu import builtin_parameter_list
from servostudio.transport.profibus.master import ByteLink, DpMaster

ADDRESS = 5


@pytest.fixture(scope="module")
def line() -> Iterator[TtaProLine]:
    with ttapro_line(ADDRESS) as line:
        yield line


@pytest.fixture(scope="module")
def engine(line: TtaProLine) -> Iterator[PkwEngine]:
    parameters = builtin_parameter_list()
    link = ProfibusLink("pb", DpMaster(ByteLink(line.spec.replace("profibus:tcp:", "socket://"))))
    engine = PkwEngine(link, lambda node: parameters)
    link.start()
    yield engine
    link.close()


@pytest.fixture(scope="module")
def drive(engine: PkwEngine) -> Drive:
    return Drive(engine, ADDRESS, builtin_parameter_list(), profile_for("ttapro"))


def test_words_double_words_signs_and_indices(drive: Drive, line: TtaProLine) -> None:
    memory = line.slaves[ADDRESS].memory
    assert drive.read("PNU700").raw == 4 == memory.get(700)
    drive.write("kp_speed", 1234)  # the profile's name for PNU 730
    assert memory.get(730) == 1234 and drive.read((730, 0)).raw == 1234
    drive.write("software_position_limit_min", -123456)  # a signed double word
    assert memory.get(748) == -123456 and drive.read("PNU748").raw == -123456
    assert drive.read("PNU828[2]").raw == 0x2306 == memory.get(828, 2)  # IND = subindex


def test_a_batch_reads_every_e_parameter_in_order(drive: Drive, line: TtaProLine) -> None:
    assert drive.dictionary is not None
    variables = [var for var in drive.dictionary.variables() if var.index in (700, 721, 740, 757)]
    values = drive.submit_read_all(variables).outcomes()
    assert [value.raw for value in values] == [line.slaves[ADDRESS].memory.get(var.index) for var in variables]


def test_a_negative_reply_is_a_readable_conflict_naming_the_pnu(drive: Drive) -> None:
    with pytest.raises(PkwRefusal) as caught:
        drive.write("positioner_mode", 3)  # in 1..16 but not a mode: the drive refuses with error 2
    assert str(caught.value) == "node 5, PNU 720: lower or upper limit exceeded (PKW error 2)"
    assert isinstance(caught.value, SdoAbortError) and caught.value.kind is ErrorKind.CONFLICT
    assert (caught.value.index, caught.value.code) == (720, 2)


def test_out_of_range_is_refused_before_anything_is_sent(drive: Drive, engine: PkwEngine, monkeypatch) -> None:
    sent: list[tuple] = []
    monkeypatch.setattr(engine, "download", lambda *args, **kwargs: sent.append(args))
    with pytest.raises(DriveAccessError, match=r"^node 5: PNU 700 Number of motor pole pairs: 99 is outside 1\.\.32$"):
        drive.write("PNU700", 99)
    with pytest.raises(DriveAccessError, match="PNU 774 Motor position is read-only"):
        drive.write("position_actual", 0)
    assert sent == []


def test_the_save_procedure_is_waited_for(drive: Drive, line: TtaProLine) -> None:
    slave = line.slaves[ADDRESS]
    drive.write("max_motor_speed", 3000)
    drive.start_procedure("save")  # PNU 729 = 1, through the PKW procedure handshake
    drive.write("max_motor_speed", 2000)
    slave.power_cycle()  # what the EEPROM holds survives
    assert drive.read("max_motor_speed").raw == 3000


def test_what_only_canopen_does_is_refused(drive: Drive, engine: PkwEngine) -> None:
    with pytest.raises(NoCanFrames, match=r"a block upload .* needs a CANopen bus"):
        engine.upload_block(ADDRESS, 774, 0)
    with pytest.raises(NoCanFrames, match="the SYNC needs a CANopen bus"):
        engine.link.send(0x080, b"")
    assert not drive.profile.canopen


def test_a_node_no_dp_slave_can_have_is_refused_before_sending(engine: PkwEngine) -> None:
    drive = Drive(engine, 126, builtin_parameter_list(), profile_for("ttapro"))
    with pytest.raises(StationOutOfRange, match=r"^DP station address 126 outside 1\.\.125: nothing was sent$"):
        drive.read("PNU700")
