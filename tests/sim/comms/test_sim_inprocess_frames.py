"""The in-process adapter's fast path: plain frames in, every queued data frame out at once."""

from __future__ import annotations

import can


def test_frames_sent_plainly_are_answered_and_received_together(make_network):
    network = make_network("1,2")
    bus = network.open_bus()
    other = network.open_bus()
    try:
        network.advance(0.01)  # boot-up messages
        bus.receive_frames(0)
        for node in (1, 2):
            bus.send_frame(0x600 + node, bytes([0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]))  # read 0x1000
        other.send(can.Message(arbitration_id=0x181, is_remote_frame=True, is_extended_id=False, dlc=0))
        network.advance(0.01)
        frames = bus.receive_frames(0)
    finally:
        bus.shutdown()
        other.shutdown()
    answers = [(cob_id, data[:4]) for cob_id, data, _, extended in frames if not extended]
    assert answers == [(0x581, bytes([0x43, 0x00, 0x10, 0x00])), (0x582, bytes([0x43, 0x00, 0x10, 0x00]))]
    assert all(timestamp > 0.01 for _, _, timestamp, _ in frames)
    assert bus.receive_frames(0) == []
