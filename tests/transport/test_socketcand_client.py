"""The socketcand client: frames parsed from the server's text however TCP cuts it, other messages skipped."""

from __future__ import annotations

import socket
import threading

import can
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from servostudio.sim.frame import Frame
from servostudio.sim.socketcand import format_frame
from servostudio.transport.socketcand import SocketcandBus, _parse_frames

frames = st.builds(
    lambda extended, can_id, data, stamp: (
        Frame(can_id & (0x1FFFFFFF if extended else 0x7FF), data, extended=extended),
        stamp,
    ),
    st.booleans(),
    st.integers(0, 0x1FFFFFFF),
    st.binary(max_size=8),
    st.integers(0, 10**9).map(lambda us: us / 1e6),
)
noise = st.sampled_from(
    [
        "< ok >",
        "< echo >",
        "< error could not send >",
        "< frame 12G 1.0 00 >",
        "< frame 123 1.0 ABC >",
        "< frame 123 1.0 000102030405060708 >",
        "garbage",
    ]
)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.one_of(frames, noise), max_size=20))
def test_every_frame_is_parsed_and_everything_else_skipped(items):
    text = "".join(format_frame(*item) if isinstance(item, tuple) else item for item in items)
    expected = [
        (frame.can_id, frame.data, round(stamp, 6), frame.extended)
        for frame, stamp in (item for item in items if isinstance(item, tuple))
    ]
    parsed = [
        (identifier, data, round(stamp, 6), extended)
        for identifier, data, stamp, extended in _parse_frames(text.encode())
    ]
    assert parsed == expected


class TinyServer:
    """A socketcand server that greets, accepts the channel and raw mode, then sends the given chunks."""

    def __init__(self, chunks: list[bytes]) -> None:
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.chunks = chunks
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    @property
    def port(self) -> int:
        return self.listener.getsockname()[1]

    def _serve(self) -> None:
        connection, _ = self.listener.accept()
        connection.sendall(b"< hi >")
        for answer in (b"< ok >", b"< ok >"):
            connection.recv(100)
            connection.sendall(answer)
        for chunk in self.chunks:
            connection.sendall(chunk)
            threading.Event().wait(0.02)
        connection.close()


def test_frames_cut_anywhere_by_tcp_arrive_whole_and_a_closed_server_is_reported():
    text = b"".join(format_frame(Frame(0x580 + node, bytes([node] * node)), node / 10).encode() for node in range(1, 8))
    chunks = [text[start : start + 7] for start in range(0, len(text), 7)]  # cut inside every message
    server = TinyServer(chunks)
    bus = SocketcandBus(channel="can0", host="127.0.0.1", port=server.port)
    received = []
    try:
        with pytest.raises(can.CanOperationError, match="closed by the server"):
            while True:
                received += bus.receive_frames(1.0)
    finally:
        bus.shutdown()
    assert [(cob_id, data) for cob_id, data, _, _ in received] == [(0x580 + n, bytes([n] * n)) for n in range(1, 8)]


def test_python_can_recv_gives_messages():
    server = TinyServer([format_frame(Frame(0x181, b"\x01\x02"), 2.5).encode()])
    bus = SocketcandBus(channel="can0", host="127.0.0.1", port=server.port)
    try:
        message = bus.recv(2.0)
    finally:
        bus.shutdown()
    assert (message.arbitration_id, bytes(message.data), message.timestamp) == (0x181, b"\x01\x02", 2.5)
