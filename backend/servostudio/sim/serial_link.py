"""The XtrapulsPac RS-232 link (decisions.md §1), plugged into one simulated drive.

The gateway drive serves its own SDO channels (0x600+n and 0x640+n) locally, forwards every host frame with COB-ID
0x641–0x67F onto the CAN bus and relays CAN frames 0x5C1–0x5FF (other drives' redirected SDO responses) back to the
line. Other host frames are dropped, as the drive does. Frames use the 12-byte codec of
`servostudio.transport.rs232_framing` ('M' host → drive, 'S' drive → host); corrupted bytes are dropped by the
decoder, which resynchronises on the next valid frame.

With `response_id_quirk` the drive reproduces the firmware quirk: SDO responses go to the line with the request
identifier (0x580+n → 0x600+n, 0x5C0+n → 0x640+n).

Two endpoints carry the byte stream: a raw TCP server (pyserial `socket://HOST:PORT`) and a pseudo-terminal
(`os.openpty`, raw mode). The line's baud rate is not modelled: bytes flow as fast as the endpoint takes them.
"""

from __future__ import annotations

import os
import select
import socket
import threading
import tty

from servostudio.sim.frame import Frame
from servostudio.sim.network import SimulatedNetwork
from servostudio.sim.node import REDIRECTED_REQUEST_BASE, REDIRECTED_RESPONSE_BASE, SimulatedNode
from servostudio.sim.tcp import QueuedWriter, StreamListener
from servostudio.transport.rs232_framing import DRIVE_HEADER, HOST_HEADER, FrameDecoder, encode_frame

FORWARDED = range(REDIRECTED_REQUEST_BASE + 1, REDIRECTED_REQUEST_BASE + 64)  # 0x641–0x67F
RELAYED = range(REDIRECTED_RESPONSE_BASE + 1, REDIRECTED_RESPONSE_BASE + 64)  # 0x5C1–0x5FF
SDO_RESPONSES = range(0x581, 0x600)
QUIRK_OFFSET = 0x80  # response identifier -> request identifier


class SerialGateway:
    """Drive side of the serial line; a station on the CAN bus for the relayed responses."""

    def __init__(
        self, network: SimulatedNetwork, node: SimulatedNode | None = None, response_id_quirk: bool = False
    ) -> None:
        self.network = network
        self.node = node or network.first_node
        self.response_id_quirk = response_id_quirk
        self._writers: list[QueuedWriter] = []
        network.attach(self)

    def close(self) -> None:
        self.network.detach(self)

    # -- line side ------------------------------------------------------------------------------------------------

    def add_writer(self, writer: QueuedWriter) -> None:
        self._writers.append(writer)

    def remove_writer(self, writer: QueuedWriter) -> None:
        if writer in self._writers:
            self._writers.remove(writer)

    def host_frames(self, frames: list[tuple[int, bytes]]) -> None:
        """Frames decoded from the host's bytes (called from an endpoint thread; they enter the simulation like a
        client's CAN frames, between two chunks of simulated time)."""
        self.network.post(lambda: self._host_frames(frames))

    def _host_frames(self, frames: list[tuple[int, bytes]]) -> None:
        for cob_id, data in frames:
            frame = Frame(cob_id, data)
            if self.node.handle_local(frame, self._to_host):
                continue
            if cob_id in FORWARDED:
                self.network.bus.transmit(frame, sender=self)

    def _to_host(self, frame: Frame) -> None:
        cob_id = frame.can_id
        if self.response_id_quirk and cob_id in SDO_RESPONSES:
            cob_id += QUIRK_OFFSET
        data = encode_frame(DRIVE_HEADER, cob_id, frame.data)
        for writer in list(self._writers):
            writer.put(data)

    # -- bus side -------------------------------------------------------------------------------------------------

    def receive(self, frame: Frame, timestamp: float) -> None:
        own_response = REDIRECTED_RESPONSE_BASE + self.node.node_id
        if frame.can_id in RELAYED and frame.can_id != own_response and not frame.rtr and not frame.extended:
            self._to_host(frame)


class SerialTcpServer(StreamListener):
    """The line as a raw TCP byte stream (pyserial `socket://HOST:PORT`); every connection sees the drive's output."""

    name = "serial-tcp"

    def __init__(self, gateway: SerialGateway, host: str = "127.0.0.1", port: int = 0) -> None:
        super().__init__(host, port)
        self.gateway = gateway

    def _serve(self, connection: socket.socket) -> None:
        writer = QueuedWriter(connection.sendall, "serial-tcp-tx")
        self.gateway.add_writer(writer)
        decoder = FrameDecoder(HOST_HEADER)
        try:
            while chunk := connection.recv(4096):
                self.gateway.host_frames(decoder.feed(chunk))
        finally:
            self.gateway.remove_writer(writer)
            writer.close()


class SerialPty:
    """The line as a pseudo-terminal in raw mode; open `path` with pyserial like a real serial port."""

    def __init__(self, gateway: SerialGateway) -> None:
        self.gateway = gateway
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)
        self.path = os.ttyname(self._slave)
        self._stop = threading.Event()
        self._writer = QueuedWriter(lambda data: os.write(self._master, data), "serial-pty-tx")
        self._thread = threading.Thread(target=self._read_loop, name="serial-pty-rx", daemon=True)

    def start(self) -> SerialPty:
        self.gateway.add_writer(self._writer)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self.gateway.remove_writer(self._writer)
        self._writer.close()
        if self._thread.is_alive():
            self._thread.join()
        os.close(self._master)
        os.close(self._slave)

    def __enter__(self) -> SerialPty:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _read_loop(self) -> None:
        decoder = FrameDecoder(HOST_HEADER)
        while not self._stop.is_set():
            ready, _, _ = select.select([self._master], [], [], 0.2)
            if not ready:
                continue
            try:
                chunk = os.read(self._master, 4096)
            except OSError:
                return
            self.gateway.host_frames(decoder.feed(chunk))
