"""Suite-wide set-up: the shared fixture modules of `tests/support/` and the interpreter's thread switch interval.

The fixtures live in importable modules (not in folder conftests) because the test folders mirror the package:
the simulated drives over socketcand, for example, serve the drive, services, API and CLI folders alike.
Folder-specific fixtures stay in the conftest of their folder.
"""

from __future__ import annotations

import sys

import pytest

pytest_plugins = [
    "tests.support.canopen_peers",
    "tests.support.embedded_sim",
    "tests.support.live_server",
    "tests.support.sim_endpoints",
]


@pytest.fixture(autouse=True, scope="session")
def short_switch_interval():
    """The simulated drives, the bus reader, the socket threads and the test share one interpreter: a short GIL
    switch interval keeps each hand-over (and so every SDO round trip) at a fraction of a millisecond instead of
    5 ms. One setting for the whole session (the suite always ran under it once the live project fixtures were
    collected); the interpreter's setting is restored afterwards."""
    previous = sys.getswitchinterval()
    sys.setswitchinterval(0.0002)
    yield
    sys.setswitchinterval(previous)
