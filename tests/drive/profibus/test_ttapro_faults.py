"""The TTA-PRO's fault words decoded with the manual's texts (docs/profibus.md §12), against the manual's tables
written out here (byte.bit → abbreviation, L1792-1831; PNU 778 L1856-1868; PNU 873 L2856-2870)."""

from __future__ import annotations

import pytest

from servostudio.drive.faults import faults_from_words
from servostudio.drive.profiles.ttapro import TTAPRO

MANUAL_773 = {
    "1.1": "I²t", "1.2": "RDC / COUNT", "1.3": "POS", "1.4": "MEM", "1.5": "BUS", "1.7": "BUSY",
    "2.0": "2nd SENSOR", "2.1": "POWER", "2.2": "RES / COD / HES", "2.3": "AP", "2.4": "24V", "2.5": "TMOT",
    "2.6": "CDG", "3.0": "HOME", "3.1": "E2PPAR", "3.2": "E2PSEQ", "3.3": "E2PCOG", "3.4": "SEQWR",
}  # fmt: skip


def decode(positioner: int = 0, power: int = 0):
    words = [(int(positioner), 1), (int(power), 101)]
    return faults_from_words(TTAPRO.errors, words, TTAPRO.coded_error_bits)


@pytest.mark.parametrize(("place", "abbreviation"), MANUAL_773.items())
def test_each_bit_of_pnu_773_is_named_as_the_manual_names_it(place, abbreviation):
    byte, bit = (int(part) for part in place.split("."))
    (fault,) = decode(positioner=1 << (8 * (byte - 1) + bit))
    assert fault.name.startswith(f"{abbreviation}: ") and "acknowledge" in fault.remedy


def test_pnu_778_holds_a_code_in_bits_0_to_2_and_single_bits_above_without_masking_773():
    faults = decode(positioner=0b110, power=0b1000 | 4)  # I²t and RDC in 773; IGBT and code 4 in 778
    assert [fault.name.split(":")[0] for fault in faults] == [
        "I²t",
        "RDC / COUNT",
        "IGBT module error",
        "Motor phases/earth short-circuit",
    ]
    assert decode(power=1 << 15)[0].name == "Current error"


def test_pnu_873_warnings():
    names = [warning.name for warning in faults_from_words(TTAPRO.warnings, [(1 << 1 | 1 << 13, 1)])]
    assert names == ["I²t protection", "°C motor: motor temperature"]
