"""Device facts a project needs before any drive is connected: the drive files of an axis.

They come from the drive profiles (``servostudio.drive.profiles``), as do the node-ID rules the validation checks
(``DeviceProfile.addressing``). Imported EDS devices get the generic profile.
"""

from __future__ import annotations

from collections.abc import Mapping

from servostudio.drive.profiles import profile_for
from servostudio.od import SaveType
from servostudio.services.projects import layout


def parameter_files(device: str) -> Mapping[str, SaveType]:
    """The device's parameter files and the save type of the objects each holds, in the order the drive applies
    them (a later file overrides an earlier one: XtrapulsPac loads DRIVEPAR.TXT, then USER_PAR.TXT with 'lusr')."""
    return profile_for(device).parameter_files


def axis_files(device: str) -> tuple[str, ...]:
    """Every file an axis directory of this device holds: the parameter files, plus its sequence file if it has one
    (SEQUENCE.TXT, or the file of a sequence table behind a buffer: the TTA-PRO's TTASEQ.TXT)."""
    profile = profile_for(device)
    buffered = (profile.sequence_buffer.file,) if profile.sequence_buffer is not None else ()
    return (*profile.parameter_files, *((layout.SEQUENCE,) if profile.has_sequences else ()), *buffered)
