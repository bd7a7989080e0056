"""A roll written down (``servostudio scope … --roll``, docs/scope.md §8): the roll's samples as they arrived, as a
CSV in the capture file format (§5) — the same comments, header and rows — with the gaps stated.

Time 0 is the roll's first sample (sequence number 0: the trigger of a roll is its start, "immediate"); row *k* is
at ``seq × period``. Sequence numbers the roll lost have no row: the time column jumps, and a ``gaps`` comment
counts them and each ``gap`` comment names the numbers, the times and the reason. Nothing is filled in.
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field

from servostudio.services.scope.capture import ChannelInfo, DriveIdentity, Number
from servostudio.services.scope.capturefile import csv_head, microseconds_text, seconds_text, units_text, value_text

Event = dict[str, object]
#: a gap no event explained: the samples simply never arrived
UNEXPLAINED = "samples not received"


@dataclass
class RollRecord:
    """Every sample a roll delivered (its sequence number and its physical values) and every gap, from its events."""

    channels: tuple[ChannelInfo, ...]
    period_ns: int
    drive: DriveIdentity
    started_at: str  # ISO 8601, UTC
    numbers: list[int] = field(default_factory=list)
    rows: list[tuple[Number, ...]] = field(default_factory=list)
    gaps: list[tuple[int, int, str]] = field(default_factory=list)  # sequence numbers [from, to) lost, and why
    _next: int = 0
    _reason: str | None = None

    def take(self, event: Event) -> None:
        """One event of the roll's feed (``samples``, ``gap``; others are not this record's)."""
        if event["type"] == "samples":
            self._samples(int(event["seq"]), event["values"])  # type: ignore[call-overload, arg-type]
        elif event["type"] == "gap":
            self._gap(event)

    def _samples(self, seq: int, values: list[list[Number]]) -> None:
        if seq > self._next:  # numbers that never came, whatever the feed said of them
            self.gaps.append((self._next, seq, self._reason or UNEXPLAINED))
        self._reason = None
        count = len(values[0]) if values else 0
        self.numbers += range(seq, seq + count)
        self.rows += zip(*values, strict=True)
        self._next = seq + count

    def _gap(self, event: Event) -> None:
        """A gap the roll reported (``from``, ``to``); a reader's own backlog has no numbers: the next samples show
        which are missing."""
        reason = str(event.get("reason") or UNEXPLAINED)
        if "from" in event and "to" in event:
            start, end = int(event["from"]), int(event["to"])  # type: ignore[call-overload]
            if end > start:
                self.gaps.append((start, end, reason))
            self._next = max(self._next, end)
        else:
            self._reason = reason

    @property
    def lost(self) -> int:
        return sum(end - start for start, end, _ in self.gaps)

    def gap_texts(self) -> list[str]:
        """Each gap as the CSV states it: ``samples 512..986 (0.512 s to 0.987 s) lost: link lost: …``."""
        return [
            f"samples {start}..{end - 1} ({seconds_text(start * self.period_ns)} s to "
            f"{seconds_text((end - 1) * self.period_ns)} s) lost: {reason}"
            for start, end, reason in self.gaps
        ]


def roll_csv(record: RollRecord) -> str:
    """The CSV of a roll: the capture file's comments (and ``gaps``, ``gap`` lines), header and rows."""
    out = io.StringIO()
    writer = csv_head(out, _comments(record), record.channels)
    for seq, row in zip(record.numbers, record.rows, strict=True):
        writer.writerow([seconds_text(seq * record.period_ns), *(value_text(value) for value in row)])
    return out.getvalue()


def _comments(record: RollRecord) -> list[tuple[str, str]]:
    lost = f"{len(record.gaps)} ({record.lost} samples lost)" if record.gaps else "0"
    return [
        ("period", f"{microseconds_text(record.period_ns)} us"),
        ("samples", str(len(record.rows))),
        ("trigger", "immediate"),
        ("pre-trigger", "0 % (0 samples)"),
        ("units", units_text(record.channels)),
        ("drive", record.drive.describe()),
        ("node", str(record.drive.node)),
        ("bus", record.drive.bus),
        ("captured", record.started_at),
        ("source", "tpdo"),
        ("gaps", lost),
        *(("gap", text) for text in record.gap_texts()),
    ]
