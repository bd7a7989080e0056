"""Every rejection rule of the EDS/props loader: the error names the file, the line, the section and the reason."""

from __future__ import annotations

from pathlib import Path

import pytest

from servostudio.od import DictionaryError, load_dictionary


def line_of(text: str, needle: str | tuple[str, int]) -> int:
    """Line number of the line equal to `needle` (or its n-th occurrence), else of the first line starting with it."""
    needle, occurrence = needle if isinstance(needle, tuple) else (needle, 1)
    lines = text.splitlines()
    exact = [number for number, line in enumerate(lines, start=1) if line == needle]
    if exact:
        return exact[occurrence - 1]
    return next(number for number, line in enumerate(lines, start=1) if line.startswith(needle))


# (rule id, old text, new text, section named in the error, text of the line reported, words of the reason)
EDS_RULES = [
    (
        "unknown data type",
        "ParameterName=Speed limit\nDataType=0x0006",
        "ParameterName=Speed limit\nDataType=0x0099",
        "2100",
        "DataType=0x0099",
        "unknown data type 0x0099",
    ),
    (
        "missing ParameterName",
        "[2100]\nParameterName=Speed limit\n",
        "[2100]\n",
        "2100",
        "[2100]",
        "ParameterName is missing",
    ),
    ("low limit outside type", "LowLimit=10", "LowLimit=-10", "2100", "LowLimit=-10", "outside the UNSIGNED16 range"),
    (
        "high limit outside type",
        "HighLimit=6000",
        "HighLimit=70000",
        "2100",
        "HighLimit=70000",
        "outside the UNSIGNED16 range",
    ),
    ("low above high", "LowLimit=10", "LowLimit=7000", "2100", "LowLimit=7000", "above HighLimit"),
    (
        "default outside limits",
        "DefaultValue=3000",
        "DefaultValue=9000",
        "2100",
        "DefaultValue=9000",
        "outside the limits 10..6000",
    ),
    (
        "DCF ParameterValue outside limits",
        "DefaultValue=3000",
        "DefaultValue=3000\nParameterValue=7000",
        "2100",
        "ParameterValue=7000",
        "ParameterValue 7000 is outside the limits",
    ),
    ("default not a number", "DefaultValue=3000", "DefaultValue=fast", "2100", "DefaultValue=fast", "not an integer"),
    (
        "NODEID default overflows type",
        "DefaultValue=$NODEID+0x180",
        "DefaultValue=$NODEID+0xFFFFFFF0",
        "1800sub1",
        "DefaultValue=$NODEID+0xFFFFFFF0",
        "outside the UNSIGNED32 range",
    ),
    ("NODEID in a limit", "LowLimit=10", "LowLimit=$NODEID", "2100", "LowLimit=$NODEID", "$NODEID is not allowed"),
    (
        "listed object without section",
        "2=0x2100\n",
        "2=0x2200\n",
        "ManufacturerObjects",
        "2=0x2200",
        "listed object 0x2200 has no section [2200]",
    ),
    (
        "section not listed",
        "SupportedObjects=2\n1=0x2000\n2=0x2100",
        "SupportedObjects=1\n1=0x2000",
        "2100",
        "[2100]",
        "not listed in any object list",
    ),
    (
        "manufacturer object in OptionalObjects",
        "2=0x6041",
        "2=0x2100\n",
        "OptionalObjects",
        "2=0x2100",
        "manufacturer-specific",
    ),
    (
        "object listed twice",
        "1=0x2000\n2=0x2100",
        "1=0x2000\n2=0x2000",
        "ManufacturerObjects",
        "2=0x2000",
        "already listed",
    ),
    (
        "list entry missing",
        "[OptionalObjects]\nSupportedObjects=2",
        "[OptionalObjects]\nSupportedObjects=4",
        "OptionalObjects",
        "SupportedObjects=4",
        "entry 3 is missing",
    ),
    (
        "mandatory object missing",
        "SupportedObjects=3\n1=0x1000\n2=0x1001\n3=0x1018",
        "SupportedObjects=2\n1=0x1000\n2=0x1018",
        "MandatoryObjects",
        "[MandatoryObjects]",
        "mandatory object 0x1001 is not listed",
    ),
    (
        "bad AccessType",
        "AccessType=rw\nLowLimit=10",
        "AccessType=readwrite\nLowLimit=10",
        "2100",
        "AccessType=readwrite",
        "AccessType 'readwrite'",
    ),
    ("missing AccessType", "AccessType=rw\nLowLimit=10", "LowLimit=10", "2100", "[2100]", "AccessType is missing"),
    (
        "missing DataType",
        "ParameterName=Speed limit\nDataType=0x0006\n",
        "ParameterName=Speed limit\n",
        "2100",
        "[2100]",
        "DataType is missing",
    ),
    (
        "bad PDOMapping",
        "DefaultValue=3000",
        "DefaultValue=3000\nPDOMapping=2",
        "2100",
        "PDOMapping=2",
        "PDOMapping must be 0 or 1",
    ),
    (
        "unknown key",
        "DefaultValue=3000",
        "DefaultValue=3000\nColour=blue",
        "2100",
        "Colour=blue",
        "unknown key 'Colour'",
    ),
    (
        "SubNumber mismatch",
        "ObjectType=0x9\nSubNumber=3",
        "ObjectType=0x9\nSubNumber=4",
        "1018",
        "SubNumber=4",
        "SubNumber=4 but 3 sub-sections exist",
    ),
    (
        "sub-index 0 not UNSIGNED8",
        "[1018sub0]\nParameterName=Highest sub-index supported\nDataType=0x0005",
        "[1018sub0]\nParameterName=Highest sub-index supported\nDataType=0x0006",
        "1018sub0",
        "DataType=0x0006",
        "sub-index 0 must be UNSIGNED8",
    ),
    (
        "sub-section without parent",
        "[6041]\n",
        "[6042sub1]\nParameterName=x\nDataType=0x0005\nAccessType=ro\n\n[6041]\n",
        "6042sub1",
        "[6042sub1]",
        "object [6042] is not defined",
    ),
    (
        "compact name beyond CompactSubObj",
        "2=Middle gain",
        "7=Seventh gain",
        "2000Name",
        "7=Seventh gain",
        "sub-index '7' is not 1..3",
    ),
    (
        "vendor differs from identity",
        "VendorNumber=0x12",
        "VendorNumber=0x13",
        "DeviceInfo",
        "VendorNumber=0x13",
        "differs from 0x1018,1",
    ),
    (
        "malformed line",
        "ProductName=Mini drive",
        "ProductName Mini drive",
        "DeviceInfo",
        "ProductName Mini drive",
        "expected 'key=value'",
    ),
    (
        "duplicate key",
        "DefaultValue=3000",
        "DefaultValue=3000\ndefaultvalue=3001",
        "2100",
        "defaultvalue=3001",
        "duplicate key",
    ),
    (
        "duplicate section",
        "[6041]\n",
        "[6041]\nParameterName=x\n\n[6041]\n",
        "6041",
        ("[6041]", 2),
        "duplicate section (first on line",
    ),
]


@pytest.mark.parametrize(
    ("old", "new", "section", "line_text", "reason"),
    [rule[1:] for rule in EDS_RULES],
    ids=[rule[0] for rule in EDS_RULES],
)
def test_bad_eds_is_rejected_naming_file_line_section_and_reason(
    write_files, mini_eds: str, old: str, new: str, section: str, line_text: str | tuple[str, int], reason: str
) -> None:
    assert old in mini_eds, "the rule's starting text must exist in the valid file"
    text = mini_eds.replace(old, new, 1)
    path = write_files(eds=text, props=None)
    with pytest.raises(DictionaryError) as caught:
        load_dictionary(path)
    error = caught.value
    expected_line = line_of(text, line_text)
    if line_text == "ParameterName=Statusword":  # the duplicate [6041] header follows the first one's keys
        expected_line = text.splitlines().index("[6041]", expected_line) + 1
    assert (Path(error.file), error.line, error.section) == (path, expected_line, section)
    assert reason in error.reason
    assert str(error) == f"{path}:{expected_line}: [{section}] {error.reason}"


PROPS_RULES = [
    (
        "section for a missing object",
        "[2100]\nGroup=Motor",
        "[2200]\nGroup=Motor",
        "2200",
        "[2200]",
        "object 0x2200 does not exist",
    ),
    ("section for a missing sub-index", "[2000sub2]", "[2000sub9]", "2000sub9", "[2000sub9]", "has no sub-index 9"),
    (
        "not an object section",
        "[2100]\nGroup=Motor",
        "[Motor]\nGroup=Motor",
        "Motor",
        "[Motor]",
        "not an object section",
    ),
    ("bad SaveType", "SaveType=USER_PAR", "SaveType=EEPROM", "2100", "SaveType=EEPROM", "SaveType 'EEPROM'"),
    ("bad Enum key", "Enum.-5=Minus five", "Enum.five=Minus five", "2000", "Enum.five", "bad Enum key"),
    (
        "Enum value outside the type",
        "Enum.-5=Minus five",
        "Enum.40000=Too big",
        "2000",
        "Enum.40000",
        "does not fit 0x2000,1 (INTEGER16)",
    ),
    (
        "Enum value given twice",
        "Enum.-5=Minus five",
        "Enum.-5=Minus five\nEnum.-0x5=Again",
        "2000",
        "Enum.-0x5",
        "given twice",
    ),
    (
        "Bit beyond the width",
        "Bit.0=Ready to switch on",
        "Bit.16=Ready to switch on",
        "6041",
        "Bit.16",
        "bit 16 does not exist",
    ),
    ("bad Bit key", "Bit.0=Ready to switch on", "Bit.x=Ready to switch on", "6041", "Bit.x", "unknown key"),
    (
        "reversed bit range",
        "Bits.8-9=Manufacturer field",
        "Bits.9-8=Manufacturer field",
        "6041",
        "Bits.9-8",
        "reversed",
    ),
    (
        "overlapping bits",
        "Bits.8-9=Manufacturer field",
        "Bits.8-9=Manufacturer field\nBit.9=Again",
        "6041",
        "Bit.9=",
        "overlap",
    ),
    ("unknown key", "Reference=L42", "Reference=L42\nColour=blue", "2100", "Colour=blue", "unknown key 'Colour'"),
    ("zero scale", "Scale=0.5", "Scale=0", "2000", "Scale=0", "non-zero"),
    ("Pointer on a non-U32 object", "Pointer=0", "Pointer=1", "2100", "Pointer=1", "Pointer needs UNSIGNED32"),
    ("bad Pointer value", "Pointer=0", "Pointer=yes", "2100", "Pointer=yes", "Pointer must be 0 or 1"),
]


@pytest.mark.parametrize(
    ("old", "new", "section", "line_text", "reason"),
    [rule[1:] for rule in PROPS_RULES],
    ids=[rule[0] for rule in PROPS_RULES],
)
def test_bad_props_is_rejected_naming_file_line_section_and_reason(
    write_files, mini_props: str, old: str, new: str, section: str, line_text: str, reason: str
) -> None:
    assert old in mini_props
    text = mini_props.replace(old, new, 1)
    eds_path = write_files(props=text)
    with pytest.raises(DictionaryError) as caught:
        load_dictionary(eds_path)
    error = caught.value
    assert (Path(error.file), error.line, error.section) == (
        eds_path.with_suffix(".props"),
        line_of(text, line_text),
        section,
    )
    assert reason in error.reason
