"""Device families on the shared drive engine, and the factory the simulated node uses.

XtrapulsPac is the reference; CD1-k and encoTRive reuse the engine with their own object addresses, scalings,
error reporting and feature set (docs/devices.md).
"""

from __future__ import annotations

from servostudio.sim.drive.behaviour import DriveBehaviour, Events
from servostudio.sim.drive.cd1k import CD1K, Cd1kBehaviour
from servostudio.sim.drive.device_map import XTRAPULSPAC, DeviceProfile
from servostudio.sim.drive.encotrive import ENCOTRIVE, EncoTriveBehaviour
from servostudio.sim.objects import ObjectStore
from servostudio.sim.plant import Plant

DEVICE_PROFILES: dict[str, DeviceProfile] = {p.key: p for p in (XTRAPULSPAC, CD1K, ENCOTRIVE)}

_CLASSES: dict[str, type[DriveBehaviour]] = {
    "xtrapulspac": DriveBehaviour,
    "cd1k": Cd1kBehaviour,
    "encotrive": EncoTriveBehaviour,
}


def make_behaviour(device: str, store: ObjectStore, plant: Plant, events: Events, commissioned: bool) -> DriveBehaviour:
    """The behaviour of device key `device` ("xtrapulspac", "cd1k", "encotrive") on `store`."""
    try:
        profile = DEVICE_PROFILES[device]
    except KeyError:
        known = ", ".join(sorted(DEVICE_PROFILES))
        raise ValueError(f"no simulated behaviour for device {device!r} (known: {known})") from None
    return _CLASSES[device](store, plant, events, commissioned, profile)
