"""What the frequency-response tests judge against: the hidden plant's truth — its free-running form (no switches,
no hard stops), its true 1/(J·s + B) at a measured point, the closed speed loop's bandwidth from a step on the
simulated drive itself."""

from __future__ import annotations

import cmath
import math
from dataclasses import replace

from servostudio.od import builtin_library
from servostudio.sim.clock import CONTROL_PERIOD
from servostudio.sim.drive import make_behaviour
from servostudio.sim.objects import ObjectStore
from servostudio.sim.plant import Plant

TWO_PI = 2.0 * math.pi
USER_PER_REV = 4096


def free(plant: Plant) -> Plant:
    """No switches or hard stops: the base speed carries the axis several revolutions."""
    switches = {name: None for name in ("home_switch", "negative_limit_switch", "positive_limit_switch")}
    return replace(plant, **switches, negative_hard_stop=None, positive_hard_stop=None)


def plant_error(point: dict, plant: Plant) -> tuple[float, float]:
    """(dB, degrees) of the measured point against the true 1/(J·s + B), one control period taken out."""
    omega = TWO_PI * point["freq_hz"]
    true = cmath.exp(1j * omega * CONTROL_PERIOD) / (plant.total_inertia * 1j * omega + plant.viscous_friction)
    magnitude = point["magnitude_db"] - 20.0 * math.log10(abs(true))
    phase = (point["phase_deg"] - math.degrees(cmath.phase(true)) + 180.0) % 360.0 - 180.0
    return magnitude, phase


def step_bandwidth(
    plant: Plant, base: float = 15.0, delta: float = 2.0, device: str = "xtrapulspac", per_rev: int = USER_PER_REV
) -> float:
    """The closed speed loop's −3 dB bandwidth from a PV step on the simulated ``device`` (``per_rev`` position
    units per revolution): the shaft's speed every control period, H(f) = DFT of the step response's derivative /
    step (its impulse response's transform)."""
    store = ObjectStore(builtin_library().load(device), 1)

    class Events:
        flash_busy = False
        nmt_state = "OPERATIONAL"

        def emergency(self, *args: object) -> None: ...

        def emergency_cleared(self) -> None: ...

    drive = make_behaviour(device, store, free(plant), Events(), True)
    unit = TWO_PI / per_rev
    for index, value in ((0x6083, per_rev * 5000), (0x6084, per_rev * 5000), (0x6060, 3)):
        store.write_from_bus(index, 0, value)
    for word in (0x06, 0x07, 0x0F):
        store.write_from_bus(0x6040, 0, word)
        for _ in range(40):
            drive.step(CONTROL_PERIOD)
    store.write_from_bus(0x60FF, 0, round(base / unit))
    for _ in range(round(0.4 / CONTROL_PERIOD)):
        drive.step(CONTROL_PERIOD)
    before = drive.physics.omega_motor
    step = round(delta / unit)
    store.write_from_bus(0x60FF, 0, round(base / unit) + step)
    speeds = []
    for _ in range(round(0.4 / CONTROL_PERIOD)):
        drive.step(CONTROL_PERIOD)
        speeds.append(drive.physics.omega_motor)
    impulse = [b - a for a, b in zip([before, *speeds], speeds, strict=False)]
    frequency = 1.0
    while frequency < 600.0:
        turn = -2j * math.pi * frequency * CONTROL_PERIOD
        gain = abs(sum(v * cmath.exp(turn * (n + 1)) for n, v in enumerate(impulse))) / (step * unit)
        if gain < 0.5**0.5:
            return frequency
        frequency *= 1.01
    raise AssertionError("no −3 dB point below 600 Hz")
