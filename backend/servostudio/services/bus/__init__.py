"""The communication server's bus side: open buses (ConnectionManager), the event hub, background jobs."""

from servostudio.services.bus.claims import BusClaims, Claimed
from servostudio.services.bus.connections import (
    BusConnection,
    BusMatch,
    ConnectionManager,
    NodeInfo,
    UnknownBusOrNode,
    parse_share,
)
from servostudio.services.bus.events import EventHub, Subscription
from servostudio.services.bus.jobs import Job, JobRegistry, UnitResults
from servostudio.services.bus.share import BusShare, ShareRefused, ShareStatus

__all__ = [
    "BusClaims",
    "BusConnection",
    "BusMatch",
    "BusShare",
    "Claimed",
    "ConnectionManager",
    "EventHub",
    "Job",
    "JobRegistry",
    "NodeInfo",
    "ShareRefused",
    "ShareStatus",
    "Subscription",
    "UnitResults",
    "UnknownBusOrNode",
    "parse_share",
]
