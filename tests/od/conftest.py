"""A small, valid EDS + props pair that the od tests copy and break one rule at a time."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from servostudio.od import ObjectDictionary, load_dictionary

MINI_EDS = """\
[FileInfo]
FileName=mini.eds
EDSVersion=4.0
; a comment line

[DeviceInfo]
VendorName=Test
VendorNumber=0x12
ProductName=Mini drive
ProductNumber=0x34
RevisionNumber=1

[MandatoryObjects]
SupportedObjects=3
1=0x1000
2=0x1001
3=0x1018

[OptionalObjects]
SupportedObjects=2
1=0x1800
2=0x6041

[ManufacturerObjects]
SupportedObjects=2
1=0x2000
2=0x2100

[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x00020192

[1001]
ParameterName=Error register
DataType=0x0005
AccessType=ro
PDOMapping=1

[1018]
ParameterName=Identity
ObjectType=0x9
SubNumber=3

[1018sub0]
ParameterName=Highest sub-index supported
DataType=0x0005
AccessType=const
DefaultValue=2

[1018sub1]
ParameterName=Vendor-ID
DataType=0x0007
AccessType=ro
DefaultValue=0x12

[1018sub2]
ParameterName=Product code
DataType=0x0007
AccessType=ro
DefaultValue=0x34

[1800]
ParameterName=TPDO1 communication parameter
ObjectType=0x9
SubNumber=2

[1800sub0]
ParameterName=Highest sub-index supported
DataType=0x0005
AccessType=ro
DefaultValue=1

[1800sub1]
ParameterName=COB-ID used by TPDO
DataType=0x0007
AccessType=rw
DefaultValue=$NODEID+0x180

[6041]
ParameterName=Statusword
DataType=0x0006
AccessType=ro
PDOMapping=1

[2000]
ParameterName=Gains
ObjectType=0x8
DataType=0x0003
AccessType=rw
CompactSubObj=3
LowLimit=-100
HighLimit=100
DefaultValue=5

[2000Name]
NrOfEntries=1
2=Middle gain

[2100]
ParameterName=Speed limit
DataType=0x0006
AccessType=rw
LowLimit=10
HighLimit=6000
DefaultValue=3000
"""

MINI_PROPS = """\
; companion of mini.eds
[6041]
Group=Device Control
Bit.0=Ready to switch on
Bits.8-9=Manufacturer field

[2000]
Group=Servo Loops
Unit=mA
Scale=0.5
SaveType=DRIVEPAR
Enum.-5=Minus five

[2000sub2]
Description=The middle one

[2100]
Group=Motor
Unit=rpm
SaveType=USER_PAR
Reference=L42
Pointer=0
"""

WriteFiles = Callable[..., Path]


@pytest.fixture(scope="session")
def mini_eds() -> str:
    return MINI_EDS


@pytest.fixture(scope="session")
def mini_props() -> str:
    return MINI_PROPS


@pytest.fixture(scope="session")
def mini_od(tmp_path_factory: pytest.TempPathFactory) -> ObjectDictionary:
    """The valid mini dictionary, loaded once (for property-based tests that must not use function fixtures)."""
    directory = tmp_path_factory.mktemp("mini")
    (directory / "mini.eds").write_text(MINI_EDS, encoding="utf-8")
    (directory / "mini.props").write_text(MINI_PROPS, encoding="utf-8")
    return load_dictionary(directory / "mini.eds")


@pytest.fixture
def write_files(tmp_path: Path) -> WriteFiles:
    """Write mini.eds (+ mini.props) with optional text replacements; returns the EDS path."""

    def write(eds: str = MINI_EDS, props: str | None = MINI_PROPS, name: str = "mini") -> Path:
        eds_path = tmp_path / f"{name}.eds"
        eds_path.write_text(eds, encoding="utf-8")
        if props is not None:
            (tmp_path / f"{name}.props").write_text(props, encoding="utf-8")
        return eds_path

    return write
