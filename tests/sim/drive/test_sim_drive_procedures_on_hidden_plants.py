"""The simulated drives' own procedures on hidden random plants (issue #13), driven the way a tool drives them:
motor data as from a datasheet, 'calc', 'apha', 'atun' — then judged against the plant's true values.

The speed-loop bandwidth is measured from a recorded response (a small velocity-reference step in PV, the shaft's
speed sampled every control period, its frequency response from the step's derivative), never from the formula.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import replace

import pytest

from servostudio.sim.clock import CONTROL_PERIOD
from servostudio.sim.drive import gains
from servostudio.sim.drive.procedures import signature
from servostudio.sim.plant import Plant

APHA, CALC, ATUN = (signature(s) for s in ("apha", "calc", "atun"))
USER_PER_REV = 4096
TWO_PI = 2 * math.pi


def datasheet_drive(harness, plant: Plant, device: str = "xtrapulspac"):
    """An uncommissioned drive with the motor's catalogue data written, then 'calc' (XtrapulsPac) — what a tool does."""
    h = harness(device, plant, commissioned=False)
    if device == "xtrapulspac":
        h.write(0x6410, 9, round(plant.stall_current * 1000))
        h.write(0x6410, 10, round(plant.peak_current * 1000))
        h.write(0x6410, 11, round(plant.torque_constant * 1000))
        h.write(0x6410, 13, round(plant.inductance * 1e4))
        h.write(0x3411, 0, CALC)
        assert h.read(0x3411) == 5
    return h


def run_procedure(h, trigger: tuple[int, int], timeout: float) -> int:
    h.write(*trigger, signature("apha") if trigger[0] in (0x3413, 0x3410) else ATUN)
    h.run_until(lambda: h.read(*trigger) != 2, timeout, step=0.05)
    return int(h.read(*trigger))


def two_mass(seed: int, ratio: float, resonance_hz: float) -> Plant:
    """The issue's elastic axis: load `ratio` × the motor inertia on a coupling resonating at `resonance_hz`."""
    plant = Plant.from_seed(seed)
    load = plant.motor_inertia * ratio
    reduced = plant.motor_inertia * load / (plant.motor_inertia + load)
    stiffness = reduced * (TWO_PI * resonance_hz) ** 2
    return replace(
        plant, load_inertia=load, coupling_stiffness=stiffness, coupling_damping=0.1 * math.sqrt(stiffness * reduced)
    )


def offset_degrees(identified: int, true: int) -> float:
    return abs((identified - true + 32768) % 65536 - 32768) * 360 / 65536


@pytest.mark.parametrize(
    "plant",
    [
        Plant.from_seed(3),
        Plant.from_seed(8),
        replace(Plant.from_seed(100), pole_pairs=1, load_inertia=Plant.from_seed(100).motor_inertia * 4),
        replace(Plant.from_seed(110), pole_pairs=2, load_inertia=Plant.from_seed(110).motor_inertia * 4),
        two_mass(102, 4.0, 215.0),
    ],
    ids=["seed3", "seed8", "pp1-load4x", "pp2-load4x", "two-mass"],
)
def test_auto_phasing_finds_the_commutation(harness, plant):
    h = datasheet_drive(harness, plant)
    assert run_procedure(h, (0x3413, 0), 40.0) == 5
    assert h.read(0x3410, 1) == plant.pole_pairs
    assert h.read(0x3410, 2) == plant.phase_order
    assert offset_degrees(h.read(0x3410, 3), plant.sensor_offset) < 2.0


@pytest.mark.parametrize(
    "plant",
    [
        Plant.from_seed(3),
        Plant.from_seed(11),
        Plant.from_seed(22),
        two_mass(101, 3.0, 200.0),
        two_mass(103, 5.0, 230.0),
        Plant.from_seed(15),
        Plant.from_seed(44),
        two_mass(201, 3.0, 60.0),
        two_mass(203, 5.0, 80.0),
        two_mass(205, 4.5, 100.0),
    ],
    ids=[
        "seed3",
        "seed11-heavy",
        "seed22-light",
        "two-mass-3x",
        "two-mass-5x",
        "seed15-63Hz-4.9x",
        "seed44-66Hz",
        "two-mass-60Hz",
        "two-mass-80Hz",
        "two-mass-100Hz",
    ],
)
def test_auto_tuning_identifies_the_plant_and_publishes_it(harness, plant):
    h = datasheet_drive(harness, plant)
    assert run_procedure(h, (0x3413, 0), 40.0) == 5
    assert [h.read(0x3428, s) for s in range(1, 6)] == [0.0] * 5  # nothing identified yet
    assert run_procedure(h, (0x3426, 0), 30.0) == 5
    inertia, viscous, coulomb, load, residual = (h.read(0x3428, s) for s in range(1, 6))
    assert inertia == pytest.approx(plant.total_inertia, rel=0.10)
    assert viscous == pytest.approx(plant.viscous_friction, rel=0.25)
    assert coulomb == pytest.approx(plant.coulomb_friction, rel=0.10)
    assert abs(load) < 0.05 * plant.coulomb_friction + 1e-3  # no constant load on these axes
    assert 0.0 <= residual < 0.05


def test_cd1k_tunes_itself_and_publishes_per_torque_constant(harness):
    """The CD1-k has no torque-constant object: it identifies per N·m/A (documented on 0x3428)."""
    plant = Plant.from_seed(5)
    h = datasheet_drive(harness, plant, "cd1k")
    h.write(0x6410, 2, plant.pole_pairs)  # commutation and current loop as VDSetup leaves them
    h.write(0x6410, 3, 0 if plant.phase_sign > 0 else 1)
    h.write(0x6410, 4, plant.sensor_offset)
    current = gains.current_loop_gains(plant.inductance, 0)
    for sub, value in enumerate((current.kp_q, current.ki_q, current.kp_d, current.ki_d), start=1):
        h.write(0x60F6, sub, value)
    h.write(0x3420, 1, 2)  # standard filter, high bandwidth
    assert run_procedure(h, (0x3420, 2), 30.0) == 5
    kt = plant.torque_constant
    assert h.read(0x3428, 1) * kt == pytest.approx(plant.total_inertia, rel=0.10)
    assert h.read(0x3428, 2) * kt == pytest.approx(plant.viscous_friction, rel=0.25)
    assert h.read(0x60F9, 1) > 0 and h.read(0x60F9, 2) > 0  # the gains it computed


def tuned(harness, plant: Plant, bandwidth_code: int, mode: int, requirement: int = 0, filter_type: int = 0):
    free = {name: None for name in ("home_switch", "negative_limit_switch", "positive_limit_switch")}
    h = datasheet_drive(harness, replace(plant, **free, negative_hard_stop=None, positive_hard_stop=None))
    for sub, value in ((1, plant.pole_pairs), (2, plant.phase_order), (3, plant.sensor_offset)):
        h.write(0x3410, sub, value)  # commutation entered by hand (auto-phasing has its own tests above)
    h.write(0x3425, 1, bandwidth_code)
    h.write(0x3425, 2, filter_type)
    h.write(0x3425, 4, requirement)
    h.write(0x6060, 0, mode)
    assert run_procedure(h, (0x3426, 0), 30.0) == 5
    return h


def speed_step_response(h, base: float, delta: float, seconds: float = 0.4) -> tuple[float, list[float]]:
    """The shaft's speed before, and every control period after, the PV reference steps by `delta` (rad/s)."""
    h.write(0x6083, 0, USER_PER_REV * 5000)
    h.write(0x6084, 0, USER_PER_REV * 5000)
    h.enable(3)
    unit = TWO_PI / USER_PER_REV
    h.write(0x60FF, 0, round(base / unit))
    h.run(0.3)
    before = []
    for _ in range(40):
        h.drive.step(CONTROL_PERIOD)
        before.append(h.drive.physics.omega_motor)
    h.write(0x60FF, 0, round(base / unit) + round(delta / unit))
    speeds = []
    for _ in range(round(seconds / CONTROL_PERIOD)):
        h.drive.step(CONTROL_PERIOD)
        speeds.append(h.drive.physics.omega_motor)
    return sum(before) / len(before), speeds


def frequency_response(speeds: list[float], before: float, step: float) -> list[tuple[float, float]]:
    """(f, |H(f)|) from 1 to 600 Hz, H(f) = Σ Δy·e^(−j2πft) / step: the step response's derivative is the impulse
    response, so its transform is the closed loop's frequency response."""
    previous = before
    impulse = []
    for value in speeds:
        impulse.append(value - previous)
        previous = value
    response = []
    frequency = 1.0
    while frequency < 600.0:
        turn = -2j * math.pi * frequency * CONTROL_PERIOD
        response.append((frequency, abs(sum(v * cmath.exp(turn * (n + 1)) for n, v in enumerate(impulse))) / step))
        frequency *= 1.02
    return response


def measured_response(h, base: float = 20.0) -> list[tuple[float, float]]:
    """Step the PV reference by a small amount (the current stays far from its limit) and transform the response."""
    delta = min(3.0, 0.3 * h.drive.max_current / h.drive.loops.kpv)
    before, speeds = speed_step_response(h, base, delta)
    unit = TWO_PI / USER_PER_REV
    return frequency_response(speeds, before, round(delta / unit) * unit)


def bandwidth_of(response: list[tuple[float, float]]) -> float:
    return next(f for f, gain in response if gain < 0.5**0.5)


@pytest.mark.parametrize(("seed", "code", "hz"), [(3, 0, 50.0), (8, 1, 75.0), (13, 2, 100.0), (21, 1, 75.0)])
def test_tuned_speed_loop_bandwidth_measured_on_the_simulator(harness, seed, code, hz):
    h = tuned(harness, Plant.from_seed(seed), code, 3)
    assert bandwidth_of(measured_response(h)) == pytest.approx(hz, rel=0.20)


def velocity_ripple(h, speed: float = 10.0) -> float:
    """Half the peak-to-peak shaft speed over 0.5 s of a slow PV move, relative to the set speed."""
    h.write(0x6083, 0, USER_PER_REV * 20)
    h.write(0x6084, 0, USER_PER_REV * 20)
    h.enable(3)
    h.write(0x60FF, 0, round(speed / (TWO_PI / USER_PER_REV)))
    h.run(0.8)
    speeds = []
    for _ in range(round(0.5 / CONTROL_PERIOD)):
        h.drive.step(CONTROL_PERIOD)
        speeds.append(h.drive.physics.omega_motor)
    return (max(speeds) - min(speeds)) / 2 / speed


@pytest.mark.parametrize(("seed", "ratio", "hz"), [(101, 3.0, 200.0), (102, 4.0, 215.0), (103, 5.0, 230.0)])
def test_anti_resonance_filter_on_a_two_mass_axis(harness, seed, ratio, hz):
    plant = two_mass(seed, ratio, hz)

    def resonance_peak(filter_type: int) -> float:
        response = measured_response(tuned(harness, plant, 1, 3, filter_type=filter_type))
        return max(gain for f, gain in response if 0.7 * hz <= f <= 2.0 * hz)

    standard, filtered = resonance_peak(0), resonance_peak(1)
    assert filtered < 1.0 and filtered < 0.4 * standard  # the resonance peak is attenuated
    h = tuned(harness, plant, 1, 3, filter_type=1)
    assert 0.4 * hz <= h.read(0x30F9, 1) <= 0.6 * hz  # placed from the resonance the drive identified
    assert velocity_ripple(h) < 0.05  # no sustained oscillation in a slow move


def test_minimum_overshoot_position_step(harness):
    h = tuned(harness, Plant.from_seed(8), 1, 1, requirement=1)
    h.write(0x6081, 0, USER_PER_REV * 20)
    h.write(0x6083, 0, USER_PER_REV * 1000)
    h.write(0x6084, 0, USER_PER_REV * 1000)
    h.enable(1)
    start = h.drive.physics.theta_motor
    target = h.read(0x6064) + USER_PER_REV // 4
    h.write(0x607A, 0, target)
    h.control(0x1F)
    peak = 0.0
    for _ in range(round(0.6 / CONTROL_PERIOD)):
        h.drive.step(CONTROL_PERIOD)
        peak = max(peak, h.drive.physics.theta_motor - start)
    travel = h.drive.physics.theta_motor - start
    assert travel == pytest.approx(TWO_PI / 4, rel=0.01)
    assert (peak - travel) / travel < 0.02


GAINS = [(0x60F9, sub) for sub in range(1, 9)] + [(0x60FB, sub) for sub in range(1, 6)] + [(0x30FA, 0)]


def vertical(seed: int) -> Plant:
    """A vertical axis: a constant load torque (gravity) of 30 % of the motor's stall torque, no switches."""
    plant = Plant.from_seed(seed)
    free = {name: None for name in ("home_switch", "negative_limit_switch", "positive_limit_switch")}
    gravity = round(0.3 * plant.torque_constant * plant.stall_current, 4)
    return replace(plant, **free, negative_hard_stop=None, positive_hard_stop=None, gravity_torque=gravity)


def commutated(harness, plant: Plant):
    h = datasheet_drive(harness, plant)
    for sub, value in ((1, plant.pole_pairs), (2, plant.phase_order), (3, plant.sensor_offset)):
        h.write(0x3410, sub, value)
    return h


@pytest.mark.parametrize("seed", [3, 8, 22])
def test_vertical_axis_is_tuned_enabled_at_standstill(harness, seed):
    """The manual's vertical-load procedure (§1.8.16): auto-tune the motor uncoupled, couple the load and hold it
    with those gains, then auto-tune enabled at standstill; the constant load torque is identified (0x3428,4 is the
    load's torque in the + direction: gravity pulls −) and the tuned axis holds its position."""
    plant = vertical(seed)
    motor = commutated(harness, replace(plant, load_inertia=0.0, coupling_stiffness=0.0, gravity_torque=0.0))
    motor.write(0x6060, 0, 1)
    assert run_procedure(motor, (0x3426, 0), 30.0) == 5
    h = commutated(harness, plant)
    for index, sub in GAINS:
        h.write(index, sub, motor.read(index, sub))
    h.enable(1)
    h.run(0.3)
    assert run_procedure(h, (0x3426, 0), 30.0) == 5
    inertia, viscous, coulomb, load = (h.read(0x3428, s) for s in range(1, 5))
    assert inertia == pytest.approx(plant.total_inertia, rel=0.10)
    assert viscous == pytest.approx(plant.viscous_friction, rel=0.25)
    assert coulomb == pytest.approx(plant.coulomb_friction, rel=0.10)
    assert load == pytest.approx(-plant.gravity_torque, rel=0.10)
    h.run(0.5)
    held = h.drive.physics.theta_motor
    h.run(0.5)
    assert h.status & 0x6F == 0x27
    assert abs(h.drive.physics.theta_motor - held) < 0.01  # rad: the load does not sink
