"""The PKW engine (docs/profibus.md §9): a `Drive` on the TTA-PRO parameter list reads and writes PNUs of the
simulated slave over its TCP stream exactly as it does CANopen objects — width and sign from the list, IND as the
subindex, a procedure waited for, a negative reply as a readable error naming the PNU, a value out of range refused
before anything is sent, what only CANopen does refused, and a procedure cut by a lost exchange run again only when
the parameter list says it may be."""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Iterator
from contextlib import contextmanager

import pytest
from tests.support.profibus_line import TtaProLine, ttapro_line

from servostudio.drive.access import Drive, DriveAccessError
from servostudio.drive.profibus.engine import PkwEngine, PkwRefusal, StationOutOfRange
from servostudio.drive.profibus.link import NoCanFrames, ProfibusLink
from servostudio.drive.profiles import profile_for
from servostudio.drive.sdo import SdoAbortError
from servostudio.errors import ErrorKind, ServoStudioError
from servostudio.od.pnu import builtin_parameter_list
from servostudio.od.pnu_model import ParameterDictionary
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


# -- a station that leaves data exchange while a procedure runs ------------------------------------------------


def _drop_while_the_first_procedure_runs(line: TtaProLine) -> list[int]:
    """Make the slave leave data exchange (its DP watchdog expired) 30 ms after it starts its first procedure; the
    PNUs of the procedures it starts, in order."""
    slave = line.slaves[ADDRESS]
    started: list[int] = []
    start = slave.procedures.start

    def drop() -> None:
        with line.line.lock:
            slave.station._leave_data_exchange()

    def counting_start(pnu: int, value: int) -> None:
        start(pnu, value)
        started.append(pnu)
        if len(started) == 1:
            threading.Timer(0.03, drop).start()

    slave.procedures.start = counting_start  # type: ignore[method-assign]
    return started


@contextmanager
def _drive_on(line: TtaProLine, parameters: ParameterDictionary) -> Iterator[Drive]:
    link = ProfibusLink("pb", DpMaster(ByteLink(line.spec.replace("profibus:tcp:", "socket://"))))
    link.start()
    try:
        yield Drive(PkwEngine(link, lambda node: parameters), ADDRESS, parameters, profile_for("ttapro"))
    finally:
        link.close()


def test_a_save_cut_by_a_lost_exchange_is_run_again_once_the_station_is_back() -> None:
    """729 is `Repeatable` in the list: saving twice leaves the EEPROM as saving once."""
    with ttapro_line(ADDRESS) as line, _drive_on(line, builtin_parameter_list()) as drive:
        started = _drop_while_the_first_procedure_runs(line)
        drive.write("max_motor_speed", 3100)
        drive.start_procedure("save")
        assert started == [729, 729]
        line.slaves[ADDRESS].power_cycle()
        assert drive.read("max_motor_speed").raw == 3100


def test_a_procedure_not_marked_repeatable_is_never_run_twice() -> None:
    """The same save, from a list that does not call it repeatable (as auto-phasing is not: it moves the motor)."""
    parameters = builtin_parameter_list()
    parameters.parameters[729] = dataclasses.replace(parameters.parameters[729], repeatable=False)
    with ttapro_line(ADDRESS) as line, _drive_on(line, parameters) as drive:
        started = _drop_while_the_first_procedure_runs(line)
        with pytest.raises(ServoStudioError, match=r"PNU 729: DP station 5 refused Data_Exchange") as lost:
            drive.start_procedure("save")
        assert lost.value.kind is ErrorKind.UNAVAILABLE and started == [729]
