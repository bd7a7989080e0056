"""The oscilloscope recorder of the simulated XtrapulsPac (0x5800–0x5841; docs/eds.md §6, docs/scope.md), used the
way the tool will use it: SDO from an independent canopen peer over socketcand, the buffer decoded by the peer.
Every recording is compared with the probe, the simulator's own values read after each control period."""

from __future__ import annotations

import gc
import itertools
import time

import can
import canopen
import pytest
from canopen.sdo.exceptions import SdoAbortedError
from tests.support.recorder_peer import (
    ARM,
    AUTO,
    CURRENT,
    DONE,
    EDGE,
    EITHER,
    FALLING,
    FILLING,
    FORCE,
    IDLE,
    IMMEDIATE,
    NORMAL,
    POSITION,
    RECORDER_STATUS,
    RECORDING,
    RECORDING_COUNTER,
    REV,
    RISING,
    SINGLE,
    STATUS_WORD,
    STOP,
    TARGET_VELOCITY,
    VELOCITY,
    WAITING,
    Probe,
    Row,
    ScopeBus,
    ScopePeer,
    last_write,
    pointer,
    sample_grid,
    scope_bus,
)

from servostudio.od.datatypes import DataType
from servostudio.sim import sdo_abort

I16, I32, U16 = DataType.INTEGER16, DataType.INTEGER32, DataType.UNSIGNED16
POSITION_DEMAND, FOLLOWING_ERROR = (0x6062, 0), (0x60F4, 0)
CONTROL = (0x5828, 0)
DEFAULT_KEYS = [POSITION, VELOCITY, CURRENT, STATUS_WORD]
DEFAULT_CHANNELS = [pointer(POSITION, I32), pointer(VELOCITY, I32), pointer(CURRENT, I16), pointer(STATUS_WORD, U16)]
PROBED = [*DEFAULT_KEYS, TARGET_VELOCITY, POSITION_DEMAND, FOLLOWING_ERROR, RECORDER_STATUS, RECORDING_COUNTER]
TARGET_CHANNELS = [pointer(TARGET_VELOCITY, I32), pointer(POSITION, I32)]
TARGET_KEYS = [TARGET_VELOCITY, POSITION]
NEVER = 2**31 - 1  # a trigger level the position never crosses upwards


@pytest.fixture
def bus():
    with scope_bus() as bus:
        yield bus


@pytest.fixture
def scope(bus: ScopeBus) -> tuple[ScopePeer, Probe]:
    probe = bus.probe(PROBED)
    probe.watch(CONTROL)
    probe.watch(TARGET_VELOCITY)
    return bus.peer(), probe


def aborted(action) -> int:
    """The abort code an SDO action ends with."""
    with pytest.raises(SdoAbortedError) as raised:
        action()
    code = raised.value.code
    del raised
    gc.collect()  # canopen's half-built stream sends its request here, not on the simulator's thread
    return code


def enable_profile_velocity(peer: ScopePeer) -> None:
    for index, value in ((0x6060, 3), (0x6083, 100 * REV), (0x6084, 100 * REV), (0x60FF, 0)):
        peer.write(index, 0, value)
    for control_word in (0x06, 0x07, 0x0F):
        peer.write(0x6040, 0, control_word)
    peer.wait(lambda: peer.read(0x6041) & 0x6F == 0x27, "operation enabled")


def statuses(probe: Probe, rows: list[Row]) -> list[int]:
    """The recorder status of each period, repeats collapsed."""
    return [status for status, _ in itertools.groupby(probe.column(RECORDER_STATUS, rows))]


def expected_records(probe: Probe, grid: list[Row], trigger: int, pre_trigger: int, depth: int, keys) -> list[tuple]:
    """The probe's values at the records of a recording whose trigger is sample `trigger` of the grid."""
    return probe.values(grid[trigger - pre_trigger : trigger - pre_trigger + depth], keys)


def first_sample_after(grid: list[Row], instant: float) -> int:
    return next(number for number, row in enumerate(grid) if row.time > instant)


# -- the speed step (issue #12, "done when") ---------------------------------------------------------------------


@pytest.mark.parametrize("multiplier", [1, 4])
def test_speed_step_recording_has_the_pre_trigger_period_and_values_of_the_simulator(bus, scope, multiplier):
    peer, probe = scope
    depth, pre_trigger, level = 400, 80, 5 * REV  # pre-trigger 20 %; trigger: 0x606C rising through 5 rev/s
    enable_profile_velocity(peer)
    peer.configure(DEFAULT_CHANNELS, depth, multiplier, pre_trigger, EDGE, source=2, level=level, edge=RISING)
    peer.command(ARM)
    peer.wait_status(WAITING)
    peer.write(0x60FF, 0, 20 * REV)
    peer.wait_status(DONE)
    recording = peer.recording()

    grid = sample_grid(bus.rows(probe), last_write(probe, CONTROL, ARM), multiplier)
    velocity = probe.column(VELOCITY, grid)
    fired = next(k for k in range(pre_trigger, len(grid)) if velocity[k - 1] < level <= velocity[k])
    assert recording.trigger == pre_trigger
    assert len(recording.records) == depth and len(recording.raw) == depth * 12
    assert recording.records == expected_records(probe, grid, fired, pre_trigger, depth, DEFAULT_KEYS)
    instants = grid[fired - pre_trigger : fired - pre_trigger + depth]
    assert {later.period - earlier.period for earlier, later in itertools.pairwise(instants)} == {multiplier}
    assert instants[pre_trigger].time > last_write(probe, TARGET_VELOCITY)  # time 0 is the step's crossing
    trigger_record = recording.records[pre_trigger]
    assert recording.records[pre_trigger - 1][1] < level <= trigger_record[1]


# -- trigger kinds ------------------------------------------------------------------------------------------------


def test_immediate_mode_records_from_the_arm_with_four_32_bit_channels_at_full_depth(bus, scope):
    peer, probe = scope
    keys = [POSITION, VELOCITY, POSITION_DEMAND, FOLLOWING_ERROR]
    enable_profile_velocity(peer)
    peer.write(0x60FF, 0, 10 * REV)
    peer.configure([pointer(key, I32) for key in keys], depth=2048, mode=IMMEDIATE)
    assert peer.read(0x5804, 5) == 16 and peer.read(0x5804, 1) == 32768
    peer.command(ARM)
    peer.wait_status(DONE)
    recording = peer.recording()

    grid = sample_grid(bus.rows(probe), last_write(probe, CONTROL, ARM), 1)
    assert recording.trigger == 0 and peer.read(0x5840, 4) == 2048 and len(recording.raw) == 32768
    assert recording.records == probe.values(grid[:2048], keys)


def test_depth_beyond_the_buffer_is_refused_and_fewer_channels_allow_more(scope):
    peer, _ = scope
    peer.configure([pointer(POSITION, I32)] * 4, depth=2049)
    assert aborted(lambda: peer.command(ARM)) == sdo_abort.CANNOT_TRANSFER
    assert peer.status() == IDLE
    assert aborted(lambda: peer.write(0x5804, 2, 40000)) == sdo_abort.VALUE_TOO_HIGH
    peer.configure([pointer(STATUS_WORD, U16)], depth=16384)
    peer.command(ARM)
    assert peer.status() == RECORDING
    peer.command(STOP)
    assert peer.status() == IDLE


@pytest.mark.parametrize(
    ("edge", "start", "writes"),
    [
        (RISING, REV, [0, REV]),  # the falling crossing is ignored
        (FALLING, 0, [REV, 0]),  # the rising crossing is ignored
        (EITHER, 0, [REV]),
        (EITHER, REV, [0]),
    ],
)
def test_edges_on_an_object_that_is_not_a_channel(bus, scope, edge, start, writes):
    peer, probe = scope
    depth, pre_trigger = 40, 10
    peer.write(0x60FF, 0, start)
    peer.configure(
        TARGET_CHANNELS, depth, pre_trigger=pre_trigger, mode=EDGE,
        source=pointer(TARGET_VELOCITY, I32), level=REV // 2, edge=edge,
    )  # fmt: skip
    peer.command(ARM)
    peer.wait_status(WAITING)
    for ignored in writes[:-1]:
        peer.write(0x60FF, 0, ignored)
        time.sleep(0.05)
        assert peer.status() == WAITING
    peer.write(0x60FF, 0, writes[-1])
    peer.wait_status(DONE)
    recording = peer.recording()

    grid = sample_grid(bus.rows(probe), last_write(probe, CONTROL, ARM), 1)
    fired = first_sample_after(grid, last_write(probe, TARGET_VELOCITY))
    assert recording.trigger == pre_trigger
    assert recording.records == expected_records(probe, grid, fired, pre_trigger, depth, TARGET_KEYS)
    assert [record[0] for record in recording.records[pre_trigger - 1 : pre_trigger + 1]] == [start, *writes][-2:]


def test_forced_trigger_while_waiting(bus, scope):
    peer, probe = scope
    enable_profile_velocity(peer)
    peer.write(0x60FF, 0, 10 * REV)  # the position changes every period: the values pin the instants down
    peer.configure(TARGET_CHANNELS, depth=40, pre_trigger=10, mode=EDGE, source=2, level=NEVER)
    peer.command(ARM)
    peer.wait_status(WAITING)
    peer.command(FORCE)
    peer.wait_status(DONE)
    recording = peer.recording()

    grid = sample_grid(bus.rows(probe), last_write(probe, CONTROL, ARM), 1)
    fired = first_sample_after(grid, last_write(probe, CONTROL, FORCE))
    assert recording.trigger == 10
    assert recording.records == expected_records(probe, grid, fired, 10, 40, TARGET_KEYS)


def test_forced_trigger_while_filling_keeps_fewer_pre_trigger_records(bus, scope):
    peer, probe = scope
    depth, multiplier = 120, 40  # 10 ms per record: the 100 pre-trigger records take 1 s
    enable_profile_velocity(peer)
    peer.write(0x60FF, 0, 10 * REV)
    peer.configure(TARGET_CHANNELS, depth, multiplier, pre_trigger=100, mode=EDGE, source=2, level=NEVER)
    peer.command(ARM)
    time.sleep(0.2)
    assert peer.status() == FILLING
    peer.command(FORCE)
    peer.wait_status(DONE)
    recording = peer.recording()

    grid = sample_grid(bus.rows(probe), last_write(probe, CONTROL, ARM), multiplier)
    fired = first_sample_after(grid, last_write(probe, CONTROL, FORCE))
    assert 0 < recording.trigger == fired < 100
    assert len(recording.records) == depth
    assert recording.records == probe.values(grid[:depth], TARGET_KEYS)


# -- modes and status ---------------------------------------------------------------------------------------------


def test_single_shot_status_sequence_then_stays_done(bus, scope):
    peer, probe = scope
    peer.configure(
        TARGET_CHANNELS, depth=20, pre_trigger=5, mode=EDGE, source=1, level=REV // 2, edge=EITHER, rearm=SINGLE
    )
    peer.command(ARM)
    peer.wait_status(WAITING)
    peer.write(0x60FF, 0, REV)
    peer.wait_status(DONE)
    assert peer.read(0x5804, 6) == 1
    peer.write(0x60FF, 0, 0)
    time.sleep(0.05)
    assert peer.status() == DONE and peer.read(0x5804, 6) == 1
    assert statuses(probe, bus.rows(probe)) == [IDLE, FILLING, WAITING, RECORDING, DONE]


def test_normal_mode_rearms_and_records_only_on_a_trigger(bus, scope):
    peer, probe = scope
    peer.configure(TARGET_CHANNELS, depth=20, pre_trigger=4, mode=EDGE, source=1, level=REV // 2, rearm=NORMAL)
    peer.command(ARM)
    for count in (1, 2):
        peer.wait_status(WAITING)
        peer.write(0x60FF, 0, REV)
        peer.wait(lambda count=count: peer.read(0x5804, 6) == count, f"recording {count}")
        peer.write(0x60FF, 0, 0)
        peer.wait_status(WAITING)  # re-armed
        time.sleep(0.05)
        assert peer.read(0x5804, 6) == count and peer.status() == WAITING  # no trigger, no recording
    last_recording = peer.recording()
    peer.command(STOP)
    assert peer.status() == IDLE and peer.recording() == last_recording and last_recording.trigger == 4
    assert statuses(probe, bus.rows(probe)) == [IDLE, *[FILLING, WAITING, RECORDING] * 2, FILLING, WAITING, IDLE]


def test_auto_mode_forces_a_recording_after_the_timeout(bus, scope):
    peer, probe = scope
    multiplier, timeout_ms = 2, 5  # 5 ms = 20 control periods = 10 records
    peer.configure(
        TARGET_CHANNELS, depth=24, multiplier=multiplier, pre_trigger=8, mode=EDGE, source=2, level=NEVER,
        rearm=AUTO, timeout_ms=timeout_ms,
    )  # fmt: skip
    peer.command(ARM)
    peer.wait(lambda: peer.read(0x5804, 6) >= 3, "three recordings")
    peer.command(STOP)
    rows = bus.rows(probe)
    spans = [len(list(group)) for status, group in itertools.groupby(probe.column(RECORDER_STATUS, rows))]
    waiting = [span for status, span in zip(statuses(probe, rows), spans, strict=True) if status == WAITING]
    assert waiting[:3] == [timeout_ms * 4] * 3
    assert peer.read(0x5840, 3) == 8


def test_normal_mode_in_immediate_mode_records_back_to_back(bus, scope):
    peer, probe = scope
    peer.configure(TARGET_CHANNELS, depth=10, mode=IMMEDIATE, rearm=NORMAL)
    peer.command(ARM)
    peer.wait(lambda: peer.read(0x5804, 6) >= 5, "five recordings")
    peer.command(STOP)
    counters = probe.column(RECORDING_COUNTER, bus.rows(probe))
    changes = [number for number, (a, b) in enumerate(itertools.pairwise(counters)) if a != b]
    assert {later - earlier for earlier, later in itertools.pairwise(changes)} == {10}


# -- configuration rules ------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("source", "code"),
    [
        (0x10000020, sdo_abort.CANNOT_BE_MAPPED),  # device type: not PDO-mappable
        (0x60640010, sdo_abort.CANNOT_BE_MAPPED),  # 0x6064 is 32 bits, not 16
        (0x2FFF0020, sdo_abort.OBJECT_DOES_NOT_EXIST),
        (0x60640520, sdo_abort.SUBINDEX_DOES_NOT_EXIST),
    ],
)
def test_a_source_the_recorder_cannot_sample_is_refused(scope, source, code):
    peer, _ = scope
    assert aborted(lambda: peer.write(0x5811, 1, source)) == code
    assert aborted(lambda: peer.write(0x5820, 1, source)) == code
    assert peer.read(0x5811, 1) == DEFAULT_CHANNELS[0]


def test_channel_types_and_record_size_follow_the_sources(scope):
    peer, _ = scope
    peer.write(0x5811, 2, 0)
    peer.write(0x5811, 3, pointer(TARGET_VELOCITY, I32))
    assert [peer.read(0x5810, n) for n in (1, 2, 3, 4)] == [I32, 0, I32, U16]
    assert peer.read(0x5804, 5) == 10


def test_arm_is_refused_when_the_recording_is_impossible(scope):
    peer, _ = scope
    peer.configure([], depth=10)
    assert aborted(lambda: peer.command(ARM)) == sdo_abort.CANNOT_TRANSFER  # no channel on
    peer.configure([pointer(POSITION, I32)], depth=10, mode=EDGE, source=2)
    assert aborted(lambda: peer.command(ARM)) == sdo_abort.CANNOT_TRANSFER  # trigger on an off channel
    peer.configure([pointer(POSITION, I32)], depth=10, pre_trigger=10, mode=EDGE)
    assert aborted(lambda: peer.command(ARM)) == sdo_abort.CANNOT_TRANSFER  # no room for the trigger record
    assert peer.status() == IDLE


def test_configuration_is_refused_while_armed(scope):
    peer, _ = scope
    peer.configure(TARGET_CHANNELS, depth=20, pre_trigger=2, mode=EDGE, source=2, level=NEVER)
    peer.command(ARM)
    for index, sub, value in ((0x5804, 2, 30), (0x5811, 1, 0), (0x5805, 0, 3), (0x5820, 3, 1), (0x5822, 1, 7)):
        assert aborted(lambda index=index, sub=sub, value=value: peer.write(index, sub, value)) == (
            sdo_abort.CANNOT_TRANSFER_STATE
        )
    peer.write(0x5812, 1, "rev/s")
    peer.write(0x5840, 1, 3)
    assert peer.status() == WAITING
    peer.command(STOP)
    peer.write(0x5804, 2, 30)
    assert peer.read(0x5804, 2) == 30 and peer.node.sdo[0x5812][1].raw == "rev/s"


# -- reading the buffer -------------------------------------------------------------------------------------------


def record_a_few(peer: ScopePeer, depth: int = 30) -> None:
    peer.configure(TARGET_CHANNELS, depth=depth, mode=IMMEDIATE)
    peer.command(ARM)
    peer.wait_status(DONE)


def test_block_and_segmented_uploads_and_partial_transfer_give_the_same_bytes(scope):
    peer, _ = scope
    record_a_few(peer)
    block = peer.upload(0x5801, block=True)
    assert len(block) == 30 * 8
    assert peer.upload(0x5801, block=False) == block
    assert peer.upload(0x5841, block=True) == block  # first 0, count 0: the whole recording
    peer.write(0x5840, 1, 5)
    peer.write(0x5840, 2, 7)
    assert peer.upload(0x5841, block=False) == block[5 * 8 : 12 * 8]
    peer.write(0x5840, 2, 0)
    assert peer.upload(0x5841, block=True) == block[5 * 8 :]
    peer.write(0x5840, 1, 28)
    peer.write(0x5840, 2, 10)
    assert peer.upload(0x5841, block=True) == block[28 * 8 :]  # clipped to the records available


def redirected_exchange(raw: can.BusABC, request: bytes) -> bytes:
    """One request on node 1's redirected SDO channel (0x641 → 0x5C1, which the canopen peer does not use); the
    first response."""
    raw.send(can.Message(arbitration_id=0x641, data=request, is_extended_id=False))
    for message in iter(lambda: raw.recv(5.0), None):
        if message.arbitration_id == 0x5C1:
            return bytes(message.data)
    raise AssertionError("no response on the redirected SDO channel")


def test_a_link_cut_during_an_upload_leaves_the_recorder_clean(bus, scope):
    peer, _ = scope
    record_a_few(peer, depth=400)
    before = peer.upload()
    raw = can.Bus(interface="socketcand", host=bus.host, port=bus.port, channel="can0")
    time.sleep(0.2)  # python-can's socketcand sends frames only after its raw-mode handshake
    assert redirected_exchange(raw, bytes([0xA4, 0x01, 0x58, 0, 127, 0, 0, 0]))[0] == 0xC6  # block upload of 0x5801
    assert redirected_exchange(raw, bytes([0xA3, 0, 0, 0, 0, 0, 0, 0]))[0] == 0x01  # first segment of the block
    raw.shutdown()  # the link is cut in the middle of the first block

    assert peer.status() == DONE and peer.upload() == before
    redirected = canopen.sdo.SdoClient(0x641, 0x5C1, peer.node.object_dictionary)
    redirected.network = bus.client
    bus.client.subscribe(0x5C1, redirected.on_response)
    with redirected.open(0x5801, 0, "rb", block_transfer=True) as stream:
        assert stream.read() == before  # the interrupted channel serves a new upload
    peer.write(0x60FF, 0, 123)
    peer.command(ARM)
    peer.wait_status(DONE)
    assert peer.read(0x5804, 6) == 2 and peer.upload() != before


def test_a_warm_reset_leaves_the_recorder_idle_and_empty(bus, scope):
    peer, _ = scope
    record_a_few(peer)
    peer.write(0x205D, 0, 2)  # reset node = warm reset
    peer.node.nmt.state = "RESET"
    time.sleep(0.1)
    assert peer.status() == IDLE and peer.read(0x5840, 4) == 0 and peer.read(0x5804, 6) == 0
    record_a_few(peer)
    assert peer.read(0x5804, 6) == 1


# -- several drives -----------------------------------------------------------------------------------------------


def test_one_rpdo_arms_two_drives_in_the_same_control_period():
    with scope_bus("1,2") as bus:
        peers = [bus.peer(node_id) for node_id in (1, 2)]
        probes = [bus.probe([POSITION, STATUS_WORD, RECORDER_STATUS], node_id) for node_id in (1, 2)]
        for peer in peers:
            map_arm_rpdo(peer, cob_id=0x300)
            peer.configure([pointer(POSITION, I32), pointer(STATUS_WORD, U16)], depth=50, mode=IMMEDIATE)
        bus.client.nmt.send_command(0x01)  # start all nodes
        time.sleep(0.05)
        bus.client.send_message(0x300, bytes([ARM]))
        for peer in peers:
            peer.wait_status(DONE)
        starts = []
        for peer, probe in zip(peers, probes, strict=True):
            rows = bus.rows(probe)
            started = next(row for row in rows if row.values[2] != IDLE)
            grid = [row for row in rows if row.time >= started.time][:50]
            assert peer.recording().records == probe.values(grid, [POSITION, STATUS_WORD])
            starts.append(started.period)
        assert starts[0] == starts[1]


def map_arm_rpdo(peer: ScopePeer, cob_id: int) -> None:
    """RPDO 4 carries 0x5828 on `cob_id`, applied on reception (the same frame reaches every drive at once)."""
    peer.write(0x1403, 1, 0x80000000 | cob_id)
    peer.write(0x1603, 0, 0)
    peer.write(0x1603, 1, 0x58280008)
    peer.write(0x1603, 0, 1)
    peer.write(0x1403, 2, 255)
    peer.write(0x1403, 1, cob_id)
