"""Behaviour-level harness of the simulated drive (``tests/support/drive_harness.py``); integration over CAN is
tested in tests/sim/comms."""

from __future__ import annotations

import pytest
from tests.support.drive_harness import Harness

from servostudio.sim.plant import Plant


@pytest.fixture
def harness():
    """Factory: harness(device="xtrapulspac", plant=None, commissioned=True)."""

    def build(device: str = "xtrapulspac", plant: Plant | None = None, commissioned: bool = True) -> Harness:
        return Harness(device, plant or Plant.commissioned(), commissioned)

    return build
