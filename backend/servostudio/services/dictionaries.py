"""The EDS library as the API and the CLI offer it: look a dictionary up by the name a caller gives, check and import
EDS files (from a path, or uploaded bytes staged on the server)."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path

from servostudio.drive.profiles import DeviceProfile, ProfileError, profile_for
from servostudio.errors import InvalidInput, NotFound
from servostudio.od import EdsLibrary, LibraryError, ObjectDictionary, Variable, load_dictionary
from servostudio.od.ini import decode_ini
from servostudio.services import backup
from servostudio.services.backup import profile_file_kinds


class UnknownDictionary(NotFound):
    """No dictionary of the library has the device key the caller named."""


class UnknownEntry(NotFound):
    """The dictionary has no object of that address or name."""


class ImportRefused(InvalidInput):
    """An uploaded EDS (or its properties) is invalid or clashes with a built-in device; nothing was kept."""


def dictionary(library: EdsLibrary, device: str) -> ObjectDictionary:
    """The dictionary a caller asks for by its device key (as a path or a command's subject, so unknown: not found)."""
    try:
        return library.load(device)
    except LibraryError as error:
        raise UnknownDictionary(str(error)) from None


def entry(od: ObjectDictionary, key: str) -> Variable:
    """One object by address (``0x6041``, ``60F9,2``) or name."""
    try:
        return od.find(key)
    except KeyError as error:
        raise UnknownEntry(error.args[0]) from None


def profile_names(od: ObjectDictionary) -> dict[str, tuple[int, int]]:
    """The semantic names of the device's profile that its dictionary has, with their addresses: a client (the
    dashboard) asks for ``statusword`` or ``position_actual`` and learns this device's address — 0x6041 on a
    CANopen drive, the PZD status word on a TTA-PRO — instead of keeping a table of raw addresses of its own."""
    objects = profile_for(od.device).objects
    return {name: address for name, address in sorted(objects.items()) if address in od}


def fieldbus(od: ObjectDictionary) -> str:
    """The device's fieldbus (``CANopen``, ``PROFIBUS-DP``): what a client may offer (NMT, modes of operation)."""
    return profile_for(od.device).fieldbus


def drive_files(od: ObjectDictionary) -> list[str]:
    """The files a backup of the device holds (its profile's: DRIVEPAR.TXT …, a TTA-PRO's TTAPAR.TXT, TTASEQ.TXT)."""
    return [kind.value for kind in profile_file_kinds(profile_for(od.device))]


#: what a client may offer a device, each by the part of its profile the server's service needs (and refuses
#: without): captures need CANopen's TPDOs or recorder; a measured frequency response those and the speed loop
FEATURES: dict[str, Callable[[DeviceProfile], bool]] = {
    "scope": lambda profile: profile.canopen,
    # the procedure pages, each by the procedure it starts (a CD1-k phases and auto-tunes but has no 'calc')
    "current_loop": lambda profile: profile.procedures.get("current_loop") is not None,
    "phasing": lambda profile: profile.procedures.get("auto_phasing") is not None,
    "auto_tuning": lambda profile: profile.procedures.get("auto_tuning") is not None,
    "frequency_response": lambda profile: profile.canopen and profile.speed_loop is not None,
    "sequences": lambda profile: profile.has_sequences,
    "io": lambda profile: profile.io is not None,
}


def features(od: ObjectDictionary) -> list[str]:
    """The services the device has (``FEATURES``): the UI shows only the pages a device can use, from this answer
    instead of a list of device names of its own."""
    profile = profile_for(od.device)
    return [name for name, has in FEATURES.items() if has(profile)]


def store_action(od: ObjectDictionary) -> str | None:
    """What "store parameters" writes on the device (``PNU 729 Save parameters in EEPROM = 1``); None when its
    profile or dictionary has no save."""
    try:
        return backup.store_action(profile_for(od.device), od)
    except (ProfileError, KeyError):
        return None


def is_builtin(library: EdsLibrary, device: str) -> bool:
    return library.path_of(device).parent == library.builtin_dir


def check_file(eds: Path, props: Path | None = None) -> ObjectDictionary:
    """Load an EDS (and its properties) without importing it; a file that cannot be read is refused input."""
    try:
        return load_dictionary(eds, props)
    except OSError as error:
        raise InvalidInput(f"{error.filename}: {error.strerror}") from None


def read_file_text(path: Path) -> str:
    """The text of an EDS or DCF the user named (the CLI), decoded as the loader decodes files; a file that cannot
    be read is refused input."""
    try:
        return decode_ini(Path(path).read_bytes())
    except OSError as error:
        raise InvalidInput(f"{error.filename}: {error.strerror}") from None


def upload_text(raw: bytes) -> str:
    """The text of an uploaded EDS or DCF, decoded as the loader decodes files."""
    return decode_ini(raw)


def import_file(library: EdsLibrary, eds: Path, props: Path | None = None) -> str:
    """Validate an EDS file and add it to the user library; returns its device key."""
    try:
        return library.import_eds(eds, props)
    except OSError as error:
        raise InvalidInput(f"{error.filename}: {error.strerror}") from None


def import_upload(library: EdsLibrary, eds_name: str, eds: bytes, props: bytes | None = None) -> str:
    """Validate uploaded EDS bytes (and properties) and add them to the user library under the uploaded file's
    name; nothing is kept on error, and the message names the file as the user uploaded it."""
    with tempfile.TemporaryDirectory() as staging:
        eds_path = Path(staging) / _file_name(eds_name)
        eds_path.write_bytes(eds)
        props_path = None
        if props is not None:
            props_path = eds_path.with_suffix(".props")
            props_path.write_bytes(props)
        try:
            return library.import_eds(eds_path, props_path)
        except InvalidInput as error:
            raise ImportRefused(str(error).replace(f"{staging}{os.sep}", "")) from None


def _file_name(uploaded: str) -> str:
    """The uploaded file's own name, without any folder (a name like ``..`` becomes ``upload.eds``)."""
    name = Path(uploaded).name
    return name if name not in ("", "..") else "upload.eds"
