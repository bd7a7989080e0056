"""The four user levels and what writing each object of a drive's dictionary needs.

Gem Drive Studio protects "the drive parameter modification levels" with passwords and names Administrator the
highest level with full access (*Gem Drive Studio manual*, §2.2 "Starting the software"); it names no other level
and no level per object. Servo Studio's levels, from the lowest:

- Operator: views everything, uses the oscilloscope, reads through the terminal;
- Maintenance: + backup and restore, fault reset, the CiA 402 state (switching on to run a prepared sequence);
- Expert: + every parameter, phasing, tuning, motion, projects;
- Administrator: + users, the EDS library, firmware update, server settings.

The dictionaries carry no level per object either, so :data:`WRITE_RULES` decides from each entry's UI group and
save type (``docs/security.md`` has the table); the first rule that applies wins, and every other writable entry
needs Expert ("every parameter").
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass

from servostudio.drive.profiles.base import CIA402_OBJECTS
from servostudio.errors import Forbidden, InvalidInput
from servostudio.od.model import SaveType, Variable


class Level(enum.StrEnum):
    """A user level; members are listed from the lowest to the highest."""

    OPERATOR = "operator"
    MAINTENANCE = "maintenance"
    EXPERT = "expert"
    ADMINISTRATOR = "administrator"

    @property
    def rank(self) -> int:
        return list(Level).index(self)

    def at_least(self, required: Level) -> bool:
        return self.rank >= required.rank

    @classmethod
    def named(cls, text: str) -> Level:
        """The level a user typed (``--level expert``); anything else is refused naming the four."""
        try:
            return cls(text.strip().lower())
        except ValueError:
            raise UnknownLevel(f"unknown level {text!r}; use {', '.join(cls)}") from None


class UnknownLevel(InvalidInput):
    """A level name that is none of the four."""


class LevelTooLow(Forbidden):
    """The caller's level is below what the route, the message or the object needs."""


@dataclass(frozen=True)
class User:
    """Who is asking, as far as a request is concerned: a name for the logs and the level that decides."""

    name: str
    level: Level


#: the password-less single-user mode's one caller (opted in at setup, loopback only)
LOCAL_ADMINISTRATOR = User(name="local", level=Level.ADMINISTRATOR)


def require(user: User, level: Level, action: str) -> None:
    """Refuse ``action`` unless ``user`` has at least ``level``."""
    if not user.level.at_least(level):
        raise LevelTooLow(f"{action} needs the {level} level; {user.name} is {user.level}")


@dataclass(frozen=True)
class WriteRule:
    """One line of the object-level table: entries it applies to, the level they need, and why."""

    level: Level
    applies: Callable[[Variable], bool]
    why: str


def _is_controlword(var: Variable) -> bool:
    return (var.index, var.subindex) == CIA402_OBJECTS["controlword"]


WRITE_RULES: tuple[WriteRule, ...] = (
    WriteRule(
        Level.OPERATOR,
        lambda var: var.group == "Oscilloscope",
        "oscilloscope set-up (channels, trigger, depth): changes what is recorded, not what the drive does",
    ),
    WriteRule(
        Level.ADMINISTRATOR,
        lambda var: var.group == "Firmware Update",
        "firmware update: replaces the firmware the EDS library describes",
    ),
    WriteRule(
        Level.MAINTENANCE,
        _is_controlword,
        "the CiA 402 control word: switch on and off, fault reset, start a prepared sequence (whether the axis "
        "may move is the motion guard's decision)",
    ),
    WriteRule(
        Level.MAINTENANCE,
        lambda var: var.group == "Sequence Mode" and var.save_type is SaveType.NONE,
        "sequence inputs and the sequence table: what running a sequence selects, and what restoring "
        "SEQUENCE.TXT writes anyway",
    ),
)
#: every other writable entry: "Expert: every parameter"
DEFAULT_WRITE_LEVEL = Level.EXPERT


def write_level(var: Variable) -> Level | None:
    """The lowest level that may write this entry; None when nobody can (read-only, const)."""
    if not var.access.writable:
        return None
    return next((rule.level for rule in WRITE_RULES if rule.applies(var)), DEFAULT_WRITE_LEVEL)


def check_write(user: User, var: Variable) -> None:
    """Refuse a write the caller's level does not cover (a read-only entry is refused later, by the drive layer)."""
    level = write_level(var)
    if level is not None:
        require(user, level, f"writing {var.label}")
