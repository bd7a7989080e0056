"""The speed loop's bandwidth of a simulated encoTRive on a given plant, measured from a step of the shaft's true
speed (the plant's, every control period, in this process), never from a tuning formula: what the tuning tests
judge a written inertia setting by."""

from __future__ import annotations

import cmath
import itertools
import math
from dataclasses import replace

from servostudio.od import builtin_library
from servostudio.sim.clock import CONTROL_PERIOD
from servostudio.sim.drive import make_behaviour
from servostudio.sim.objects import ObjectStore
from servostudio.sim.plant import Plant

RPM = 2 * math.pi / 60
#: the step: from BASE to BASE + STEP rpm, ramps far beyond the loop's (rpm/s)
BASE_RPM, STEP_RPM, RAMP = 15, 60, 10**7
RECORD_S = 0.4


class _Events:
    """The node's event sink, unused here."""

    flash_busy = False
    nmt_state = "OPERATIONAL"

    def emergency(self, *args: object) -> None:
        pass

    def emergency_cleared(self) -> None:
        pass


def encotrive_bandwidth(plant: Plant, inertia_setting_raw: int | None = None) -> float:
    """The −3 dB frequency of the closed speed loop with 0x2F02,8 = ``inertia_setting_raw`` (None: the factory's),
    from |DFT(Δω)| / step of the shaft's speed after a profile-velocity step."""
    free = {name: None for name in ("home_switch", "negative_limit_switch", "positive_limit_switch")}
    store = ObjectStore(builtin_library().load("encotrive"), 5)
    drive = make_behaviour("encotrive", store, replace(plant, **free, negative_hard_stop=None, positive_hard_stop=None),
                           _Events(), False)  # fmt: skip
    writes = {(0x60C5, 0): RAMP, (0x60C6, 0): RAMP, (0x6083, 0): RAMP, (0x6084, 0): RAMP, (0x6060, 0): 3}
    if inertia_setting_raw is not None:
        writes[0x2F02, 8] = inertia_setting_raw
    for (index, sub), value in writes.items():
        store.write_from_bus(index, sub, value)
    for word in (0x06, 0x07, 0x0F):
        store.write_from_bus(0x6040, 0, word)
        _run(drive, 0.01)
    store.write_from_bus(0x60FF, 0, BASE_RPM)
    _run(drive, 0.3)
    before = drive.physics.omega_motor
    store.write_from_bus(0x60FF, 0, BASE_RPM + STEP_RPM)
    speeds = [before]
    for _ in range(round(RECORD_S / CONTROL_PERIOD)):
        drive.step(CONTROL_PERIOD)
        speeds.append(drive.physics.omega_motor)
    return _bandwidth([b - a for a, b in itertools.pairwise(speeds)], STEP_RPM * RPM)


def _run(drive, seconds: float) -> None:
    for _ in range(round(seconds / CONTROL_PERIOD)):
        drive.step(CONTROL_PERIOD)


def _bandwidth(impulse: list[float], step: float) -> float:
    """The first frequency (1 Hz steps) where |Σ Δω·e^(−j2πft)| / step falls below 1/√2."""
    for frequency in range(1, 600):
        turn = -2j * math.pi * frequency * CONTROL_PERIOD
        if abs(sum(v * cmath.exp(turn * (n + 1)) for n, v in enumerate(impulse))) / step < 0.5**0.5:
            return float(frequency)
    return math.inf
