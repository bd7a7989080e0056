"""Named capture definitions for the recordings tuning asks for most (the manual sends the engineer to the
oscilloscope for each): a speed step, the following error of a move, the current loop, the timing of the I/O.

Channels are CiA 402 objects, so a preset works for every drive with a recorder whose dictionary has them; one
that lacks an object is not offered for that drive (``presets_for``).
"""

from __future__ import annotations

from dataclasses import dataclass

from servostudio.drive.access import Drive
from servostudio.errors import InvalidInput, NotFound
from servostudio.services.scope.definition import CaptureDefinition, Trigger


@dataclass(frozen=True)
class Preset:
    key: str
    title: str
    description: str
    definition: CaptureDefinition


#: key, title, what it shows; channels; period in µs; trigger source and edge (level 1); pre-trigger in %
_TABLE = (
    ("speed-step", "Speed step",
     "Target velocity, velocity, current and status word around a step of the target velocity (profile velocity "
     "mode): rise time, overshoot and settling of the speed loop.",
     ("0x60FF,0", "0x606C,0", "0x6078,0", "0x6041,0"), 250, ("0x60FF,0", "either"), 20),
    ("following-error", "Following error",
     "Position demand, actual position, following error and velocity over a move, from its start: the "
     "following-error threshold and the position loop.",
     ("0x6062,0", "0x6064,0", "0x60F4,0", "0x606C,0"), 1000, ("0x606B,0", "either"), 10),
    ("current-loop", "Current loop",
     "Target torque, torque demand, torque and current at the control rate around a torque step: the current "
     "loop's response and noise.",
     ("0x6071,0", "0x6074,0", "0x6077,0", "0x6078,0"), 250, ("0x6071,0", "either"), 10),
    ("io-timing", "I/O timing",
     "Digital inputs and outputs, status word and velocity around the first input that switches on: the delay "
     "between an input and the drive's answer.",
     ("0x60FD,0", "0x60FE,1", "0x6041,0", "0x606C,0"), 250, ("0x60FD,0", "rising"), 50),
)  # fmt: skip

PRESETS: tuple[Preset, ...] = tuple(
    Preset(key, title, description, CaptureDefinition(
        channels=channels, period_us=period_us, samples=2048, trigger=Trigger(source, edge, 1), pre_trigger_pct=pre,
    ))
    for key, title, description, channels, period_us, (source, edge), pre in _TABLE
)  # fmt: skip


class UnknownPreset(NotFound):
    """No preset of that name."""


def preset(key: str) -> Preset:
    for candidate in PRESETS:
        if candidate.key == key:
            return candidate
    raise UnknownPreset(f"no capture preset {key!r}; presets: {', '.join(item.key for item in PRESETS)}")


def presets_for(drive: Drive) -> list[Preset]:
    """The presets whose every object the drive's dictionary has."""
    return [item for item in PRESETS if _resolves(drive, item.definition)]


def _resolves(drive: Drive, definition: CaptureDefinition) -> bool:
    keys = [*definition.channels, *([definition.trigger.source] if definition.trigger.source else [])]
    try:
        for key in keys:
            drive.variable(key)
    except InvalidInput:
        return False
    return True
