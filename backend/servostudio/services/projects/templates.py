"""Device Config application templates (manual §2.4.1, L492-499).

A template sets the operating mode and the I/O functions of a standard application in the project's values and
names the parameter groups the UI shows for it; Expert mode sets nothing and shows every group.

The "XtrapulsPac Templates" manual the user guide refers to is not available. Each setting below is therefore taken
from the user guide itself (mode values, the I/O routing format ``index<<16 | sub<<8 | bit`` of 0x3050/0x3054, and
its configuration examples), with the line it comes from; where the guide only describes a function and not its
wiring, the choice of input/output is the project's and is marked so (see docs/projects.md).
"""

from __future__ import annotations

from dataclasses import dataclass

from servostudio.services.projects.errors import ProjectNotFound


@dataclass(frozen=True)
class Setting:
    index: int
    sub: int
    value: int
    why: str


@dataclass(frozen=True)
class ApplicationTemplate:
    key: str
    title: str
    description: str
    devices: tuple[str, ...]
    settings: tuple[Setting, ...]
    groups: tuple[str, ...] | None  # UI groups to show; None = all (Expert mode)


_COMMON_GROUPS = (
    "Communication",
    "General",
    "Device Control",
    "Motor",
    "Sensors",
    "Servo Loops",
    "Auto-tuning",
    "Error Control",
    "Application Features",
)

TEMPLATES: tuple[ApplicationTemplate, ...] = (
    ApplicationTemplate(
        key="analog-speed",
        title="Analog speed drive",
        description="±10 V speed reference on analog input 1 with A/B/Z encoder emulation output",
        devices=("xtrapulspac",),
        settings=(
            Setting(0x6060, 0, -1, "mode Analog Speed (L8308-8359, L11516-11571)"),
            Setting(0x3050, 1, 0x60FD0003, "IN1 -> INHIBIT, the manual's 'ENABLE input on IN1' example (L12755ff)"),
            Setting(0x3051, 0, 0x0001, "IN1 inverted: losing 24 V inhibits the drive (same example)"),
            Setting(0x3160, 1, 0x31000400, "encoder emulation source: resolver position (L13484-13655 example)"),
            Setting(0x3160, 3, 1024, "encoder emulation resolution 1024 ppr (same example)"),
            Setting(0x3160, 6, 0x0E03, "encoder emulation on, A/B/Z lines as outputs (same example)"),
        ),
        groups=(*_COMMON_GROUPS, "Analog Speed Mode"),
    ),
    ApplicationTemplate(
        key="positioner",
        title="Stand-alone positioner",
        description="Motion sequences selected and started by logic inputs (Sequence mode)",
        devices=("xtrapulspac",),
        settings=(
            Setting(0x6060, 0, -3, "mode Sequence (L8308-8359, L9660ff)"),
            Setting(0x3050, 1, 0x36010100, "IN1 -> SEQ SEL 1 = bit 0 of sequence number 0x3601,1 (project choice)"),
            Setting(0x3050, 2, 0x36010101, "IN2 -> SEQ SEL 2 = bit 1 of 0x3601,1 (project choice)"),
            Setting(0x3050, 3, 0x36010102, "IN3 -> SEQ SEL 3 = bit 2 of 0x3601,1 (project choice)"),
            Setting(0x3050, 4, 0x36010103, "IN4 -> SEQ SEL 4 = bit 3 of 0x3601,1 (project choice)"),
            Setting(
                0x3050,
                5,
                0x60400004,
                "IN5 -> SEQ START = control word bit 4 (rising edge starts, L9697-9702; input choice is the project's)",
            ),
            Setting(0x3054, 1, 0x6041000A, "OUT1 <- IN POS = status word bit 10 target reached (project choice)"),
        ),
        groups=(*_COMMON_GROUPS, "Factor", "Position Control", "Profile Position Mode", "Homing Mode", "Sequence Mode"),
    ),
    ApplicationTemplate(
        key="stepper-emulation",
        title="Stepper emulation",
        description="The motor follows PULSE/DIR inputs like a stepper motor",
        devices=("xtrapulspac",),
        settings=(
            Setting(0x6060, 0, -2, "mode Stepper Emulation (L8308-8359, L11282-11514)"),
            Setting(
                0x3681,
                3,
                0x013A,
                "PULSE/DIR on the Hall lines, both polarities inverted, counting enabled "
                "(the manual's configuration example, L11496-11514)",
            ),
            Setting(0x3681, 4, 10, "PULSE_CNT timeout 10 ms (same example)"),
            Setting(0x3054, 3, 0x36810201, "OUT3 <- PULSE_CNT (same example)"),
        ),
        groups=(*_COMMON_GROUPS, "Factor", "Position Control", "Stepper Emulation Mode"),
    ),
    ApplicationTemplate(
        key="expert",
        title="Expert mode",
        description="Full parameter set and every operating mode; sets nothing",
        devices=(),
        settings=(),
        groups=None,
    ),
)


def templates_for(device: str) -> list[ApplicationTemplate]:
    return [template for template in TEMPLATES if not template.devices or device in template.devices]


def template(key: str, device: str) -> ApplicationTemplate:
    for candidate in templates_for(device):
        if candidate.key == key:
            return candidate
    known = ", ".join(t.key for t in templates_for(device))
    raise ProjectNotFound(f"no Device Config template '{key}' for device '{device}' (available: {known})")
