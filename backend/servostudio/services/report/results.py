"""Reading the saved procedure results as the report needs them: which procedure a file is, the newest of a kind,
the labels of the semantic names they are keyed by (from the axis's device profile and dictionary)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from servostudio.drive.profiles import profile_for
from servostudio.od import ObjectDictionary

PHASING = ("auto_phasing", "motor_phasing")
TUNING = ("auto_tuning", "identification", "current_loop", "current_limits")
#: keys of a saved result that are about the run, not values the procedure found
META = frozenset(
    {"procedure", "kind", "status", "before", "options", "saved", "verification", "file", "saved_at", "gains",
     "limits", "identified", "user", "time", "error", "node", "device", "axis", "reason", "aborted"}
)  # fmt: skip
LABELS = {
    "auto_phasing": "Auto-phasing (drive)",
    "motor_phasing": "Motor phasing (drive)",
    "current_loop": "Current-loop calculation (drive)",
    "current_limits": "Current limits (drive)",
    "auto_tuning": "Auto-tuning (drive)",
    "identification": "Identification (tool)",
}


def procedure(result: Mapping[str, Any]) -> str:
    """The procedure a saved result is of: its ``procedure`` or ``kind``, else its file name's prefix."""
    named = result.get("procedure") or result.get("kind")
    if isinstance(named, str) and named:
        return named
    return str(result.get("file", "")).rsplit("-", 1)[0]


def label(result: Mapping[str, Any]) -> str:
    name = procedure(result)
    return LABELS.get(name, name.replace("_", " "))


def of(results: Iterable[Mapping[str, Any]], names: Iterable[str]) -> list[Mapping[str, Any]]:
    """The results of these procedures, newest first (as the store lists them)."""
    wanted = set(names)
    return [result for result in results if procedure(result) in wanted]


def done(results: Iterable[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    return [result for result in results if result.get("status") == "done"]


def when(result: Mapping[str, Any]) -> str:
    return str(result.get("saved_at") or "time not recorded")


def who(result: Mapping[str, Any]) -> str:
    user = result.get("user")
    return str(user) if user else "not recorded in the result"


class Names:
    """The dictionary label of a semantic name of the axis's device profile (``kp_speed`` → ``0x30F2,1 …``)."""

    def __init__(self, device: str, dictionary: ObjectDictionary | None) -> None:
        self.profile = profile_for(device)
        self.dictionary = dictionary

    def __call__(self, name: str) -> str:
        if self.dictionary is None or not self.profile.has(name):
            return name
        variable = self.dictionary.get(*self.profile.address(name))
        return f"{name} ({variable.label})" if variable is not None else name
