"""Objects only a simulated drive has: the test bench's wiring, reachable over the bus like any other object.

They live in the manufacturer range 0x5F00–0x5F0F, which the simulator reserves for itself (docs/simulator.md): no
device dictionary the product ships uses it, and the product's dictionaries never gain these objects, so the tool
cannot mistake them for a real drive's. A client reaches them by raw SDO or PDO (an EDS-driven client has no entry
for them).

- 0x5F00 "SIM: physical inputs" (U16 rw, PDO): the electrical level of the XtrapulsPac's logic inputs IN1..IN5
  (bit 0 = IN1), as if 24 V were wired to them; the drive reads them through its polarity and input routing
  (0x3051, 0x3050), see docs/sequences.md.  On the CD1-k, which has no input polarity, bit n activates its
  INPUTn (INPUT0 = LS+ … INPUT5 = LOW SPEED), in addition to the plant's limit switches on LS+ / LS− (docs/io.md).
"""

from __future__ import annotations

from functools import cache

from servostudio.od.datatypes import DataType
from servostudio.od.model import Access, BitField, DictObject, ObjectDictionary, ObjectKind, Variable

SIMULATOR_RANGE = range(0x5F00, 0x5F10)
PHYSICAL_INPUTS = 0x5F00
GROUP = "Simulator"

_INPUT_ROUTING = (0x3050, 1)
_PHYSICAL_INPUT_IMAGE = (0x3058, 3)
_DEDICATED_INPUT_MASK = (0x30FD, 0)
#: (input names, what a bit means) by the object that tells the device
_XTRAPULSPAC_INPUTS = (tuple(f"IN{n}" for n in range(1, 6)), "the levels wired to IN1..IN5 (1 = 24 V)")
_CD1K_INPUTS = (
    ("INPUT0 / LS+", "INPUT1 / LS-", "INHIBIT", "INPUT3 / INDEX", "INPUT4 / CAPTURE", "INPUT5 / LOW SPEED"),
    "inputs INPUT0..INPUT5 activated by the test bench (1 = active), besides the plant's limit switches",
)


@cache
def with_simulator_objects(od: ObjectDictionary) -> ObjectDictionary:
    """`od` with the simulator's objects its drive model reads, as a new dictionary (the product keeps its own).

    The physical inputs go to a device that routes logic inputs (0x3050) and shows their image (0x3058,3): the
    XtrapulsPac; or to one whose inputs have dedicated functions (0x30FD): the CD1-k. A dictionary that already
    uses the reserved range is refused.
    """
    taken = [index for index in SIMULATOR_RANGE if index in od]
    if taken:
        raise ValueError(f"{od.device}: 0x{taken[0]:04X} lies in the simulator's reserved range 0x5F00–0x5F0F")
    if _INPUT_ROUTING in od and _PHYSICAL_INPUT_IMAGE in od:
        inputs = _XTRAPULSPAC_INPUTS
    elif _DEDICATED_INPUT_MASK in od:
        inputs = _CD1K_INPUTS
    else:
        return od
    objects = [*od.objects(), _physical_inputs(*inputs)]
    return ObjectDictionary(od.device, od.product_name, od.vendor_id, od.product_code, od.revision, od.source, objects)


def _physical_inputs(names: tuple[str, ...], meaning: str) -> DictObject:
    name = "SIM: physical inputs"
    count = len(names)
    variable = Variable(
        index=PHYSICAL_INPUTS,
        subindex=0,
        name=name,
        data_type=DataType.UNSIGNED16,
        access=Access.RW,
        pdo_mappable=True,
        low=0,
        high=(1 << count) - 1,
        default=0,
        group=GROUP,
        description=f"Simulator only: {meaning}; kept through a warm reset",
        bits=tuple(BitField(n, n, label) for n, label in enumerate(names)),
        parent_name=name,
    )
    return DictObject(PHYSICAL_INPUTS, name, ObjectKind.VAR, GROUP, {0: variable})
