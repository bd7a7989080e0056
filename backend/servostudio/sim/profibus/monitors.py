"""The read-only PNUs a simulated TTA-PRO computes when the PKW channel or a mapped PZD reads them: positions,
speed and current monitors, inputs, error and warning codes, the DC bus (TTA-PRO Profibus Communication Profile,
Chapter 3, L1763-1868, L2637-2646, L3149-3160)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from servostudio.sim.profibus.drive_units import TWO_PI

if TYPE_CHECKING:
    from servostudio.sim.profibus.positioner import TtaProDrive

DC_BUS_FULL = 4096 / 100.0
"""PNU 706 / signal 0x12C2: 0x1000 = 100 V."""
RESOLVER_COUNTS = 65536
SOFTWARE_LIMIT_PLUS, SOFTWARE_LIMIT_MINUS = 1 << 0, 1 << 1
HARDWARE_LIMIT_PLUS, HARDWARE_LIMIT_MINUS, INDEX, ENABLE = 1 << 4, 1 << 5, 1 << 6, 1 << 8


def register_monitors(drive: TtaProDrive) -> None:
    memory, axis, units, faults = drive.memory, drive.axis, drive.units, drive.faults
    hooks = {
        774: lambda _: units.position(axis.position),
        845: lambda _: units.position(axis.position),
        846: lambda _: 0,
        749: lambda _: position_error(drive),
        775: lambda _: round(axis.position / TWO_PI * RESOLVER_COUNTS) % RESOLVER_COUNTS,
        776: lambda _: units.share(units.direction * axis.speed, units.max_speed),
        777: lambda _: units.share(units.direction * axis.loops.i_q, units.rating),
        769: lambda _: logic_inputs(drive),
        773: lambda _: faults.positioner_error_code(),
        778: lambda _: faults.power_stage_code(),
        755: lambda _: faults.drive_error_code(),
        873: lambda _: faults.warnings,
        706: lambda _: round(axis.physics.dc_bus * DC_BUS_FULL),
        897: lambda _: 1,
    }
    for pnu, hook in hooks.items():
        memory.on_read(pnu, hook)


def position_error(drive: TtaProDrive) -> int:
    """Set point minus measured position, in position increments (0 while no position loop runs)."""
    loops = drive.axis.loops
    if not drive.powered:
        return 0
    return round(
        drive.units.direction * (loops.position_ref - loops.position) / TWO_PI * drive.units.increments_per_turn
    )


def logic_inputs(drive: TtaProDrive) -> int:
    """PNU 769."""
    physics = drive.axis.physics
    flags = (
        (drive.software_limit and drive.units.direction * drive.axis.speed >= 0, SOFTWARE_LIMIT_PLUS),
        (drive.software_limit and drive.units.direction * drive.axis.speed < 0, SOFTWARE_LIMIT_MINUS),
        (physics.positive_limit_active(), HARDWARE_LIMIT_PLUS),
        (physics.negative_limit_active(), HARDWARE_LIMIT_MINUS),
        (physics.index_seen, INDEX),
        (drive.enable_input, ENABLE),
    )
    return sum(bit for active, bit in flags if active)
