"""Simulated drive behaviour: CiA 402 device control, modes, loops and axis physics on one engine.

`make_behaviour(device, store, plant, events, commissioned)` builds the behaviour for a device key
("xtrapulspac", "cd1k", "encotrive"); see docs/sim-plant.md and docs/control-loops.md.
"""

from __future__ import annotations

from servostudio.sim.drive.behaviour import DriveBehaviour, Events
from servostudio.sim.drive.devices import DEVICE_PROFILES, make_behaviour

__all__ = ["DEVICE_PROFILES", "DriveBehaviour", "Events", "make_behaviour"]
