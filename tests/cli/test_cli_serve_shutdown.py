"""`servostudio serve` stops within 5 s of SIGTERM even with ten backup jobs running: closing its buses ends every
transfer in flight at once, so no job, request or worker thread keeps the process alive."""

from __future__ import annotations

import signal
import time

import httpx
from tests.support.live_server import LiveServer

from servostudio.formats.objectfile import read_object_file

SHUTDOWN_LIMIT = 5.0


def test_sigterm_with_ten_backups_running_stops_the_server_within_5_s(tmp_path):
    projects = tmp_path / "projects"
    projects.mkdir()
    server = LiveServer(projects)
    try:
        server.wait_ready()
        assert httpx.post(f"{server.url}/api/buses/sim/scan", timeout=30).status_code == 200
        jobs = [
            httpx.post(f"{server.url}/api/buses/sim/backup", json={"directory": str(projects / f"backup{n}")}).json()
            for n in range(10)
        ]
        time.sleep(0.5)
        running = [httpx.get(f"{server.url}/api/jobs/{job['id']}").json()["state"] for job in jobs]
        assert running.count("running") >= 8  # the work is in flight when the signal comes
        started = time.monotonic()
        server.process.send_signal(signal.SIGTERM)
        server.process.wait(timeout=30)
        assert time.monotonic() - started < SHUTDOWN_LIMIT, server.log.read_text()[-2000:]
    finally:
        server.stop()
    for path in projects.rglob("DRIVEPAR.TXT"):  # a file is there whole, or not at all
        assert read_object_file(path)
