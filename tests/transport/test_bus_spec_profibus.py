"""The PROFIBUS-DP bus spec ``profibus:PORT[@BAUD][?master=ADDR]``: its forms, one canonical text per line,
clear refusals, and round trips of any valid spec (hypothesis)."""

from __future__ import annotations

import re

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.transport.spec import PROFIBUS_BAUDRATES, BusSpecError, parse_bus_spec


@pytest.mark.parametrize(
    ("text", "canonical", "channel", "baud", "master"),
    [
        ("profibus:/dev/pts/3", "profibus:/dev/pts/3", "/dev/pts/3", None, 2),
        ("profibus:/dev/ttyUSB0@500k", "profibus:/dev/ttyUSB0@500000", "/dev/ttyUSB0", 500_000, 2),
        ("PROFIBUS:socket://127.0.0.1:29700", "profibus:socket://127.0.0.1:29700", "socket://127.0.0.1:29700", None, 2),
        (
            "profibus:tcp:localhost:29700@12M?master=1",
            "profibus:socket://localhost:29700@12000000?master=1",
            "socket://localhost:29700",
            12_000_000,
            1,
        ),
        ("profibus:/dev/pts/3?master=2", "profibus:/dev/pts/3", "/dev/pts/3", None, 2),  # the default is implied
    ],
)
def test_documented_forms(text: str, canonical: str, channel: str, baud: int | None, master: int) -> None:
    spec = parse_bus_spec(text)
    shown = (str(spec), spec.kind, spec.channel, spec.bitrate, spec.profibus_master)
    assert shown == (canonical, "profibus", channel, baud, master)
    assert parse_bus_spec(str(spec)) == spec


def test_the_tcp_spelling_and_the_default_master_are_one_bus() -> None:
    assert parse_bus_spec("profibus:tcp:h:1?master=2") == parse_bus_spec("profibus:socket://h:1")


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("profibus:", "missing port after 'profibus:'"),
        ("profibus:/dev/ttyUSB0@1234", "PROFIBUS baud rate 1234 not supported"),
        ("profibus:/dev/ttyUSB0@fast", "bit rate 'fast' is not a number"),
        ("profibus:tcp:host", "expected socket://HOST:PORT"),
        ("profibus:socket://host:99999", "expected socket://HOST:PORT"),
        ("profibus:/dev/ttyUSB0?master=126", "master address '126' outside 0..125"),
        ("profibus:/dev/ttyUSB0?ppo=2", "takes only the option master=ADDR"),
    ],
)
def test_refusals_name_the_wrong_part(text: str, reason: str) -> None:
    with pytest.raises(BusSpecError, match=re.escape(reason)):
        parse_bus_spec(text)


def test_python_can_does_not_open_a_dp_line() -> None:
    with pytest.raises(BusSpecError, match="PROFIBUS-DP line, not a CAN bus"):
        parse_bus_spec("profibus:/dev/ttyUSB0").python_can_config()


_PATHS = st.from_regex(r"/dev/[a-z]{1,8}[0-9]{0,2}", fullmatch=True)
_TCP = st.builds(lambda port: f"socket://127.0.0.1:{port}", st.integers(1, 65535))


@given(
    port=st.one_of(_PATHS, _TCP),
    baud=st.none() | st.sampled_from(PROFIBUS_BAUDRATES),
    master=st.none() | st.integers(0, 125),
)
def test_any_valid_spec_reads_back_from_its_text(port: str, baud: int | None, master: int | None) -> None:
    text = f"profibus:{port}" + (f"@{baud}" if baud else "") + (f"?master={master}" if master is not None else "")
    spec = parse_bus_spec(text)
    assert spec.channel == port and spec.bitrate == baud and spec.profibus_master == (2 if master is None else master)
    assert parse_bus_spec(str(spec)) == spec
