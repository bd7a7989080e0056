"""What a user asks of a capture, as the user says it: channels by name or address, period in µs, depth in samples or
as a duration, a trigger level in the source's physical unit.

Nothing here knows a drive: ``plan.py`` checks a definition against one drive's dictionary and recorder and turns it
into raw recorder settings, or refuses it with the reason before anything is written.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from typing import Any

from servostudio.errors import InvalidInput

EDGES = ("rising", "falling", "either")
MODES = ("single", "normal", "auto")
#: how the samples are taken: the drive's recorder, synchronous TPDOs at the server's SYNC, SDO polling; ``auto``
#: picks the first the capture allows (the recorder for one drive that has one, else TPDOs, else polling)
SOURCES = ("auto", "recorder", "tpdo", "poll")
#: a channel of another axis of the bus: ``0x606C,0@2`` (the object, then its node)
NODE_SEPARATOR = "@"
DEFAULT_PERIOD_US = 250.0
DEFAULT_SAMPLES = 2048


class DefinitionError(InvalidInput):
    """A capture definition that is malformed in itself (before any drive is asked)."""


@dataclass(frozen=True)
class Trigger:
    """When the recording starts: ``source`` (an object, or one of the channels) crossing ``level`` (in the source's
    unit) with ``edge``; no source means immediate (record from the arm)."""

    source: str | None = None
    edge: str = "rising"
    level: float = 0.0

    def __post_init__(self) -> None:
        if self.edge not in EDGES:
            raise DefinitionError(f"trigger edge {self.edge!r}: use one of {', '.join(EDGES)}")

    @property
    def immediate(self) -> bool:
        return self.source is None

    def describe(self, unit: str = "") -> str:
        """How the CSV and the page name the trigger: ``0x606C,0 rising 20480 user unit/s`` or ``immediate``."""
        if self.source is None:
            return "immediate"
        return " ".join(part for part in (self.source, self.edge, number_text(self.level), unit) if part)


@dataclass(frozen=True)
class CaptureDefinition:
    """One capture as asked for; ``samples`` or ``duration_s`` gives the depth (samples wins when both are given)."""

    channels: tuple[str, ...]
    period_us: float = DEFAULT_PERIOD_US
    samples: int | None = None
    duration_s: float | None = None
    trigger: Trigger = field(default_factory=Trigger)
    pre_trigger_pct: float = 0.0
    mode: str = "single"
    auto_timeout_ms: int = 100
    #: seconds to wait for the recording to complete (None: until stopped)
    timeout_s: float | None = None
    source: str = "auto"

    def __post_init__(self) -> None:
        if not self.channels:
            raise DefinitionError("a capture needs at least one channel")
        if self.mode not in MODES:
            raise DefinitionError(f"mode {self.mode!r}: use one of {', '.join(MODES)}")
        if not 0 <= self.pre_trigger_pct <= 100:
            raise DefinitionError(f"pre-trigger {number_text(self.pre_trigger_pct)} %: use 0..100 %")
        if self.source not in SOURCES:
            raise DefinitionError(f"source {self.source!r}: use one of {', '.join(SOURCES)}")
        for channel in self.channels:
            split_channel(channel)
        if self.timeout_s is not None and self.timeout_s <= 0:
            raise DefinitionError(f"timeout {number_text(self.timeout_s)} s: use a positive number of seconds")

    def as_dict(self) -> dict[str, Any]:
        shown = asdict(self)
        shown["channels"] = list(self.channels)
        return shown

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> CaptureDefinition:
        """The definition a sidecar or a request holds (unknown keys are refused: a typo must not pass silently)."""
        known = set(cls.__dataclass_fields__)
        unknown = sorted(set(data) - known)
        if unknown:
            raise DefinitionError(f"unknown capture definition keys: {', '.join(unknown)}")
        values = dict(data)
        values["channels"] = tuple(values.get("channels", ()))
        trigger = values.get("trigger") or {}
        values["trigger"] = trigger if isinstance(trigger, Trigger) else Trigger(**trigger)
        try:
            return cls(**values)
        except TypeError as error:
            raise DefinitionError(f"capture definition: {error}") from None


def split_channel(text: str) -> tuple[str, int | None]:
    """A channel as (object, node): ``0x606C,0@2`` → ("0x606C,0", 2); without ``@`` the capture's own node (None)."""
    name, separator, node = text.rpartition(NODE_SEPARATOR)
    if not separator:
        return text, None
    if not name.strip() or not node.strip().isdigit() or not 1 <= int(node) <= 127:
        raise DefinitionError(f"channel {text!r}: write OBJECT@NODE with a node 1..127, e.g. 0x606C,0@2")
    return name.strip(), int(node)


def parse_trigger(text: str) -> Trigger:
    """The CLI's ``OBJ:rising|falling|either:LEVEL`` (``0x606C,0:rising:20480``; OBJ may hold a colon itself,
    ``60FF:0``, so the edge and level are the last two fields)."""
    parts = text.rsplit(":", 2)
    if len(parts) != 3 or not parts[0].strip():
        raise DefinitionError(f"trigger {text!r}: write OBJECT:rising|falling|either:LEVEL, e.g. 0x606C,0:rising:100")
    source, edge, level = (part.strip() for part in parts)
    try:
        value = float(level)
    except ValueError:
        raise DefinitionError(f"trigger {text!r}: level {level!r} is not a number") from None
    return Trigger(source, edge.lower(), value)


def number_text(value: float) -> str:
    """A number as a person writes it: 20480, not 20480.0."""
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def fixed_point_text(value: int, decimals: int) -> str:
    """An integer count of 10^-decimals units, exactly: (-20000000, 9) → ``-0.02``, (250000, 3) → ``250``."""
    whole, fraction = divmod(abs(value), 10**decimals)
    text = f"{whole}.{fraction:0{decimals}d}".rstrip("0").rstrip(".")
    return f"-{text}" if value < 0 else text
