"""The quick test's limits: small by default, raised by the user per axis, checked before anything is written.

A jog or move asked for above them is refused (``LimitExceeded``, invalid input) before a frame goes to the drive.
They live in the server's memory per axis, so a restart brings the small defaults back: raising them is a
decision for the session at hand, not a setting that outlives it.
"""

from __future__ import annotations

import math
import threading
from dataclasses import asdict, dataclass, replace

from servostudio.errors import InvalidInput
from servostudio.services.motion.control import Axis, where

#: the defaults: slow (300 rpm), short (one revolution per move), brief (a 10 s jog)
DEFAULT_VELOCITY_RPM = 300.0
DEFAULT_DISTANCE_REVOLUTIONS = 1.0
DEFAULT_SECONDS = 10.0
#: what a user may raise them to at most (the drive's own limits still apply)
CEILING = {"velocity_rpm": 6000.0, "distance_revolutions": 10_000.0, "seconds": 600.0}


class LimitExceeded(InvalidInput):
    """A jog, move or homing asked for more than the axis's quick-test limits allow."""


@dataclass(frozen=True)
class MotionLimits:
    velocity_rpm: float = DEFAULT_VELOCITY_RPM
    distance_revolutions: float = DEFAULT_DISTANCE_REVOLUTIONS
    seconds: float = DEFAULT_SECONDS

    def as_dict(self) -> dict[str, float]:
        return asdict(self)

    def check_velocity(self, axis: Axis, rpm: float) -> None:
        if not math.isfinite(rpm) or abs(rpm) > self.velocity_rpm:
            raise LimitExceeded(
                f"{where(axis)}: {rpm} rpm is above the quick test's limit of {self._raise('velocity_rpm')}"
            )

    def check_distance(self, axis: Axis, revolutions: float) -> None:
        if not math.isfinite(revolutions) or abs(revolutions) > self.distance_revolutions:
            raise LimitExceeded(
                f"{where(axis)}: a move of {abs(revolutions):.4g} revolutions is above the quick test's limit of "
                f"{self._raise('distance_revolutions')}"
            )

    def check_seconds(self, axis: Axis, seconds: float) -> None:
        if not math.isfinite(seconds) or not 0 < seconds <= self.seconds:
            raise LimitExceeded(f"{where(axis)}: a jog of {seconds} s is outside 0 < s ≤ {self._raise('seconds')}")

    def _raise(self, name: str) -> str:
        return f"{getattr(self, name):g} ({name}; raise it with PUT …/motion/limits)"


class LimitStore:
    """Each axis's limits (the defaults until a user raises them)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._limits: dict[Axis, MotionLimits] = {}

    def of(self, axis: Axis) -> MotionLimits:
        with self._lock:
            return self._limits.get(axis, MotionLimits())

    def set(self, axis: Axis, **values: float | None) -> MotionLimits:
        """Change some limits (None: keep); each must be positive and at most its ``CEILING``."""
        given = {name: float(value) for name, value in values.items() if value is not None}
        for name, value in given.items():
            if name not in CEILING:
                raise LimitExceeded(f"no quick-test limit {name!r}; there are {', '.join(CEILING)}")
            if not math.isfinite(value) or not 0 < value <= CEILING[name]:
                raise LimitExceeded(f"{name} = {value:g} is outside 0 < value ≤ {CEILING[name]:g}")
        with self._lock:
            changed = replace(self._limits.get(axis, MotionLimits()), **given)
            self._limits[axis] = changed
            return changed
