"""``servostudio jog`` and ``servostudio home``, on their own bus and through ``--server``: the moves read back from
the simulated drive, the limits refused before the bus, the refusal while another client holds the axis, and a
command killed (or frozen) mid-jog stopping the axis within 200 ms of its last keepalive on the simulator's clock."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys

import httpx
import pytest
from tests.support.motion_timing import DriveProbe, InProcessServer, KeepaliveLog
from tests.support.waits import eventually

from servostudio.cli.liveclient import LiveClient
from servostudio.cli.remote import Remote
from servostudio.services.motion.hold import HOLD_TIMEOUT

BUDGET = 0.2  # seconds from the last keepalive to the stop (issue #13)


def servostudio(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    command = [sys.executable, "-m", "servostudio", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=_env())


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONUNBUFFERED": "1"}


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    running = InProcessServer(tmp_path_factory.mktemp("motion-cli"))
    yield running
    running.close()


def position(server: InProcessServer, node: int) -> int:
    return int(httpx.get(f"{server.url}/api/buses/sim/nodes/{node}/objects/0x6064").json()["raw"])


def state(server: InProcessServer, node: int) -> str:
    return httpx.get(f"{server.url}/api/buses/sim/nodes/{node}/state").json()["state"]


def test_a_jog_and_a_move_on_the_commands_own_bus():
    jogged = servostudio("jog", "--bus", "sim", "--node", "1", "--velocity", "60", "--seconds", "0.3")
    assert jogged.returncode == 0, jogged.stderr
    assert json.loads(jogged.stdout)["state"] == "done"
    moved = servostudio("jog", "--bus", "sim", "--node", "1", "--move", "1024", "--absolute")
    assert moved.returncode == 0, moved.stderr
    assert abs(json.loads(moved.stdout)["position"] - 1024) <= 4


def test_limits_are_refused_before_the_bus():
    refused = servostudio("jog", "--bus", "sim", "--node", "1", "--velocity", "5000", "--seconds", "1")
    assert refused.returncode == 3 and "velocity_rpm" in refused.stderr
    assert refused.stdout == ""
    missing = servostudio("jog", "--bus", "sim", "--node", "1", "--velocity", "60")
    assert missing.returncode == 3 and "--seconds" in missing.stderr


@pytest.fixture
def patient_hold(server):
    """The hold-to-run watchdog at 1 s instead of 0.1 s, for a test of what the motions do, not of the hold's
    timing (the killed and frozen commands below judge that): a loaded host once starved the command's keepalives
    for 200 ms and the move ended stopped — the safe side, but not what this test is about."""
    server.set_hold_timeout(1.0)
    yield server
    server.set_hold_timeout(HOLD_TIMEOUT)


def test_moves_and_homing_through_the_server(patient_hold):
    server = patient_hold
    start = position(server, 2)
    moved = servostudio("--server", server.url, "jog", "--bus", "sim", "--node", "2", "--move", "2048")
    assert moved.returncode == 0, moved.stderr
    assert json.loads(moved.stdout)["state"] == "done"
    assert abs(position(server, 2) - (start + 2048)) <= 4
    to = start - 512
    absolute = servostudio(
        "jog", "--server", server.url, "--bus", "sim", "--node", "2", "--move", str(to), "--absolute"
    )
    assert absolute.returncode == 0, absolute.stderr
    assert abs(position(server, 2) - to) <= 4
    homed = servostudio("home", "--server", server.url, "--bus", "sim", "--node", "2", "--method", "35")
    assert homed.returncode == 0, homed.stderr
    answer = json.loads(homed.stdout)
    assert answer["kind"] == "home" and answer["state"] == "done"
    assert answer["statusword"] & (1 << 12)  # homing attained, as the drive said when it ended
    assert httpx.get(f"{server.url}/api/control").json() == []  # released again


def test_through_the_server_an_axis_another_client_holds_is_refused(server):
    with LiveClient(Remote(server.url, None)) as other:
        other.arm("sim", 3)
        refused = servostudio(
            "jog", "--server", server.url, "--bus", "sim", "--node", "3", "--velocity", "60", "--seconds", "1"
        )
        assert refused.returncode == 3 and "armed by" in refused.stderr
        assert state(server, 3) != "OPERATION ENABLED"


def motion(server: InProcessServer, node: int) -> dict:
    return httpx.get(f"{server.url}/api/buses/sim/nodes/{node}/motion").json()


def held_jog(server: InProcessServer, keepalives: KeepaliveLog, probe: DriveProbe) -> subprocess.Popen:
    """A CLI jog through the server, running and kept alive.  On a host so loaded that a keepalive came late and
    the server stopped the jog early (the safe side), it is started again, up to three times."""
    command = [sys.executable, "-m", "servostudio", "jog", "--server", server.url, "--bus", "sim", "--node", "3"]
    for _ in range(3):
        keepalives.times.clear()
        probe.samples.clear()
        process = subprocess.Popen([*command, "--velocity", "60", "--seconds", "10"], env=_env())
        ended = process.poll
        eventually(lambda: len(keepalives.times) > 10 or ended() is not None, 60, "the jog's keepalives")  # noqa: B023
        eventually(lambda: probe.was_running() or ended() is not None, 10, "the axis turning")  # noqa: B023
        if process.poll() is None and motion(server, 3)["state"] == "running":
            return process
        process.kill()
        process.wait(timeout=10)
    raise AssertionError(f"the held jog never kept running: {motion(server, 3)}")


@pytest.mark.parametrize("how", [signal.SIGKILL, signal.SIGSTOP], ids=["killed", "frozen"])
def test_a_command_killed_mid_jog_stops_the_axis_within_200_ms_of_its_last_keepalive(server, how):
    keepalives = KeepaliveLog(server.network)
    keepalives.install(server)
    probe = DriveProbe(server.network, 3)
    process = held_jog(server, keepalives, probe)
    try:
        process.send_signal(how)  # frozen: its socket stays open, only the missing keepalives can stop the axis
        eventually(lambda: state(server, 3) != "OPERATION ENABLED", 5, "the stop")
        eventually(lambda: probe.samples[-1].time > probe.stop_began() + 0.05, 5, "the samples after the stop")
    finally:
        probe.stop()
        process.kill()
        process.wait(timeout=10)
    last = keepalives.last()
    assert probe.stop_began() - last <= BUDGET, (probe.stop_began() - last, how)
    assert probe.standstill() - last <= BUDGET, (probe.standstill() - last, how)
    ended = motion(server, 3)
    assert ended["state"] == "stopped"
    if how == signal.SIGSTOP:
        assert "no keepalive" in ended["reason"]
