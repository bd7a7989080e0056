"""`servostudio store --bus SPEC --node N` (here and through a server): the device's own save, judged on the
simulated drives — an XtrapulsPac's flash file DRIVEPAR.TXT, a TTA-PRO's EEPROM through a simulated power cycle
(which keeps only EEPROM values) — and an enabled TTA-PRO refused with exit code 3 and nothing stored."""

from __future__ import annotations

import signal
import subprocess
import sys

import pytest
from tests.support.commands import run_json
from tests.support.motion_timing import server_on_bus
from tests.support.profibus_line import ttapro_line

from servostudio.formats.objectfile import parse_object_file
from servostudio.sim.drive.statemachine import State


@pytest.fixture(scope="module")
def line():
    with ttapro_line(5) as line:
        yield line


@pytest.fixture(scope="module")
def server(tmp_path_factory, line):
    with server_on_bus(tmp_path_factory.mktemp("cli-store"), line.spec) as running:
        yield running


def flash_kpv(node) -> object:
    text = node.flash.read_text("DRIVEPAR.TXT") or ""
    return {(entry.index, entry.sub): entry.value for entry in parse_object_file(text)}.get((0x60F9, 2))


def through(capsys, server, bus: str, node: int, *argv: str) -> tuple[int, object, str]:
    """A command through the server on one of its buses."""
    command, *rest = argv
    return run_json(capsys, command, "--server", server.url, "--bus", bus, "--node", str(node), *rest)


def survives_power_cycle(line, value: int) -> bool:
    slave = line.slaves[5]
    with line.line.lock:
        slave.power_cycle()
        return slave.memory.get(730) == value


def test_store_here_on_a_ttapro_keeps_the_value_through_a_power_cycle(line, capsys):
    kp = line.slaves[5].memory.get(730) % 400 + 11
    assert run_json(capsys, "write", "--bus", line.spec, "--node", "5", "PNU730", str(kp))[0] == 0
    code, stored, _ = run_json(capsys, "store", "--bus", line.spec, "--node", "5")
    assert code == 0 and stored["wrote"] == "PNU 729 Save parameters in EEPROM = 1"
    assert survives_power_cycle(line, kp)


def test_store_here_on_an_xtrapulspac_writes_its_flash_file(socketcand, sim_network, capsys):
    kpv = 311 if flash_kpv(sim_network.node(2)) == 310 else 310
    assert run_json(capsys, "write", "--bus", socketcand.spec, "--node", "2", "0x60F9,2", str(kpv))[0] == 0
    code, stored, _ = run_json(capsys, "store", "--bus", socketcand.spec, "--node", "2")
    assert code == 0 and stored["stored"] == "save" and flash_kpv(sim_network.node(2)) == kpv


def test_store_through_a_server_on_both_devices(server, line, capsys):
    kp = line.slaves[5].memory.get(730) % 400 + 23
    assert through(capsys, server, "pb", 5, "write", "PNU730", str(kp))[0] == 0
    code, stored, _ = through(capsys, server, "pb", 5, "store")
    assert code == 0 and stored["wrote"] == "PNU 729 Save parameters in EEPROM = 1"
    assert survives_power_cycle(line, kp)
    node = server.network.node(1)
    kpv = 313 if flash_kpv(node) == 312 else 312
    assert through(capsys, server, "sim", 1, "write", "0x60F9,2", str(kpv))[0] == 0
    code, stored, _ = through(capsys, server, "sim", 1, "store")
    assert code == 0 and stored["wrote"] == "0x1010,1 Store parameters.Save all parameters = 'save'"
    assert flash_kpv(node) == kpv


def test_store_of_an_enabled_ttapro_is_refused_and_stores_nothing(server, line, capsys):
    kept = line.slaves[5].memory.get(730)
    assert through(capsys, server, "pb", 5, "write", "PNU730", str(kept + 1))[0] == 0
    command = [sys.executable, "-m", "servostudio", "--server", server.url, "state", "operation-enabled"]
    holder = subprocess.Popen([*command, "--bus", "pb", "--node", "5"], stderr=subprocess.PIPE, text=True)
    try:
        said = holder.stderr.readline()
        assert "holding" in said, said + holder.stderr.read()
        with line.line.lock:
            assert line.slaves[5].drive.device.state is State.OPERATION_ENABLED
        code, out, error = through(capsys, server, "pb", 5, "store")
    finally:
        holder.send_signal(signal.SIGTERM)
        holder.communicate(timeout=30)
    assert code == 3 and out is None
    assert error.strip().splitlines()[-1] == (
        "error: node 5: TTA-PRO stores parameters only with the drive disabled; disable it first — nothing was written"
    )
    assert survives_power_cycle(line, kept)
