"""The trigger and the pre-trigger of a capture the server assembles itself (TPDO or polled samples), with the
recorder's rules (docs/scope.md §2): the first ``pre_trigger`` samples fill the pre-trigger without looking for an
edge; then each sample's trigger value is compared with the previous one's (rising: ``previous < level ≤
current``; falling: ``previous > level ≥ current``; either: one of the two) while the newest ``pre_trigger``
samples are kept; the sample where the condition holds is the trigger sample, and the window is complete with
``depth`` samples. Immediate: the first ``depth`` samples, the first one the trigger sample.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence

Sample = tuple[int | float, ...]


def crossed(edge: str, level: int, previous: float, current: float) -> bool:
    rising = previous < level <= current
    falling = previous > level >= current
    return {"rising": rising, "falling": falling, "either": rising or falling}[edge]


class SampleWindow:
    """Samples in, the captured window out once it is complete."""

    def __init__(self, depth: int, pre_trigger: int, channel: int | None, level: int = 0, edge: str = "rising") -> None:
        self.depth, self.pre_trigger = depth, pre_trigger
        self.channel, self.level, self.edge = channel, level, edge
        self.samples: deque[Sample] = deque(maxlen=max(pre_trigger, 1) if channel is not None else None)
        self.trigger_index: int | None = 0 if channel is None else None
        self.seen = 0  # samples offered, in order (the position of the first one kept is seen - len(samples))
        self._previous: float | None = None

    @property
    def stage(self) -> str:
        """As the recorder's status names it: filling, waiting, recording, done."""
        if self.complete:
            return "done"
        if self.trigger_index is not None:
            return "recording"
        return "filling" if self.seen < self.pre_trigger else "waiting"

    @property
    def complete(self) -> bool:
        return self.trigger_index is not None and len(self.samples) >= self.depth

    def add(self, sample: Sample) -> bool:
        """Take one sample; True once the window is complete (later samples are ignored)."""
        if self.complete:
            return True
        self.seen += 1
        if self.trigger_index is None and self.channel is not None:
            value = sample[self.channel]
            previous, self._previous = self._previous, value
            if (
                self.seen > self.pre_trigger
                and previous is not None
                and crossed(self.edge, self.level, previous, value)
            ):
                self._triggered()
            elif self.pre_trigger == 0:
                return False  # nothing kept before the trigger
        self.samples.append(sample)
        return self.complete

    def add_all(self, samples: Sequence[Sample]) -> bool:
        return any(self.add(sample) for sample in samples)

    def _triggered(self) -> None:
        kept = list(self.samples)[-self.pre_trigger :] if self.pre_trigger else []
        self.samples = deque(kept)  # unbounded from now on: the rest of the window
        self.trigger_index = len(kept)

    def columns(self, count: int) -> tuple[tuple[int | float, ...], ...]:
        """The window as one tuple of values per channel."""
        rows = list(self.samples)[: self.depth]
        return tuple(tuple(row[n] for row in rows) for n in range(count))
