"""The signature-started procedures of a device family (phasing, current loop, auto-tuning), keyed by semantic names.

The procedure service (``services.procedures``) asks a profile for ``"auto_tuning"`` and gets the trigger object, the
signature that starts it, the options and the codes of their values, what it needs before it may start, and the
objects it changes; it never sees 0x3426 or 0x3425,1. A new drive family describes its own procedures here.

Status read back from every trigger (docs/control-loops.md §5): 0 never executed, 1 cannot execute, 2 running,
3 aborted, 4 stopped on error, 5 done.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

#: the read-back status codes of a trigger object, by their API names (index = code)
STATUSES = ("never", "cannot", "running", "aborted", "error", "done")

#: the precondition checks a procedure may list (``services.procedures.preconditions`` implements each)
CHECKS = (
    "disabled",
    "disabled_or_standstill",
    "no_fault",
    "no_limit_switch",
    "dc_bus",
    "brake_released",
    "not_running",
)


@dataclass(frozen=True)
class OptionCodes:
    """One option of a procedure: the object it is written to and the raw code of each value. Options that share an
    object add their codes (the CD1-k's 0x3420,1 holds 3 × filter + bandwidth)."""

    object: str
    codes: Mapping[str, int]


@dataclass(frozen=True)
class ProcedureDescription:
    """One procedure of a drive family, by semantic names."""

    label: str
    #: the trigger object: the signature written to it starts the procedure, 0 aborts it, reading it gives the status
    trigger: str
    signature: str
    #: the procedure turns the motor by itself (the motion guard's ``moving_procedures`` say so too)
    moves: bool
    #: checks of ``CHECKS`` made before the start, each refused with the manual's reason
    preconditions: tuple[str, ...]
    #: values the procedure needs non-zero and in range (motor data, currents)
    inputs: tuple[str, ...] = ()
    options: Mapping[str, OptionCodes] = field(default_factory=dict)
    #: options given as a physical value, written to an object before the start (the inductance for 'calc')
    values: Mapping[str, str] = field(default_factory=dict)
    #: the objects it writes, whose values before and after the result shows (and an abort restores)
    results: tuple[str, ...] = ()
    #: the current limits it sets (current-loop calculation), shown apart from the gains
    limits: tuple[str, ...] = ()
    #: the mode of operation it runs in (auto-tuning in a position mode computes the position gains too); None: any
    mode: int | None = None
    #: how long it usually runs (progress fraction) and when the tool gives up on it (abort, failure)
    duration_s: float = 1.0
    timeout_s: float = 30.0


@dataclass(frozen=True)
class UserUnits:
    """How many user position units one motor revolution is: ``increments`` (a count, or the semantic name of the
    object that holds it) × ``denominator`` / ``numerator`` when the drive has a factor group."""

    increments: int | str
    numerator: str | None = None
    denominator: str | None = None


@dataclass(frozen=True)
class ProcedureSet:
    """Every procedure of a drive family, and what the service needs besides them."""

    procedures: Mapping[str, ProcedureDescription]
    units: UserUnits = UserUnits(4096)
    #: identified-plant objects the drive publishes after auto-tuning (0x3428), by the result key they fill
    identified: Mapping[str, str] = field(default_factory=dict)
    #: the drive knows no torque constant and publishes its plant per N·m/A of it, in amperes (J/Kt, B/Kt, …: the
    #: simulated CD1-k, whose manual has no torque-constant object)
    identified_per_ampere: bool = False
    #: the motor's own inertia (motor data) for the inertia ratio; None: the drive has no such object
    motor_inertia: str | None = None
    #: the motor's torque constant (motor data), for the size of the verification step
    torque_constant: str | None = None
    #: first-order filter of the measured speed (Hz) that the verification takes out of its recorded response
    speed_monitor_filter: str | None = None
    #: the speed loop's own filter of the measured speed (a code), and each code's time constant in s: the recorded
    #: speed is the loop's filtered one, the bandwidth is the shaft's, so the verification takes it out too
    speed_measurement_filter: str | None = None
    speed_measurement_filter_s: Mapping[int, float] = field(default_factory=dict)
    #: the objects a verification move changes (mode, target, ramps), restored after it
    verification_objects: tuple[str, ...] = ()

    def get(self, name: str) -> ProcedureDescription | None:
        return self.procedures.get(name)


NO_PROCEDURES = ProcedureSet({})

#: what every auto-phasing result names, by result key (the profile's objects of the same names)
PHASING_RESULTS = ("pole_pairs", "phase_order", "sensor_offset")
#: identified-plant result keys → the semantic names of the 0x3428 sub-objects (contract of issue #13)
IDENTIFIED_PLANT = {
    "inertia_kgm2": "identified_inertia",
    "viscous_friction_nms_per_rad": "identified_viscous_friction",
    "coulomb_friction_nm": "identified_coulomb_friction",
    "load_torque_nm": "identified_load_torque",
    "residual": "identified_residual",
}
IDENTIFIED_PLANT_OBJECTS = {name: (0x3428, sub) for sub, name in enumerate(IDENTIFIED_PLANT.values(), start=1)}


def phasing_procedures(checks: tuple[str, ...], currents: tuple[str, ...]) -> dict[str, ProcedureDescription]:
    """Auto-phasing (``apha``) and motor phasing (``mcal``) as the Infranor drives share them: the same objects and
    results; a drive differs only in the checks before the start and the current inputs its motor data has."""
    return {
        "auto_phasing": ProcedureDescription(
            "Auto-phasing", "auto_phasing", "apha", moves=True, preconditions=checks, inputs=currents,
            results=PHASING_RESULTS, duration_s=8.0, timeout_s=90.0,
        ),
        "motor_phasing": ProcedureDescription(
            "Motor phasing", "motor_phasing", "mcal", moves=True, preconditions=checks,
            inputs=(*currents, "pole_pairs"), results=("sensor_offset",), duration_s=2.0, timeout_s=60.0,
        ),
    }  # fmt: skip
