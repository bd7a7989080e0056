"""The TTA-PRO parameter list `eds/ttapro.pnu` against the manual (TTA-PRO Profibus Communication Profile,
Chapter 3 §1, L897-1148): every listed PNU is there, PNU 833-898 (whose columns the OCR lost) say they are
derived, and the list maps onto the dictionary model as docs/profibus.md §2 states."""

from __future__ import annotations

import re

import pytest

from servostudio.od import Access, DataType, ObjectKind, SaveType
from servostudio.od.pnu import builtin_parameter_list
from servostudio.od.pnu_model import ParameterDictionary, Persistence

MANUAL_LIST = [
    *(700, 701, 702, 704, 705),  # L900-904
    *range(710, 755),  # L905-951
    *range(756, 772),  # L952-967
    *range(773, 779),  # L968-973
    *range(780, 808),  # L974-1003
    810,  # L1004
    815,  # L1005
    *range(818, 825),  # L1006-1012
    *range(828, 833),  # L1013-1017
    *(833, 834, 837, 838, 839, 842, 843, 845, 846),  # L1025-1078 (numbers and names only)
    *range(850, 861),  # L1079-1091
    *(865, 870, 873, 875, 876, 879, 880),  # L1093-1101
    *range(882, 899),  # L1102-1140
    899,  # L1141
]
LOST_COLUMNS = [pnu for pnu in MANUAL_LIST if 833 <= pnu <= 898]
READ_FROM_MAPPING_CODES = [706, 707, 708, 755]  # 0x12C2, 0x12C3, 0x12C4, 0x12F3 (L2443-2497)


@pytest.fixture(scope="module")
def ttapro() -> ParameterDictionary:
    return builtin_parameter_list()


def test_every_pnu_the_manual_lists_is_present(ttapro: ParameterDictionary) -> None:
    assert len(MANUAL_LIST) == 159
    assert [pnu for pnu in MANUAL_LIST if pnu not in ttapro.parameters] == []
    assert sorted(ttapro.parameters) == sorted(MANUAL_LIST + READ_FROM_MAPPING_CODES)


def test_the_pnus_whose_columns_were_lost_say_they_are_derived(ttapro: ParameterDictionary) -> None:
    derived = sorted(pnu for pnu, parameter in ttapro.parameters.items() if parameter.derived)
    assert derived == sorted(LOST_COLUMNS + READ_FROM_MAPPING_CODES)
    assert len(LOST_COLUMNS) == 44


def test_every_pnu_names_its_manual_lines(ttapro: ParameterDictionary) -> None:
    for pnu, parameter in ttapro.parameters.items():
        lines = [int(line) for line in re.findall(r"L(\d+)", parameter.reference)]
        assert lines and all(1 <= line <= 3211 for line in lines), pnu
        if pnu in MANUAL_LIST:
            assert 897 <= lines[0] <= 1141, f"PNU {pnu}: the first reference is its list row"


def test_words_and_double_words_map_onto_16_and_32_bit_types(ttapro: ParameterDictionary) -> None:
    assert ttapro[700, 0].data_type is DataType.UNSIGNED16
    assert ttapro[776, 0].data_type is DataType.INTEGER16  # "integer" monitor
    assert ttapro[774, 0].data_type is DataType.INTEGER32
    assert ttapro[770, 0].data_type is DataType.UNSIGNED32
    for parameter in ttapro.parameters.values():
        assert parameter.data_type in (
            DataType.UNSIGNED16,
            DataType.INTEGER16,
            DataType.UNSIGNED32,
            DataType.INTEGER32,
        )


def test_the_list_rows_attributes(ttapro: ParameterDictionary) -> None:
    current = ttapro[710, 0]
    assert (current.low, current.high, current.default, current.access) == (6553, 32767, 0x7FFF, Access.RW)
    assert current.save_type is SaveType.DRIVEPAR and current.unit == "% rating"
    assert ttapro[747, 0].default == 0x7FFFFFFF and ttapro[748, 0].default == -(2**31)
    assert ttapro[774, 0].access is Access.RO
    assert ttapro[729, 0].access is Access.WO and ttapro.parameters[729].procedure
    assert ttapro.parameters[782].persistence is Persistence.S
    assert ttapro.parameters[899].persistence is Persistence.RAM and ttapro[899, 0].default == 0
    assert ttapro[730, 0].scale == pytest.approx(1 / 16)


def test_an_indexed_pnu_is_an_array_with_ind_as_subindex(ttapro: ParameterDictionary) -> None:
    sequence_control = ttapro.object(795)
    assert sequence_control.kind is ObjectKind.ARRAY and sorted(sequence_control.subs) == list(range(128))
    assert [ttapro[828, slot].default for slot in range(3)] == [0x1309, 0x1308, 0x2306]
    assert [ttapro[829, slot].default for slot in range(3)] == [0x1348, 0x1348, 0x22FF]


def test_parameters_are_found_and_labelled_by_pnu(ttapro: ParameterDictionary) -> None:
    assert ttapro.find("PNU700").label == "PNU 700 Number of motor pole pairs"
    assert ttapro.find("795[5]").label == "PNU 795[5] Sequence control modification"
    assert ttapro.find("828,2").default == 0x2306
    assert ttapro.find("Maximum motor speed").index == 721
    with pytest.raises(KeyError):
        ttapro.find("PNU709")


def test_identity(ttapro: ParameterDictionary) -> None:
    assert ttapro.device == "ttapro" and ttapro.product_name == "TTA-PRO"
    assert ttapro.ident_number == ttapro.product_code == 0x00C7  # INFR00C7.GSD (L78)
