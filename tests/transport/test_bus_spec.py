"""Bus spec strings: every documented form, round trips, and clear errors."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.transport.spec import SERIAL_BAUDRATES, BusSpec, BusSpecError, known_kinds, parse_bus_spec


@pytest.mark.parametrize(
    "text, config",
    [
        ("socketcan:can0", {"interface": "socketcan", "channel": "can0"}),
        ("pcan:PCAN_USBBUS1@1000000", {"interface": "pcan", "channel": "PCAN_USBBUS1", "bitrate": 1000000}),
        ("ixxat:0@500000", {"interface": "ixxat", "channel": 0, "bitrate": 500000}),
        ("ixxat:0@500k", {"interface": "ixxat", "channel": 0, "bitrate": 500000}),
        ("kvaser:0", {"interface": "kvaser", "channel": 0}),
        ("slcan:/dev/ttyACM0@1M", {"interface": "slcan", "channel": "/dev/ttyACM0", "bitrate": 1000000}),
        (
            "socketcand:127.0.0.1:29536",
            {"interface": "socketcand", "host": "127.0.0.1", "port": 29536, "channel": "can0"},
        ),
        (
            "socketcand:localhost:29536/vcan1",
            {"interface": "socketcand", "host": "localhost", "port": 29536, "channel": "vcan1"},
        ),
        ("virtual:bench", {"interface": "virtual", "channel": "bench"}),
        ("serial:/dev/ttyUSB0", {"interface": "servostudio_rs232", "channel": "/dev/ttyUSB0", "baudrate": 19200}),
        (
            "serial:socket://127.0.0.1:29600@115200",
            {"interface": "servostudio_rs232", "channel": "socket://127.0.0.1:29600", "baudrate": 115200},
        ),
    ],
)
def test_documented_forms(text, config):
    spec = parse_bus_spec(text)
    assert spec.python_can_config() == config
    assert parse_bus_spec(str(spec)) == spec


def test_sim_defaults_to_three_xtrapulspac_nodes():
    assert parse_bus_spec("sim") == BusSpec(kind="sim", channel="1,2,3")
    assert parse_bus_spec("sim:1:xtrapulspac,2:cd1k").channel == "1:xtrapulspac,2:cd1k"
    with pytest.raises(BusSpecError):
        parse_bus_spec("sim").python_can_config()


@pytest.mark.parametrize(
    "text, words",
    [
        ("can0", "unknown interface"),
        ("usb:0", "unknown interface"),
        ("socketcan:", "missing channel"),
        ("socketcan:can0@500000", "takes no '@bitrate'"),
        ("pcan:PCAN_USBBUS1@fast", "not a number"),
        ("pcan:@500000", "missing channel"),
        ("kvaser:abc", "must be a number"),
        ("socketcand:127.0.0.1", "HOST:PORT"),
        ("socketcand:127.0.0.1:99999", "not a TCP port"),
        ("socketcand:127.0.0.1:29536/", "missing channel after '/'"),
        ("serial:/dev/ttyS0@12345", "not supported"),
        ("sim:0", "outside 1..127"),
        ("sim:1;2", "must look like"),
    ],
)
def test_errors_name_the_problem(text, words):
    with pytest.raises(BusSpecError) as error:
        parse_bus_spec(text)
    assert words in str(error.value)
    assert repr(text.strip()) in str(error.value)


names = st.text(
    st.characters(whitelist_categories=("Lu", "Ll", "Nd"), whitelist_characters="_-./"), min_size=1, max_size=20
)
specs = st.one_of(
    st.builds(BusSpec, kind=st.just("socketcan"), channel=names),
    st.builds(
        BusSpec, kind=st.sampled_from(["pcan", "slcan"]), channel=names, bitrate=st.none() | st.integers(1, 10_000_000)
    ),
    st.builds(
        BusSpec,
        kind=st.sampled_from(["ixxat", "kvaser"]),
        channel=st.integers(0, 99).map(str),
        bitrate=st.none() | st.integers(1, 10_000_000),
    ),
    st.builds(
        BusSpec,
        kind=st.just("socketcand"),
        host=names.filter(lambda name: "/" not in name),
        port=st.integers(1, 65535),
        channel=names.filter(lambda name: "/" not in name),
    ),
    st.builds(BusSpec, kind=st.just("virtual"), channel=names),
    st.builds(
        BusSpec,
        kind=st.sampled_from(["gs_usb", "vector", "systec"]),
        channel=names.filter(lambda name: "@" not in name),
        bitrate=st.none() | st.integers(1, 10_000_000),
        options=st.dictionaries(
            st.from_regex(r"[a-z_][a-z0-9_]{0,8}", fullmatch=True).filter(
                lambda name: name not in ("interface", "channel", "bitrate")
            ),
            st.text(st.characters(whitelist_categories=("Lu", "Ll", "Nd"), whitelist_characters="_-./:"), min_size=1),
            max_size=3,
        ).map(lambda options: tuple(options.items())),
    ),
    st.builds(
        BusSpec,
        kind=st.just("serial"),
        channel=names.map(lambda name: "socket://" + name + ":1"),
        bitrate=st.none() | st.sampled_from(SERIAL_BAUDRATES),
    ),
    st.builds(
        BusSpec,
        kind=st.just("sim"),
        channel=st.lists(st.integers(1, 127), min_size=1, max_size=8).map(lambda ns: ",".join(map(str, ns))),
    ),
)


@given(specs)
def test_round_trip(spec):
    assert parse_bus_spec(str(spec)) == spec


@given(st.text(max_size=40))
def test_any_text_parses_or_raises_bus_spec_error(text):
    try:
        spec = parse_bus_spec(text)
    except BusSpecError as error:
        assert str(error).startswith("bus ")
    else:
        assert spec.kind in text.lower()


@pytest.mark.parametrize(
    "text, config",
    [
        (
            "gs_usb:canable@1M?index=0&bus=1",
            {"interface": "gs_usb", "channel": "canable", "bitrate": 1_000_000, "index": 0, "bus": 1},
        ),
        ("udp_multicast:239.74.163.2", {"interface": "udp_multicast", "channel": "239.74.163.2"}),
        ("socketcan:can0?fd=true", {"interface": "socketcan", "channel": "can0", "fd": True}),
        (
            "vector:0@500k?app_name=CANalyzer",
            {"interface": "vector", "channel": "0", "bitrate": 500_000, "app_name": "CANalyzer"},
        ),
        (
            "pcan:PCAN_USBBUS1@1M?timing=0.5",
            {"interface": "pcan", "channel": "PCAN_USBBUS1", "bitrate": 1_000_000, "timing": 0.5},
        ),
    ],
)
def test_every_python_can_interface_with_its_own_options(text, config):
    spec = parse_bus_spec(text)
    assert spec.python_can_config() == config
    assert parse_bus_spec(str(spec)) == spec


def test_every_interface_python_can_registers_is_a_kind():
    from can.interfaces import VALID_INTERFACES

    assert set(VALID_INTERFACES) - {"serial", "servostudio_rs232"} <= set(known_kinds())


def test_a_pyserial_url_keeps_its_own_query():
    spec = parse_bus_spec("serial:rfc2217://127.0.0.1:4000?logging=debug")
    assert spec.python_can_config()["channel"] == "rfc2217://127.0.0.1:4000?logging=debug"


@pytest.mark.parametrize(
    "text, words",
    [
        ("pcan:x?index", "must look like name=value"),
        ("pcan:x?=3", "must look like name=value"),
        ("pcan:x?a=1&a=2", "given twice"),
        ("pcan:x?channel=3", "part of the spec itself"),
        ("udp_multicast:239.74.163.2@500000", "takes no '@bitrate'"),
        ("sim:1?speed=2", "takes no options"),
    ],
)
def test_option_errors_name_the_problem(text, words):
    with pytest.raises(BusSpecError, match=words):
        parse_bus_spec(text)


def test_a_missing_driver_package_is_named():
    """gs_usb needs pyusb; where it is missing, the error says which extra brings it."""
    import importlib.util

    import can

    if importlib.util.find_spec("usb") is not None:
        pytest.skip("pyusb is installed here")

    from servostudio.transport.open import open_bus

    with pytest.raises(can.CanInitializationError, match=r'pip install "python-can\[gs-usb\]"'):
        open_bus(parse_bus_spec("gs_usb:canable@1M?index=0"))
