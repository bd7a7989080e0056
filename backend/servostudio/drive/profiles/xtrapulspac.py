"""Infranor XtrapulsPac: error words 0x3022, warnings 0x3024, Infranor code in EMCY byte 3, signatures, files."""

from __future__ import annotations

from servostudio.drive.profiles.base import CIA301_OBJECTS, CIA402_OBJECTS, Addressing, DeviceProfile, EmcyLayout
from servostudio.drive.profiles.xtrapulspac_faults import ERRORS, WARNINGS
from servostudio.od.model import SaveType

XTRAPULSPAC = DeviceProfile(
    device="xtrapulspac",
    objects={
        **CIA301_OBJECTS,
        **CIA402_OBJECTS,
        "errors_low": (0x3022, 1),
        "errors_high": (0x3022, 2),
        "infranor_error_code": (0x3023, 4),
        "warnings": (0x3024, 0),
        "nmt_reset_configuration": (0x205D, 0),
        "sequence_number": (0x3610, 0),
        "sequence_parameters": (0x3611, 0),
        "max_sequences": (0x3612, 0),
    },
    signatures={
        "save": ("store_parameters", "save"),
        "save_sequences": ("store_parameters", "sseq"),
        "load": ("restore_parameters", "load"),
        "load_user": ("restore_parameters", "lusr"),
        "load_sequences": ("restore_parameters", "lseq"),
        "merge_sequences": ("restore_parameters", "mseq"),
    },
    error_words=(("errors_low", 1), ("errors_high", 33)),
    warning_word="warnings",
    errors=ERRORS,
    warnings=WARNINGS,
    emcy_layout=EmcyLayout.CODE_BYTE,
    parameter_files={"DRIVEPAR.TXT": SaveType.DRIVEPAR, "USER_PAR.TXT": SaveType.USER_PAR},
    has_sequences=True,
    addressing=Addressing(
        range(1, 64),
        "XtrapulsPac node IDs are 1-63 (front-panel switches); n+64 is its redirected SDO channel (manual L2565-2589)",
        redirect_offset=64,
    ),
)
