"""A real `servostudio serve` process on a free localhost port, as a user starts it (API and browser tests).

Its data directory is fresh: opted into the password-less single-user mode (`tests.support.access`) unless the
test passes one it prepared itself (users, tokens, or nothing at all for the first-start setup)."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import httpx
import pytest
from tests.support.access import passwordless

REPO_ROOT = Path(__file__).resolve().parents[2]


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class LiveServer:
    """`servostudio serve` in a child process, as a user would start it."""

    def __init__(self, projects_dir: Path, extra_args: list[str] | None = None, data_dir: Path | None = None) -> None:
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.data_dir = data_dir or passwordless(projects_dir.parent / f"data-{self.port}")
        command = [
            sys.executable,
            "-m",
            "servostudio",
            "serve",
            "--port",
            str(self.port),
            "--projects",
            str(projects_dir),
            "--data-dir",
            str(self.data_dir),
            *_private_ui(),
            *(extra_args or []),
        ]
        self.log = projects_dir.parent / f"server-{self.port}.log"
        self._log_file = self.log.open("wb")
        self.process = subprocess.Popen(
            command,
            cwd=REPO_ROOT,
            stdout=self._log_file,
            stderr=subprocess.STDOUT,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )

    def wait_ready(self, timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise RuntimeError(f"server exited with {self.process.returncode}:\n{self.log.read_text()}")
            try:
                if httpx.get(f"{self.url}/api/health", timeout=1.0).status_code == 200:
                    return
            except httpx.HTTPError:
                time.sleep(0.1)
        raise TimeoutError(f"server not ready after {timeout} s:\n{self.log.read_text()}")

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self._log_file.close()


# Module scope: the server runs three simulated drives in real time; it must not outlive the tests using it.
@pytest.fixture(scope="module")
def live_server(tmp_path_factory: pytest.TempPathFactory):
    root = tmp_path_factory.mktemp("live")
    projects = root / "projects"
    projects.mkdir()
    server = LiveServer(projects)
    try:
        server.wait_ready()
        yield server
    finally:
        server.stop()


def _private_ui() -> list[str]:
    """``SERVOSTUDIO_TEST_UI=DIR``: serve a UI built into DIR instead of the package's (an engineer trying a
    frontend change while others' browser tests read the shared build)."""
    built = os.environ.get("SERVOSTUDIO_TEST_UI")
    return ["--ui", built] if built else []


def private_ui_settings() -> dict[str, Path]:
    """The same for a server built in the test's process: ``Settings(**private_ui_settings(), …)``."""
    built = os.environ.get("SERVOSTUDIO_TEST_UI")
    return {"static_dir": Path(built)} if built else {}
