"""Motion safety: one armed controller per axis, and a guard that judges every write by what the drive will do.

``docs/motion-safety.md`` tells the whole story; in short, ``MotionGuard`` is the write gate of every drive the
server hands out (``guard``), it judges writes with ``verdict.judge`` and authorises them with ``control``'s
controllers.
"""

from servostudio.services.motion.control import Axis, AxisHeld, Holder, NoLiveClient, NotArmed, NotHeld
from servostudio.services.motion.guard import MotionGuard, TakeOverRefused
from servostudio.services.motion.verdict import Motion, Verdict

__all__ = [
    "Axis",
    "AxisHeld",
    "Holder",
    "Motion",
    "MotionGuard",
    "NoLiveClient",
    "NotArmed",
    "NotHeld",
    "TakeOverRefused",
    "Verdict",
]
