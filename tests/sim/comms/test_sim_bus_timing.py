"""Bit-rate model: frame length with bit stuffing, arbitration by identifier, response time on the virtual clock."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.sim.bus import VirtualBus
from servostudio.sim.clock import VirtualClock
from servostudio.sim.frame import Frame
from servostudio.sim.timing import count_stuff_bits, crc15, frame_bits, stuffed_section


class Recorder:
    def __init__(self) -> None:
        self.frames: list[tuple[float, Frame]] = []

    def receive(self, frame: Frame, timestamp: float) -> None:
        self.frames.append((timestamp, frame))


def test_stuff_bits_follow_runs_of_five():
    assert count_stuff_bits([0] * 5) == 1
    assert count_stuff_bits([0] * 4 + [1] * 4) == 0
    # the stuff bit (1) after five 0s starts a run: 1 + four more 1s make five -> a second stuff bit
    assert count_stuff_bits([0] * 5 + [1] * 4) == 2


def test_crc15_of_the_iso_check_value():
    bits = [int(b) for byte in b"123456789" for b in f"{byte:08b}"]
    assert crc15(bits) == 0x059E  # CRC-15/CAN check value


@given(
    st.integers(0, 0x7FF),
    st.binary(max_size=8),
)
def test_frame_length_lies_between_the_unstuffed_and_worst_case_lengths(can_id, data):
    frame = Frame(can_id, data)
    unstuffed = 47 + 8 * len(data)
    worst = unstuffed + (34 + 8 * len(data) - 1) // 4
    assert unstuffed <= frame_bits(frame) <= worst
    assert len(stuffed_section(frame)) == 34 + 8 * len(data)


def test_bit_rate_delays_delivery_and_lower_identifier_wins_arbitration():
    clock = VirtualClock()
    bus = VirtualBus(clock, bitrate=125_000)
    recorder = Recorder()
    bus.attach(recorder)
    high, low = Frame(0x600, bytes(8)), Frame(0x080)
    bus.transmit(high)
    bus.transmit(low)
    clock.run_until(1.0)
    assert [frame for _, frame in recorder.frames] == [low, high]
    first_done = frame_bits(low) / 125_000
    assert recorder.frames[0][0] == pytest.approx(first_done)
    assert recorder.frames[1][0] == pytest.approx(first_done + frame_bits(high) / 125_000)


def test_a_station_s_own_frames_leave_in_its_order_and_others_still_arbitrate():
    """A client's RPDO queued before its SYNC is not overtaken by it (a transmit FIFO); another station's frame
    with a lower identifier still wins the round it takes part in."""
    clock = VirtualClock()
    bus = VirtualBus(clock, bitrate=125_000)
    client, other, recorder = Recorder(), Recorder(), Recorder()
    bus.attach(recorder)
    rpdo, sync, emcy = Frame(0x201, bytes(8)), Frame(0x080), Frame(0x081, bytes(8))
    bus.transmit(rpdo, client)  # all three queued at one instant: one round
    bus.transmit(sync, client)
    bus.transmit(emcy, other)
    clock.run_until(1.0)
    assert [frame for _, frame in recorder.frames] == [emcy, rpdo, sync]


def test_data_frame_beats_remote_frame_with_the_same_identifier():
    clock = VirtualClock()
    bus = VirtualBus(clock, bitrate=None)
    recorder = Recorder()
    bus.attach(recorder)
    bus.transmit(Frame.remote(0x181, 2))
    bus.transmit(Frame(0x181, b"\x01\x02"))
    clock.run_until(0.0)
    assert [frame.rtr for _, frame in recorder.frames] == [False, True]


def test_sender_does_not_receive_its_own_frame():
    clock = VirtualClock()
    bus = VirtualBus(clock)
    sender, other = Recorder(), Recorder()
    bus.attach(sender)
    bus.attach(other)
    bus.transmit(Frame(0x123, b"x"), sender=sender)
    clock.run_until(0.01)
    assert sender.frames == [] and len(other.frames) == 1


def test_sdo_response_arrives_after_request_time_plus_response_time_plus_response_time_on_wire(
    make_network, raw_client
):
    network = make_network("1", bitrate=500_000, sdo_response_time=2e-3)
    network.advance(0.01)
    client = raw_client(network)
    start = network.now
    request = bytes([0x40, 0x18, 0x10, 1, 0, 0, 0, 0])
    client.send(0x601, request)
    [response] = [m for m in client.collect(0.02) if m.arbitration_id == 0x581]
    expected = (
        start
        + frame_bits(Frame(0x601, request)) / 500_000
        + 2e-3
        + frame_bits(Frame(0x581, bytes(response.data))) / 500_000
    )
    assert response.timestamp == pytest.approx(expected, abs=1e-9)
