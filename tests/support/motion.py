"""How tests that are not about motion safety enable an axis: as a UI does, through a live client that armed it.

Every drive a ``ConnectionManager`` hands out writes through its motion guard, so a test that walks a drive to
Operation enabled must be the axis's armed controller, exactly as a browser page or a CLI command is.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager

from servostudio.services.audit import Actor, acting_as
from servostudio.services.bus import ConnectionManager


@contextmanager
def controlling(
    manager: ConnectionManager, bus: str, node: int | Sequence[int], user: str = "tests"
) -> Iterator[Actor]:
    """Inside the block the test acts as the armed controller of node ``node`` (or of each of several) on ``bus``;
    afterwards its client is gone without a quick stop (the test leaves the axis as it wants)."""
    guard = manager.motion
    actor = Actor(user, "administrator", guard.connect(user))
    for each in [node] if isinstance(node, int) else node:
        guard.arm(actor, (bus, each))
    try:
        with acting_as(actor):
            yield actor
    finally:
        guard.controllers.disconnect(actor.client or "")
