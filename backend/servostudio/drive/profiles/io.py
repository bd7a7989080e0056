"""The I/O of each drive family, by semantic names (docs/io.md): logic inputs with the functions they may take and
how the drive is told, polarity, outputs, analog scaling, encoder emulation and the CANopen I/O extension.

The three devices configure their inputs in three ways, so the description says which:

- ``POINTER`` (XtrapulsPac, manual §3.2.5.1): every input INn has a destination 0x3050,n, the pointer
  ``index << 16 | sub << 8 | bit`` of the bit its state is copied into: 0x60FD0001 makes it the positive limit
  switch, 0x36010307 bit 7 of the sequence conditional input.  The polarity 0x3051 bit n−1 inverts INn.
- ``DEDICATED`` (CD1-k, manual 001 L3417-3436): each of the six inputs has one function of its own, which it keeps
  while its bit of 0x30FD is set (the factory 0x3F) and loses when freed for general use; there is no polarity.
- ``FIXED`` (encoTRive): the manual names the digital inputs 0x60FD and nothing to configure them with.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass


class Routing(enum.StrEnum):
    POINTER = "pointer"
    DEDICATED = "dedicated"
    FIXED = "fixed"


def pointer(index: int, sub: int, bit: int) -> int:
    """A dataflow pointer (``index << 16 | sub << 8 | bit``) as 0x3050 / 0x3054 hold them."""
    return index << 16 | sub << 8 | bit


@dataclass(frozen=True)
class Function:
    """What an input or output can be: ``value`` is the pointer a ``POINTER`` device stores (0 = none)."""

    key: str
    label: str
    value: int = 0
    #: −1 / +1 for the negative / positive limit switch: the fail-safe check looks at these
    limit: int = 0
    #: the bit of the sequence conditional input 0x3601,3 it feeds (the sequence editor's input names)
    condition_bit: int | None = None


@dataclass(frozen=True)
class LogicInput:
    name: str
    #: bit of the input image 0x60FD (bits 16 and up: the inputs themselves)
    bit: int
    physical: bool = True
    #: semantic name of its destination object (``POINTER``)
    destination: str | None = None
    #: bit of the polarity object (``POINTER``)
    polarity_bit: int | None = None
    #: its own function and the bit of the dedicated-function mask (``DEDICATED``)
    dedicated: str | None = None
    mask_bit: int | None = None


@dataclass(frozen=True)
class Output:
    name: str
    #: bit of the output image 0x60FE,1
    bit: int
    physical: bool = True
    #: semantic name of its source object and the bit of the output polarity (``POINTER``)
    source: str | None = None
    polarity_bit: int | None = None
    #: bits of the specific-outputs object that give it a function (CD1-k 0x30FF): function key → bit
    function_bits: Mapping[str, int] | None = None


@dataclass(frozen=True)
class Setting:
    """One configurable value (analog scaling, encoder emulation, extension module), in the dictionary's range."""

    key: str
    label: str
    address: tuple[int, int]
    #: the value is a dataflow pointer: shown in hex, and it can make the drive act on other objects
    is_pointer: bool = False


@dataclass(frozen=True)
class SettingGroup:
    key: str
    title: str
    settings: tuple[Setting, ...]
    #: live values shown beside the settings (read-only)
    live: tuple[Setting, ...] = ()


@dataclass(frozen=True)
class IoDescription:
    routing: Routing
    inputs: tuple[LogicInput, ...]
    #: every function an input may take, in the order a picker lists them
    functions: tuple[Function, ...]
    outputs: tuple[Output, ...] = ()
    output_functions: tuple[Function, ...] = ()
    #: semantic names: the input polarity (``POINTER``), the dedicated-function mask (``DEDICATED``), the output
    #: polarity and the object whose bits give outputs their function (CD1-k 0x30FF)
    input_polarity: str | None = None
    input_mask: str | None = None
    output_polarity: str | None = None
    output_functions_object: str | None = None
    groups: tuple[SettingGroup, ...] = ()
    #: what the manual leaves to the hardware, said on the page and by the fail-safe check
    note: str = ""
    #: a simulated drive only (``sim_physical_inputs``, 0x5F00): the test bench's inputs by bit, and what a 1 means
    sim_inputs: tuple[str, ...] = ()
    sim_meaning: str = ""

    def function(self, key: str) -> Function | None:
        return next((found for found in self.functions if found.key == key), None)

    def function_of_pointer(self, value: int) -> Function | None:
        return next((found for found in self.functions if found.value == value), None)

    def output_function(self, key: str) -> Function | None:
        return next((found for found in self.output_functions if found.key == key), None)

    def input(self, name: str) -> LogicInput | None:
        return next((found for found in self.inputs if found.name == name), None)

    def output(self, name: str) -> Output | None:
        return next((found for found in self.outputs if found.name == name), None)

    def setting(self, key: str) -> Setting | None:
        every = (setting for group in self.groups for setting in group.settings)
        return next((found for found in every if found.key == key), None)


# -- XtrapulsPac -----------------------------------------------------------------------------------------------

_DIGITAL_INPUTS, _CONTROL_WORD, _SEQUENCE_INPUT = 0x60FD, 0x6040, 0x3601

XTRAPULSPAC_INPUT_FUNCTIONS: tuple[Function, ...] = (
    Function("none", "No function"),
    Function("negative_limit", "Negative limit switch", pointer(_DIGITAL_INPUTS, 0, 0), limit=-1),
    Function("positive_limit", "Positive limit switch", pointer(_DIGITAL_INPUTS, 0, 1), limit=+1),
    Function("home", "Home switch", pointer(_DIGITAL_INPUTS, 0, 2)),
    Function("inhibit", "INHIBIT (drive disabled while active)", pointer(_DIGITAL_INPUTS, 0, 3)),
    Function("fault_reset", "RESET (fault reset)", pointer(_DIGITAL_INPUTS, 0, 12)),
    Function("enable", "ENABLE", pointer(_DIGITAL_INPUTS, 0, 13)),
    Function("motor_phasing", "Motor phasing start", pointer(_DIGITAL_INPUTS, 0, 14)),
    Function("quick_stop", "Quick stop", pointer(_DIGITAL_INPUTS, 0, 15)),
    Function("sequence_start", "Sequence START (control word bit 4)", pointer(_CONTROL_WORD, 0, 4)),
    Function("sequence_stop", "Sequence STOP (control word bit 5)", pointer(_CONTROL_WORD, 0, 5)),
    *(
        Function(f"sequence_number_{bit}", f"Sequence number bit {bit} (0x3601,1)", pointer(_SEQUENCE_INPUT, 1, bit))
        for bit in range(7)
    ),
    *(
        Function(
            f"condition_{bit}",
            f"Sequence condition bit {bit} (0x3601,3)",
            pointer(_SEQUENCE_INPUT, 3, bit),
            condition_bit=bit,
        )
        for bit in range(8)
    ),
)

_STATUS_WORD, _WARNINGS, _SEQUENCE_OUTPUTS = 0x6041, 0x3024, 0x3602

XTRAPULSPAC_OUTPUT_FUNCTIONS: tuple[Function, ...] = (
    Function("none", "No function (written through 0x60FE,1)"),
    Function("fault", "Fault (status word bit 3)", pointer(_STATUS_WORD, 0, 3)),
    Function("operation_enabled", "Operation enabled (status word bit 2)", pointer(_STATUS_WORD, 0, 2)),
    Function("warning", "Warning (status word bit 7)", pointer(_STATUS_WORD, 0, 7)),
    Function("target_reached", "Target reached (status word bit 10)", pointer(_STATUS_WORD, 0, 10)),
    Function("limit_switch_warning", "Limit switch active (0x3024 bit 16)", pointer(_WARNINGS, 0, 16)),
    Function("undervoltage_warning", "Undervoltage warning (0x3024 bit 19)", pointer(_WARNINGS, 0, 19)),
    *(
        Function(
            f"sequence_output_{bit}",
            f"Sequence output {bit + 1} (0x3602,1 bit {bit})",
            pointer(_SEQUENCE_OUTPUTS, 1, bit),
        )
        for bit in range(8)
    ),
)

#: the objects of the XtrapulsPac's I/O by semantic name (merged into its device profile)
XTRAPULSPAC_IO_OBJECTS: dict[str, tuple[int, int]] = {
    **{f"input_{n}_destination": (0x3050, n) for n in range(1, 11)},
    "input_polarity": (0x3051, 0),
    **{f"output_{n}_source": (0x3054, n) for n in range(1, 7)},
    "output_polarity": (0x3055, 0),
    "inputs_16": (0x3058, 1),
    "physical_inputs_16": (0x3058, 3),
    "virtual_inputs": (0x3059, 1),
    "virtual_link": (0x3059, 3),
    "extension_di_target_1": (0x3821, 1),
    "extension_di_target_2": (0x3821, 4),
    "extension_ai_target": (0x3823, 1),
}
#: of those, the ones that change what the drive does with its axis: an input may become ENABLE or a limit
#: switch, a polarity flip activates it, an extension input may feed the control word, its analog input a target
XTRAPULSPAC_IO_MOTION_OBJECTS = frozenset(
    {
        *(f"input_{n}_destination" for n in range(1, 11)),
        "input_polarity",
        "virtual_inputs",
        "virtual_link",
        "extension_di_target_1",
        "extension_di_target_2",
        "extension_ai_target",
    }
)


def _analog_input(n: int) -> SettingGroup:
    index = 0x30F0 + n
    return SettingGroup(
        f"analog_input_{n}",
        f"Analog input {n} (0x{index:04X}): 32-bit value = (16-bit value − offset) × gain / 256",
        (
            Setting(f"analog_input_{n}_offset", "Offset", (index, 3)),
            Setting(f"analog_input_{n}_gain", "Gain (256 = 1)", (index, 4)),
            Setting(f"analog_input_{n}_filter", "Filter (Hz)", (index, 5)),
        ),
        live=(
            Setting(f"analog_input_{n}_raw", "16-bit value (0x7FF0 ≈ 10 V)", (index, 1)),
            Setting(f"analog_input_{n}_value", "32-bit value", (index, 2)),
        ),
    )


def _extension() -> SettingGroup:
    rows = [Setting("extension_node", "Module node ID (0 = none)", (0x3828, 1))]
    rows.append(Setting("extension_control", "Control (bit 0 enable, 1 auto-restart, …)", (0x3828, 2)))
    for n, first in ((1, 1), (2, 4)):
        rows.append(Setting(f"extension_di_target_{n}", f"DI → target {n}", (0x3821, first), True))
        rows.append(Setting(f"extension_di_mask_{n}", f"DI mask {n}", (0x3821, first + 1)))
        rows.append(Setting(f"extension_di_shift_{n}", f"DI shift {n}", (0x3821, first + 2)))
    for n, first in ((1, 1), (2, 4)):
        rows.append(Setting(f"extension_do_source_{n}", f"DO ← source {n}", (0x3822, first), True))
        rows.append(Setting(f"extension_do_mask_{n}", f"DO mask {n}", (0x3822, first + 1)))
        rows.append(Setting(f"extension_do_shift_{n}", f"DO shift {n}", (0x3822, first + 2)))
    rows += [
        Setting("extension_ai_target", "AI → target", (0x3823, 1), True),
        Setting("extension_ai_offset", "AI offset", (0x3823, 2)),
        Setting("extension_ai_gain", "AI gain (256 = 1)", (0x3823, 3)),
        Setting("extension_ao_source", "AO ← source", (0x3824, 1), True),
        Setting("extension_ao_offset", "AO offset", (0x3824, 2)),
        Setting("extension_ao_gain", "AO gain (256 = 1)", (0x3824, 3)),
    ]
    live = (
        Setting("extension_status", "Status", (0x3828, 3)),
        Setting("extension_hardware", "Module hardware (bit 0 DI, 1 DO, 2 AI, 3 AO)", (0x3828, 4)),
        Setting("extension_inputs", "Module digital inputs", (0x3829, 1)),
        Setting("extension_outputs", "Module digital outputs", (0x3829, 2)),
    )
    return SettingGroup("extension", "CANopen I/O extension (DS-401 module, 0x3821-0x3829)", tuple(rows), live)


XTRAPULSPAC_IO = IoDescription(
    routing=Routing.POINTER,
    inputs=tuple(
        LogicInput(f"IN{n}", 15 + n, physical=n <= 5, destination=f"input_{n}_destination", polarity_bit=n - 1)
        for n in range(1, 11)
    ),
    functions=XTRAPULSPAC_INPUT_FUNCTIONS,
    outputs=tuple(
        Output(f"OUT{n}", 15 + n, physical=n <= 3, source=f"output_{n}_source", polarity_bit=n - 1) for n in range(1, 7)
    ),
    output_functions=XTRAPULSPAC_OUTPUT_FUNCTIONS,
    input_polarity="input_polarity",
    output_polarity="output_polarity",
    groups=(
        _analog_input(1),
        _analog_input(2),
        SettingGroup(
            "analog_output",
            "Analog output (0x30A1): output = (source + offset) × gain / 256, −32768..32767 ↔ 0..5 V",
            (
                Setting("analog_output_source", "Source", (0x30A1, 2), True),
                Setting("analog_output_offset", "Offset", (0x30A1, 3)),
                Setting("analog_output_gain", "Gain (256 = 1)", (0x30A1, 4)),
            ),
        ),
        SettingGroup(
            "encoder_emulation",
            "Encoder emulation output (0x3160): Source 1 − Source 2 as A/B/Z",
            (
                Setting("encoder_output_source_1", "Source 1", (0x3160, 1), True),
                Setting("encoder_output_source_2", "Source 2 (0 = none)", (0x3160, 2), True),
                Setting("encoder_output_resolution", "Resolution (ppr)", (0x3160, 3)),
                Setting("encoder_output_deadband", "Deadband", (0x3160, 4)),
                Setting("encoder_output_z_shift", "Top Z shift (65536 = 1 rev)", (0x3160, 5)),
                Setting("encoder_output_configuration", "Configuration (bit 0 enable, …)", (0x3160, 6)),
            ),
        ),
        _extension(),
    ),
    note="IN1..IN5 are wired, IN6..IN10 are virtual (0x3059,1); OUT1..OUT3 are wired, OUT4..OUT6 virtual.",
    sim_inputs=tuple(f"IN{n}" for n in range(1, 6)),
    sim_meaning="1 = 24 V wired to the input (before its polarity)",
)

# -- CD1-k -----------------------------------------------------------------------------------------------------

CD1K_INPUT_FUNCTIONS: tuple[Function, ...] = (
    Function("general", "General input (0x60FD bit only)"),
    Function("positive_limit", "Positive limit switch (LS+)", limit=+1),
    Function("negative_limit", "Negative limit switch (LS−)", limit=-1),
    Function("inhibit", "INHIBIT"),
    Function("index", "INDEX"),
    Function("capture", "CAPTURE"),
    Function("low_speed", "LOW SPEED"),
)

CD1K_OUTPUT_FUNCTIONS: tuple[Function, ...] = (
    Function("general", "General output (0x60FE,1)"),
    Function("amplifier_error", "Amplifier error (active 0)"),
    Function("cam", "Cam status"),
)

CD1K_IO_OBJECTS: dict[str, tuple[int, int]] = {
    "input_mask": (0x30FD, 0),
    "specific_outputs": (0x30FF, 0),
    "analog_setpoint_select": (0x30C0, 0),
    # simulator only (docs/io.md): the test bench's activation of INPUT0..INPUT5, absent from the EDS
    "sim_physical_inputs": (0x5F00, 0),
}
#: freeing LS+ lets the axis run past its switch; AIN1 as the set point changes what an enabled axis does
CD1K_IO_MOTION_OBJECTS = frozenset({"input_mask", "analog_setpoint_select", "sim_physical_inputs"})

_CD1K_INPUTS = (
    ("INPUT0 / LS+", "positive_limit"),
    ("INPUT1 / LS−", "negative_limit"),
    ("INHIBIT", "inhibit"),
    ("INPUT3 / INDEX", "index"),
    ("INPUT4 / CAPTURE", "capture"),
    ("INPUT5 / LOW SPEED", "low_speed"),
)

CD1K_IO = IoDescription(
    routing=Routing.DEDICATED,
    inputs=tuple(
        LogicInput(name, 16 + bit, dedicated=function, mask_bit=bit)
        for bit, (name, function) in enumerate(_CD1K_INPUTS)
    ),
    functions=CD1K_INPUT_FUNCTIONS,
    outputs=tuple(Output(f"DO{n}", 16 + n, function_bits={"amplifier_error": n, "cam": 4 + n}) for n in range(4)),
    output_functions=CD1K_OUTPUT_FUNCTIONS,
    input_mask="input_mask",
    output_functions_object="specific_outputs",
    groups=(
        SettingGroup(
            "analog_input_1",
            "Analog input 1 (±10 V = ±0x7FFF)",
            (
                Setting("analog_setpoint_select", "Set point (0 CAN, 1 AIN1 for pv / torque)", (0x30C0, 0)),
                Setting("analog_input_1_filter", "Low-pass filter (1000/π·ln(65536/x) Hz)", (0x30C2, 0)),
            ),
            live=(Setting("analog_input_1_raw", "Voltage", (0x30C1, 0)),),
        ),
        SettingGroup(
            "analog_input_2",
            "Analog input 2 (±10 V = ±0x7FFF)",
            (),
            live=(Setting("analog_input_2_raw", "Voltage", (0x30C3, 0)),),
        ),
        SettingGroup(
            "encoder_emulation",
            "Encoder emulation output (0x3487, on the TTL encoder input's pins)",
            (
                Setting("encoder_output_resolution", "Resolution (ppr)", (0x3487, 1)),
                Setting("encoder_output_division", "Division ratio (1/2^n)", (0x3487, 2)),
                Setting("encoder_output_deadband", "Deadband", (0x3487, 3)),
                Setting("encoder_output_z_shift", "Zero-pulse shift (32767 = 1 rev)", (0x3487, 4)),
                Setting("encoder_output_enable", "Enable (0/1)", (0x3487, 5)),
            ),
        ),
        SettingGroup(
            "capture", "Capture inputs (0x3389)", (Setting("capture_inputs", "Capture input selection", (0x3389, 0)),)
        ),
    ),
    note=(
        "The CD1-k has no input polarity object: each input's active level is its hardware's. An input keeps its "
        "function while its 0x30FD bit is set; freed, it is a general input read in 0x60FD bits 16-21."
    ),
    sim_inputs=tuple(name for name, _ in _CD1K_INPUTS),
    sim_meaning="1 = input active (besides the plant's own limit switches on LS+ / LS−)",
)

# -- encoTRive -------------------------------------------------------------------------------------------------

ENCOTRIVE_IO = IoDescription(
    routing=Routing.FIXED,
    inputs=(),
    functions=(),
    note=(
        "The encoTRive manual names the digital inputs 0x60FD and the holding brake 0x60FE,1 bit 0, but no object "
        "to give an input a function or a polarity: its I/O is read here, not configured."
    ),
)
