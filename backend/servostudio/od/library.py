"""The EDS library: built-in dictionaries (`<repo>/eds`) plus dictionaries the user imported (a user directory).

Devices are keyed by the EDS file name without suffix, lower-case (`xtrapulspac`). A user dictionary with the same
key as a built-in one is refused at import, so a key always means one file. A PROFIBUS parameter list
(`<device>.pnu`, docs/profibus.md §2) is a device of the library too (`ttapro`): it loads as a `ParameterDictionary`,
an `ObjectDictionary` with index = PNU, subindex = IND, and matches by its DP ident number (vendor ID 0).
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
import threading
from collections.abc import Mapping
from pathlib import Path

from servostudio.errors import InvalidInput
from servostudio.od.eds import load_dictionary
from servostudio.od.model import ObjectDictionary

#: the repository's ``eds/`` folder; ``builtin_eds_dir()`` is what a process uses
BUILTIN_EDS_DIR = Path(__file__).resolve().parents[3] / "eds"


def builtin_eds_dir(environ: Mapping[str, str] = os.environ) -> Path:
    """The built-in dictionaries: ``SERVOSTUDIO_EDS_DIR``, else the repository's ``eds/`` (read when asked, so
    importing this module reads no environment)."""
    return Path(environ.get("SERVOSTUDIO_EDS_DIR") or BUILTIN_EDS_DIR)


def default_user_eds_dir(environ: Mapping[str, str] = os.environ) -> Path:
    """Imported dictionaries: ``SERVOSTUDIO_USER_EDS_DIR``, else ``$XDG_DATA_HOME/servostudio/eds``."""
    data_home = Path(environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
    return Path(environ.get("SERVOSTUDIO_USER_EDS_DIR") or data_home / "servostudio" / "eds")


_KEY = re.compile(r"^[a-z0-9][a-z0-9_.-]*$")


class LibraryError(InvalidInput):
    """An import was refused (bad name, key clash) or a device key is unknown."""


class EdsLibrary:
    def __init__(self, builtin_dir: Path = BUILTIN_EDS_DIR, user_dir: Path | None = None) -> None:
        self.builtin_dir = Path(builtin_dir)
        self.user_dir = Path(user_dir) if user_dir is not None else None
        self._cache: dict[str, ObjectDictionary] = {}
        self._lock = threading.Lock()

    def devices(self) -> list[str]:
        """Device keys of every EDS in the built-in and user directories, sorted."""
        return sorted(set(self._files(self.builtin_dir)) | set(self._files(self.user_dir)))

    def path_of(self, device: str) -> Path:
        """The EDS file behind a device key (built-in first)."""
        for directory in (self.builtin_dir, self.user_dir):
            path = self._files(directory).get(device)
            if path is not None:
                return path
        raise LibraryError(f"unknown device {device!r}; known: {', '.join(self.devices()) or 'none'}")

    def load(self, device: str) -> ObjectDictionary:
        """The dictionary of `device`, loaded once and cached."""
        with self._lock:
            if device not in self._cache:
                self._cache[device] = _load_file(self.path_of(device))
            return self._cache[device]

    def import_eds(self, eds_path: Path, props_path: Path | None = None) -> str:
        """Validate an EDS (+ props) and copy it into the user directory; returns the device key.

        Nothing is copied when validation fails (DictionaryError) or the key clashes with a built-in device
        (LibraryError). The copies are written as temporary files in the user directory and renamed into place.
        """
        if self.user_dir is None:
            raise LibraryError("this library has no user directory to import into")
        eds_path = Path(eds_path)
        key = eds_path.stem.lower()
        if not _KEY.match(key):
            raise LibraryError(f"{eds_path.name}: file name must give a key of letters, digits, '_', '-', '.'")
        if key in self._files(self.builtin_dir):
            raise LibraryError(f"{eds_path.name}: a built-in device is already called {key!r}")
        if props_path is None:
            candidate = eds_path.with_suffix(".props")
            props_path = candidate if candidate.exists() else None
        load_dictionary(eds_path, props_path)
        self.user_dir.mkdir(parents=True, exist_ok=True)
        self._install(self.user_dir, eds_path, props_path, key)
        with self._lock:
            self._cache.pop(key, None)
        return key

    def match(self, vendor_id: int, product_code: int) -> str | None:
        """Device key whose identity (vendor ID, product code) matches, user dictionaries first; None if none."""
        ordered = list(self._files(self.user_dir)) + list(self._files(self.builtin_dir))
        for device in ordered:
            od = self.load(device)
            if od.vendor_id == vendor_id and od.product_code == product_code:
                return device
        return None

    def _install(self, user_dir: Path, eds_path: Path, props_path: Path | None, key: str) -> None:
        target_eds = user_dir / f"{key}.eds"
        target_props = user_dir / f"{key}.props"
        staged = [(self._stage(eds_path), target_eds)]
        if props_path is not None:
            staged.append((self._stage(Path(props_path)), target_props))
        try:
            for temp, target in reversed(staged):
                os.replace(temp, target)
        finally:
            for temp, _ in staged:
                temp.unlink(missing_ok=True)
        if props_path is None:
            target_props.unlink(missing_ok=True)

    def _stage(self, source: Path) -> Path:
        handle, name = tempfile.mkstemp(dir=self.user_dir, prefix=".import-", suffix=source.suffix + ".tmp")
        with os.fdopen(handle, "wb") as out, source.open("rb") as src:
            shutil.copyfileobj(src, out)
        return Path(name)

    @staticmethod
    def _files(directory: Path | None) -> dict[str, Path]:
        if directory is None or not directory.is_dir():
            return {}
        files = [path for suffix in DICTIONARY_SUFFIXES for path in sorted(directory.glob(f"*{suffix}"))]
        return {key: path for path in reversed(files) if path.is_file() for key in [path.stem.lower()]}


DICTIONARY_SUFFIXES = (".eds", ".pnu")
"""What the library lists, in this order of precedence for one key: CiA 306 EDS, PROFIBUS parameter lists."""


def _load_file(path: Path) -> ObjectDictionary:
    """An EDS (with its .props), or a PROFIBUS parameter list (``od/pnu.py`` builds on this module: imported here)."""
    if path.suffix.lower() == ".pnu":
        from servostudio.od.pnu import load_parameter_list

        return load_parameter_list(path)
    return load_dictionary(path)


_builtin: EdsLibrary | None = None


def builtin_library() -> EdsLibrary:
    """Process-wide library: the built-in directory plus the user directory, as the environment names them when
    it is first asked for."""
    global _builtin
    if _builtin is None:
        _builtin = EdsLibrary(builtin_eds_dir(), default_user_eds_dir())
    return _builtin
