"""Projects with live drives: compare and synchronise values, commission (check, download, upload), scan into a
project, select a catalog motor on the drive. See docs/projects.md §13."""

from servostudio.services.projects.live.commission import AxisReport, CommissionReport
from servostudio.services.projects.live.links import AxisLink, link_axes
from servostudio.services.projects.live.scaninto import ScannedNode, ScanReport
from servostudio.services.projects.live.service import LiveProjects
from servostudio.services.projects.live.source import DriveValues
from servostudio.services.projects.live.sync import DriveWrite, DriveWriteReport, LiveCompare

__all__ = [
    "AxisLink",
    "AxisReport",
    "CommissionReport",
    "DriveValues",
    "DriveWrite",
    "DriveWriteReport",
    "LiveCompare",
    "LiveProjects",
    "ScanReport",
    "ScannedNode",
    "link_axes",
]
