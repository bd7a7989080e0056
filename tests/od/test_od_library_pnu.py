"""The EDS library lists PROFIBUS parameter lists (`*.pnu`) beside the EDS files: the built-in TTA-PRO loads as
its `ParameterDictionary` and is found by its DP ident number; an EDS of the same key wins."""

from __future__ import annotations

import shutil

from servostudio.od.library import BUILTIN_EDS_DIR, EdsLibrary, builtin_library
from servostudio.od.pnu_model import ParameterDictionary


def test_the_builtin_ttapro_is_a_device_of_the_library() -> None:
    library = builtin_library()
    assert "ttapro" in library.devices()
    dictionary = library.load("ttapro")
    assert isinstance(dictionary, ParameterDictionary) and dictionary.find("PNU700").label.startswith("PNU 700")
    assert library.match(0, 0x00C7) == "ttapro" and library.path_of("ttapro").suffix == ".pnu"


def test_an_eds_of_the_same_key_wins(tmp_path) -> None:
    shutil.copy(BUILTIN_EDS_DIR / "ttapro.pnu", tmp_path / "drive.pnu")
    shutil.copy(BUILTIN_EDS_DIR / "cd1k.eds", tmp_path / "drive.eds")
    library = EdsLibrary(tmp_path)
    assert library.devices() == ["drive"] and library.path_of("drive").suffix == ".eds"
