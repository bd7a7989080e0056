"""The communication server's bus side: open buses (ConnectionManager), the event hub, background jobs."""

from servostudio.services.bus.connections import BusConnection, ConnectionManager, NodeInfo, UnknownBusOrNode
from servostudio.services.bus.events import EventHub, Subscription
from servostudio.services.bus.jobs import Job, JobRegistry, UnitResults

__all__ = [
    "BusConnection",
    "ConnectionManager",
    "EventHub",
    "Job",
    "JobRegistry",
    "NodeInfo",
    "Subscription",
    "UnitResults",
    "UnknownBusOrNode",
]
