"""The SDO server a share's client talks to: CiA 301 expedited and segmented transfers, frame by frame, against
fake engine calls (property tests: any request sequence is answered with 8-byte frames and never raises)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from servostudio.drive.sdo import SdoAbortError
from servostudio.services.bus.sdo_proxy import ABORT_COMMAND, ABORT_TOGGLE, SdoProxy


class Drive:
    """The engine side: values by (index, sub); writes kept."""

    def __init__(self, values: dict[tuple[int, int], bytes]) -> None:
        self.values, self.answers = values, []

    def upload(self, node: int, index: int, sub: int) -> bytes:
        if (index, sub) not in self.values:
            raise SdoAbortError(node, index, sub, 0x06020000)
        return self.values[index, sub]

    def write(self, node: int, index: int, sub: int, data: bytes) -> None:
        self.values[index, sub] = data

    def proxy(self) -> SdoProxy:
        return SdoProxy(self.upload, self.write, lambda node, data: self.answers.append((node, data)))


def _upload(proxy: SdoProxy, drive: Drive, index: int, sub: int) -> bytes:
    """A client's upload, expedited or segmented, as python canopen runs it."""
    proxy.request(5, bytes([0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0]))
    first = drive.answers.pop()[1]
    if first[0] & 0x02:
        return first[4 : 8 - ((first[0] >> 2) & 3)]
    data, toggle = b"", 0
    while True:
        proxy.request(5, bytes([0x60 | (toggle << 4)]) + bytes(7))
        segment = drive.answers.pop()[1]
        data += segment[1 : 8 - ((segment[0] >> 1) & 7)]
        toggle ^= 1
        if segment[0] & 0x01:
            return data


def _download(proxy: SdoProxy, drive: Drive, index: int, sub: int, data: bytes) -> None:
    proxy.request(5, bytes([0x21, index & 0xFF, index >> 8, sub]) + len(data).to_bytes(4, "little"))
    assert drive.answers.pop()[1][0] == 0x60
    for start, toggle in zip(range(0, len(data), 7), [0, 1] * len(data), strict=False):
        chunk = data[start : start + 7]
        last = start + 7 >= len(data)
        proxy.request(5, bytes([(toggle << 4) | ((7 - len(chunk)) << 1) | int(last)]) + chunk.ljust(7, b"\0"))
        assert drive.answers.pop()[1][0] == 0x20 | (toggle << 4)


@given(st.binary(min_size=1, max_size=200))
def test_an_upload_brings_the_value_whatever_its_length(value):
    drive = Drive({(0x2004, 0): value})
    assert _upload(drive.proxy(), drive, 0x2004, 0) == value


@given(st.binary(min_size=5, max_size=200))
def test_a_segmented_download_writes_the_whole_value(value):
    drive = Drive({})
    _download(drive.proxy(), drive, 0x2004, 0, value)
    assert drive.values[0x2004, 0] == value


def test_expedited_download_aborts_and_block_requests():
    drive = Drive({(0x6041, 0): b"\x40\x02"})
    proxy = drive.proxy()
    proxy.request(1, bytes([0x2B, 0xF9, 0x60, 2, 77, 0, 0, 0]))  # 2 bytes, expedited
    assert drive.answers.pop() == (1, bytes([0x60, 0xF9, 0x60, 2, 0, 0, 0, 0]))
    assert drive.values[0x60F9, 2] == bytes([77, 0])
    proxy.request(1, bytes([0x40, 0xFE, 0x2F, 0, 0, 0, 0, 0]))  # unknown object: the drive's abort code
    assert drive.answers.pop() == (1, bytes([0x80, 0xFE, 0x2F, 0]) + (0x06020000).to_bytes(4, "little"))
    proxy.request(1, bytes([0xA4, 0x41, 0x60, 0, 0x7F, 0, 0, 0]))  # block upload: refused
    assert drive.answers.pop()[1][4:] == ABORT_COMMAND.to_bytes(4, "little")
    proxy.request(1, bytes([0x70]) + bytes(7))  # a segment without a transfer
    assert drive.answers.pop()[1][4:] == ABORT_TOGGLE.to_bytes(4, "little")


@given(st.lists(st.binary(min_size=8, max_size=8), max_size=30))
def test_any_request_sequence_is_answered_with_frames_and_never_raises(requests):
    drive = Drive({(0x1008, 0): b"XtrapulsPac", (0x6041, 0): b"\x40\x02"})
    proxy = drive.proxy()
    for request in requests:
        proxy.request(3, request)
    assert all(node == 3 and len(data) == 8 for node, data in drive.answers)
