"""The EDS library as the API and the CLI offer it: look a dictionary up by the name a caller gives, check and import
EDS files (from a path, or uploaded bytes staged on the server)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from servostudio.errors import InvalidInput, NotFound
from servostudio.od import EdsLibrary, LibraryError, ObjectDictionary, Variable, load_dictionary
from servostudio.od.ini import decode_ini


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
