"""FDL telegram codec (EN 50170 vol. 2 part 2): the bytes of known telegrams, round trips of any telegram, a byte
stream cut anywhere, and every corrupted telegram rejected with its reason."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.transport.profibus.telegram import (
    MAX_UNIT,
    SD1,
    SD2,
    SD3,
    ShortAcknowledge,
    Telegram,
    Token,
    encode,
)
from servostudio.transport.profibus.telegram_decoder import TelegramDecoder, TelegramError, decode_telegram

addresses = st.integers(0, 127)
saps = st.none() | st.integers(0, 63)


@st.composite
def telegrams(draw) -> Telegram:
    destination_sap, source_sap = draw(saps), draw(saps)
    extensions = (destination_sap is not None) + (source_sap is not None)
    data = draw(st.binary(max_size=MAX_UNIT - extensions))
    return Telegram(draw(addresses), draw(addresses), draw(st.integers(0, 255)), data, destination_sap, source_sap)


frames = telegrams() | st.builds(Token, addresses, addresses) | st.just(ShortAcknowledge())


def test_known_telegrams_have_the_standards_bytes() -> None:
    fdl_status = Telegram(5, 2, 0x49)
    assert encode(fdl_status) == bytes.fromhex("10 05 02 49 50 16")
    slave_diag = Telegram(5, 2, 0x6D, b"", 60, 62)
    assert encode(slave_diag) == bytes.fromhex("68 05 05 68 85 82 6D 3C 3E EE 16")
    eight = Telegram(2, 5, 0x08, bytes(6), 62, 60)
    assert encode(eight)[0] == SD3 and len(encode(eight)) == 14
    assert encode(ShortAcknowledge()) == b"\xe5"
    assert encode(Token(3, 1)) == bytes((0xDC, 3, 1))


@given(telegrams())
def test_the_delimiter_follows_the_data_unit_length(telegram: Telegram) -> None:
    size = len(telegram.unit)
    assert telegram.delimiter == (SD1 if size == 0 else SD3 if size == 8 else SD2)


@given(frames)
def test_every_frame_reads_back_as_itself(frame) -> None:
    assert decode_telegram(encode(frame)) == frame


@given(st.lists(frames, max_size=8), st.data())
def test_a_stream_cut_anywhere_gives_the_same_frames(sequence, data) -> None:
    stream = b"".join(encode(frame) for frame in sequence)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=6)))
    decoder = TelegramDecoder()
    received = []
    for start, end in zip([0, *cuts], [*cuts, len(stream)], strict=True):
        received += decoder.feed(stream[start:end])
    assert received == sequence and decoder.dropped_bytes == 0


@given(telegrams(), st.data())
def test_any_single_byte_change_is_rejected_with_a_reason(telegram: Telegram, data) -> None:
    raw = bytearray(encode(telegram))
    position = data.draw(st.integers(0, len(raw) - 1))
    raw[position] = (raw[position] + data.draw(st.integers(1, 255))) & 0xFF
    with pytest.raises(TelegramError) as error:
        decode_telegram(bytes(raw))
    assert str(error.value)


@given(telegrams(), telegrams(), st.data())
def test_a_corrupted_telegram_is_dropped_and_the_next_one_still_arrives(
    before: Telegram, after: Telegram, data
) -> None:
    raw = bytearray(encode(before))
    position = data.draw(st.integers(0, len(raw) - 1))
    raw[position] ^= data.draw(st.integers(1, 255))
    decoder = TelegramDecoder()
    decoder.feed(bytes(raw))
    decoder.line_idle()
    assert decoder.feed(encode(after))[-1:] == [after]
    assert decoder.rejected


@pytest.mark.parametrize(
    ("raw", "reason"),
    [
        (bytes.fromhex("10 05 02 49 51 16"), "FCS 0x51 does not match the computed 0x50"),
        (bytes.fromhex("10 05 02 49 50 17"), "end delimiter 0x17, expected 0x16"),
        (bytes.fromhex("68 05 06 68 85 82 6D 3C 3E EE 16"), "SD2 length LE 0x05 differs from its repetition LEr 0x06"),
        (bytes.fromhex("68 02 02 68 85 82 00 00"), "SD2 length LE 2 is outside 4..249"),
        (bytes.fromhex("68 05 05 10 85 82 6D 3C 3E EE 16"), "SD2 start delimiter is repeated as 0x10"),
        (bytes.fromhex("33 05 02 49 50 16"), "unknown start delimiter 0x33"),
        (bytes.fromhex("10 05 02 49 50"), "telegram of 5 bytes, its delimiter 0x10 needs 6"),
        (
            bytes.fromhex("68 04 04 68 85 02 6D C0 B4 16"),
            "destination address extension 0xC0 chains or names a segment",
        ),
    ],
)
def test_malformed_telegrams_name_what_is_wrong(raw: bytes, reason: str) -> None:
    with pytest.raises(TelegramError, match=reason.replace("(", r"\(").replace(")", r"\)")):
        decode_telegram(raw)


def test_the_stream_drops_garbage_and_a_telegram_that_never_ends() -> None:
    decoder = TelegramDecoder()
    good = encode(Telegram(5, 2, 0x49))
    assert decoder.feed(b"\x00\x33" + good) == [Telegram(5, 2, 0x49)]
    assert decoder.dropped_bytes == 2
    assert decoder.feed(good[:3]) == []
    decoder.line_idle()
    assert "discarded on line idle" in decoder.rejected[-1]
    assert decoder.feed(good) == [Telegram(5, 2, 0x49)]


def test_a_telegram_refuses_what_the_wire_cannot_carry() -> None:
    with pytest.raises(ValueError, match="address"):
        Telegram(128, 2, 0x49)
    with pytest.raises(ValueError, match="at most 246"):
        Telegram(5, 2, 0x49, bytes(247))
