"""A small valid user EDS + props pair (device "acme"), imported through REST by the API tests and through
`servostudio eds` by the CLI tests."""

from __future__ import annotations

from pathlib import Path

SMALL_EDS = """\
[FileInfo]
FileName=acme.eds
FileVersion=1
FileRevision=0
EDSVersion=4.0
Description=Test device
CreationTime=12:00PM
CreationDate=11-21-2026
CreatedBy=Servo Studio tests

[DeviceInfo]
VendorName=Acme
VendorNumber=0x12345
ProductName=Acme Drive
ProductNumber=0x42
RevisionNumber=0x10001
BaudRate_10=0
BaudRate_20=0
BaudRate_50=0
BaudRate_125=1
BaudRate_250=1
BaudRate_500=1
BaudRate_800=0
BaudRate_1000=1
SimpleBootUpMaster=0
SimpleBootUpSlave=1
Granularity=8
DynamicChannelsSupported=0
GroupMessaging=0
NrOfRXPDO=0
NrOfTXPDO=0
LSS_Supported=0

[DummyUsage]
Dummy0001=0
Dummy0002=0
Dummy0003=0
Dummy0004=0
Dummy0005=0
Dummy0006=0
Dummy0007=0

[MandatoryObjects]
SupportedObjects=3
1=0x1000
2=0x1001
3=0x1018

[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x00020192
PDOMapping=0

[1001]
ParameterName=Error register
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=0
PDOMapping=1

[1018]
ParameterName=Identity object
ObjectType=0x9
SubNumber=3

[1018sub0]
ParameterName=Number of entries
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=2
PDOMapping=0

[1018sub1]
ParameterName=Vendor ID
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x12345
PDOMapping=0

[1018sub2]
ParameterName=Product code
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x42
PDOMapping=0

[OptionalObjects]
SupportedObjects=0

[ManufacturerObjects]
SupportedObjects=1
1=0x2000

[2000]
ParameterName=Speed limit
ObjectType=0x7
DataType=0x0006
AccessType=rw
LowLimit=10
HighLimit=6000
DefaultValue=3000
PDOMapping=0
"""

SMALL_PROPS = """\
[2000]
Group=Motor
Unit=rpm
SaveType=DRIVEPAR
Description=Maximum motor speed
"""


def write_small_eds(directory: Path, text: str = SMALL_EDS) -> Path:
    """acme.eds (``text``) and acme.props in ``directory``; returns the EDS path."""
    eds = directory / "acme.eds"
    eds.write_text(text)
    (directory / "acme.props").write_text(SMALL_PROPS)
    return eds
