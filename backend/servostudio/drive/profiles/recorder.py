"""The in-drive oscilloscope recorder of a device family, keyed by semantic names (docs/scope.md, docs/eds.md §6).

The capture service (``services.scope``) asks the profile for ``"depth"`` or ``"control"`` and for the codes of
``"arm"`` or ``"rising"``, never for 0x5804,2 or 1, so a drive family with another recorder layout is a new
description here, not edits in the service. A profile without a recorder (``DeviceProfile.recorder is None``)
has none: its captures will come from TPDOs (issue #12, item 3).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from servostudio.drive.profiles.base import ProfileError


@dataclass(frozen=True)
class RecorderDescription:
    """Where a recorder's objects are and what its codes mean."""

    #: semantic name → (index, sub) of the single objects
    objects: Mapping[str, tuple[int, int]]
    #: per channel n (1..channels): the source pointer (index, n), its data type code (index, n), its unit label
    channel_sources: int
    channel_types: int
    channel_units: int
    channels: int
    #: control word values (``stop``, ``arm``, ``force``) and the status codes in order (``idle`` … ``done``)
    commands: Mapping[str, int]
    statuses: tuple[str, ...]
    trigger_modes: Mapping[str, int]  # immediate, edge
    rearm_modes: Mapping[str, int]  # single, normal, auto
    edges: Mapping[str, int]  # rising, falling, either

    def address(self, name: str) -> tuple[int, int]:
        try:
            return self.objects[name]
        except KeyError:
            raise ProfileError(f"the recorder has no object '{name}'") from None

    def status_name(self, code: int) -> str:
        """The status a code means (an unknown code is named by its number, never guessed)."""
        return self.statuses[code] if 0 <= code < len(self.statuses) else f"status {code}"


#: The XtrapulsPac's recorder at 0x5800–0x5841 (docs/eds.md §6, the project's layout: decisions.md §2).
XTRAPULSPAC_RECORDER = RecorderDescription(
    objects={
        "functions": (0x5800, 0),
        "buffer": (0x5801, 0),
        "capacity": (0x5804, 1),
        "depth": (0x5804, 2),
        "base_period": (0x5804, 3),
        "multiplier": (0x5804, 4),
        "record_size": (0x5804, 5),
        "counter": (0x5804, 6),
        "pre_trigger": (0x5805, 0),
        "trigger_source": (0x5820, 1),
        "trigger_mode": (0x5820, 2),
        "rearm": (0x5820, 3),
        "auto_timeout": (0x5820, 4),
        "trigger_level": (0x5822, 1),
        "trigger_edge": (0x5822, 2),
        "control": (0x5828, 0),
        "status": (0x5829, 0),
        "part_first": (0x5840, 1),
        "part_count": (0x5840, 2),
        "trigger_record": (0x5840, 3),
        "records": (0x5840, 4),
        "part": (0x5841, 0),
        # what another drive's TPDO sets for this recorder to trigger on (a triggered capture of several axes,
        # docs/scope.md §7): 0x23A0 TPDO count acts only on TPDOs of transmission type 254, and only at a SYNC
        "trigger_relay": (0x23A0, 0),
    },
    channel_sources=0x5811,
    channel_types=0x5810,
    channel_units=0x5812,
    channels=4,
    commands={"stop": 0, "arm": 1, "force": 2},
    statuses=("idle", "filling", "waiting", "recording", "done"),
    trigger_modes={"immediate": 0, "edge": 1},
    rearm_modes={"single": 0, "normal": 1, "auto": 2},
    edges={"rising": 0, "falling": 1, "either": 2},
)
