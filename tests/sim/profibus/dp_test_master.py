"""An independent PROFIBUS-DP class-1 master for the tests: its FDL framing, DP payloads and PKW packing are
written here from EN 50170 and the TTA-PRO manual, not taken from `servostudio.transport.profibus` or pyprofibus,
so a mistake shared by the project's codec and its simulated slave cannot hide.

Bytes: SD1 = 10 DA SA FC FCS 16; SD2 = 68 LE LE 68 DA SA FC DU FCS 16 (LE = 3 + len(DU)); SD3 = A2 DA SA FC DU(8)
FCS 16 (a data unit of exactly 8 bytes, e.g. a Slave_Diag response: 2 SAP bytes + 6); SC = E5. FCS is the sum
of DA..DU mod 256. DA/SA bit 7 announce a SAP byte at the start of DU (DSAP first). SRD high priority is FC 0x4D
(+ FCB 0x20, FCV 0x10).
"""

from __future__ import annotations

import select
import socket
import struct
import time

MASTER = 2
SRD_HIGH = 0x4D
SDN_HIGH = 0x46
FCB, FCV = 0x20, 0x10
SAP_MASTER, SAP_GLOBAL, SAP_DIAG, SAP_PRM, SAP_CFG = 62, 58, 60, 61, 62
IDENT = 0x00C7
PPO2_CONFIG = bytes((0xF3, 0xF5))
PPO2_LENGTH = 20
ENABLING = (0x0400, 0x0406, 0x0407, 0x043F)


def fcs(body: bytes) -> int:
    return sum(body) & 0xFF


def sd1(destination: int, function: int, source: int = MASTER) -> bytes:
    body = bytes((destination, source, function))
    return bytes((0x10,)) + body + bytes((fcs(body), 0x16))


def sd2(
    destination: int, function: int, data: bytes, saps: tuple[int, int] | None = None, source: int = MASTER
) -> bytes:
    if saps is not None:
        destination, source, data = destination | 0x80, source | 0x80, bytes(saps) + data
    body = bytes((destination, source, function)) + data
    length = len(body)
    return bytes((0x68, length, length, 0x68)) + body + bytes((fcs(body), 0x16))


def parse_response(data: bytes) -> tuple[str, int, bytes]:
    """(kind, function code, data unit after any SAP bytes) of one complete response; AssertionError if malformed."""
    if data == b"\xe5":
        return "SC", 0, b""
    if data[0] == 0x10:
        assert len(data) == 6 and data[4] == fcs(data[1:4]) and data[5] == 0x16, data.hex()
        return "SD1", data[3], b""
    if data[0] == 0xA2:
        assert len(data) == 14, data.hex()
        kind, body = "SD3", data[1:-2]
    else:
        assert data[0] == 0x68 and data[1] == data[2] and data[3] == 0x68, data.hex()
        kind, body = "SD2", data[4:-2]
    assert data[-2] == fcs(body) and data[-1] == 0x16, data.hex()
    unit = body[3:]
    skip = (1 if body[0] & 0x80 else 0) + (1 if body[1] & 0x80 else 0)
    return kind, body[2], unit[skip:]


def response_length(buffer: bytes) -> int | None:
    if not buffer:
        return None
    if buffer[0] == 0xE5:
        return 1
    if buffer[0] == 0x10:
        return 6
    if buffer[0] == 0xA2:
        return 14
    if buffer[0] == 0x68 and len(buffer) >= 2:
        return buffer[1] + 6
    return None


def pkw(ak: int, pnu: int, index: int = 0, value: int = 0) -> bytes:
    return struct.pack(">HBxI", ak << 12 | pnu, index, value & 0xFFFFFFFF)


def unpack_pkw(data: bytes) -> tuple[int, int, int, int]:
    """(AK, PNU, IND, PWE)."""
    pke, index, value = struct.unpack(">HBxI", data)
    return pke >> 12, pke & 0x7FF, index, value


class TestMaster:
    """Talks to one slave over a TCP byte stream, one request and response at a time."""

    __test__ = False  # not a pytest class

    def __init__(self, host: str, port: int, slave: int) -> None:
        self.sock = socket.create_connection((host, port))
        self.slave = slave
        self._buffer = b""
        self._fcb = 1
        self.pzd = [0] * 6

    def close(self) -> None:
        self.sock.close()

    def send(self, telegram: bytes) -> None:
        self.sock.sendall(telegram)

    def receive(self, timeout: float = 0.5) -> bytes | None:
        deadline = time.monotonic() + timeout
        while True:
            length = response_length(self._buffer)
            if length is not None and len(self._buffer) >= length:
                response, self._buffer = self._buffer[:length], self._buffer[length:]
                return response
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self.sock], [], [], left)[0]:
                return None
            self._buffer += self.sock.recv(4096)

    def request(self, data: bytes = b"", saps: tuple[int, int] | None = None) -> tuple[str, int, bytes]:
        """An SRD request with a toggled FCB; the parsed response."""
        self._fcb ^= 1
        function = SRD_HIGH | FCV | (FCB if self._fcb else 0)
        self.send(sd2(self.slave, function, data, saps) if data or saps else sd1(self.slave, function))
        response = self.receive()
        assert response is not None, "no response from the slave"
        return parse_response(response)

    # -- DP services ----------------------------------------------------------------------------------------

    def diagnosis(self) -> bytes:
        kind, function, data = self.request(b"", (SAP_DIAG, SAP_MASTER))
        assert kind in ("SD2", "SD3") and function == 0x08 and len(data) >= 6
        return data

    def set_prm(self, ident: int = IDENT, watchdog_ms: int = 0) -> str:
        status = 0x80 | (0x08 if watchdog_ms else 0)
        factor = max(1, watchdog_ms // 10)
        data = bytes((status, factor, 1, 0, ident >> 8, ident & 0xFF, 0))
        return self.request(data, (SAP_PRM, SAP_MASTER))[0]

    def chk_cfg(self, config: bytes = PPO2_CONFIG) -> str:
        return self.request(config, (SAP_CFG, SAP_MASTER))[0]

    def parameterise(self, watchdog_ms: int = 0) -> None:
        assert self.set_prm(watchdog_ms=watchdog_ms) == "SC"
        assert self.chk_cfg() == "SC"
        diag = self.diagnosis()
        assert diag[0] == 0 and diag[1] & 0x01 == 0 and diag[3] == MASTER, diag.hex()

    def global_control(self, command: int) -> None:
        data = bytes((command, 0))
        self.send(sd2(127, SDN_HIGH, data, (SAP_GLOBAL, SAP_MASTER)))

    # -- PPO2 data exchange ---------------------------------------------------------------------------------

    def exchange(self, request: bytes) -> tuple[tuple[int, int, int, int], list[int]]:
        """One Data_Exchange of PPO2: (the PKW reply, the six PZD in)."""
        kind, function, data = self.request(request + struct.pack(">6H", *self.pzd))
        assert (kind, function, len(data)) == ("SD2", 0x08, PPO2_LENGTH), (kind, function, data.hex())
        return unpack_pkw(data[:8]), list(struct.unpack(">6H", data[8:]))

    def idle_until_clear(self) -> list[int]:
        """AK 0 until the slave shows AK 0: the separator between two PKW transactions."""
        for _ in range(100):
            reply, words = self.exchange(pkw(0, 0))
            if reply[0] == 0:
                return words
            time.sleep(0.001)
        raise AssertionError("the PKW reply never cleared")

    def transaction(self, request: bytes) -> tuple[int, int, int, int]:
        """Repeat `request` until its reply (same PNU, AK ≠ 0), then separate."""
        self.idle_until_clear()
        pnu = unpack_pkw(request)[1]
        for _ in range(200):
            reply, _ = self.exchange(request)
            if reply[0] != 0 and reply[1] == pnu:
                return reply
            time.sleep(0.001)
        raise AssertionError(f"no PKW reply for PNU {pnu}")

    def read(self, pnu: int, index: int = 0) -> tuple[int, int, int, int]:
        return self.transaction(pkw(1, pnu, index))

    def write(self, pnu: int, value: int, double: bool = False, index: int = 0) -> tuple[int, int, int, int]:
        return self.transaction(pkw(3 if double else 2, pnu, index, value))

    def status_after(self, control: int, mask: int, value: int, timeout: float = 2.0) -> int:
        """Send `control` in PZD1 (a cycle at least every 1 ms, as the manual asks) until ZSW & mask == value."""
        self.pzd[0] = control
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            _, words = self.exchange(pkw(0, 0))
            if words[0] & mask == value:
                return words[0]
            time.sleep(0.0015)
        raise AssertionError(f"STW 0x{control:04X}: ZSW 0x{words[0]:04X} never matched 0x{value:04X}/0x{mask:04X}")
