"""The I/O descriptions of the device profiles (drive/profiles/io.py) against the dictionaries the product ships:
every object they name exists with a type that fits, and the XtrapulsPac's input functions are the manual's
pointers (§3.2.5.1: 0x60FD bits, the control word's START / STOP, the sequence inputs 0x3601,1 / 3)."""

from __future__ import annotations

import pytest

from servostudio.drive.profiles import PROFILES
from servostudio.drive.profiles.io import Routing, pointer
from servostudio.od import builtin_library

SIMULATOR_ONLY = 0x5F00


@pytest.mark.parametrize("device", sorted(device for device, profile in PROFILES.items() if profile.canopen))
def test_every_io_object_is_in_the_dictionary(device: str):  # the TTA-PRO's I/O is a later stage (profibus.md §11)
    profile, od = PROFILES[device], builtin_library().load(device)
    io = profile.io
    assert io is not None
    names = [io.input_polarity, io.input_mask, io.output_polarity, io.output_functions_object]
    names += [row.destination for row in io.inputs] + [row.source for row in io.outputs]
    for name in filter(None, names):
        assert profile.address(name) in od, name
    for group in io.groups:
        for setting in (*group.settings, *group.live):
            variable = od[setting.address]
            assert variable.data_type.is_integer, setting.key
            if setting.is_pointer:
                assert variable.data_type.fixed_size == 4, setting.key
    for name in ("digital_inputs", "digital_outputs"):
        assert profile.address(name) in od
    if io.sim_inputs:
        assert profile.address("sim_physical_inputs")[0] == SIMULATOR_ONLY
        assert SIMULATOR_ONLY not in od  # the product's dictionary never has the test bench's object


def test_the_xtrapulspac_functions_are_the_manuals_pointers():
    io = PROFILES["xtrapulspac"].io
    assert io is not None and io.routing is Routing.POINTER
    by_key = {function.key: function.value for function in io.functions}
    assert by_key["inhibit"] == 0x60FD0003  # the manual's ENABLE example: 0x3050,1 = 0x60FD0003
    assert by_key["sequence_start"] == 0x60400004
    assert by_key["condition_7"] == 0x36010307  # "logic input 8" of the conditional jump
    assert len(set(by_key.values())) == len(by_key)  # a pointer names one function
    assert [row.name for row in io.inputs if row.physical] == ["IN1", "IN2", "IN3", "IN4", "IN5"]
    assert pointer(0x3024, 0, 19) in {function.value for function in io.output_functions}  # undervoltage → OUT


def test_the_cd1k_inputs_keep_or_lose_their_own_function():
    io = PROFILES["cd1k"].io
    assert io is not None and io.routing is Routing.DEDICATED and io.input_polarity is None
    assert [(row.dedicated, row.mask_bit) for row in io.inputs][:2] == [("positive_limit", 0), ("negative_limit", 1)]
    assert all(io.function(row.dedicated or "") is not None for row in io.inputs)


def test_the_encotrive_has_nothing_to_configure():
    io = PROFILES["encotrive"].io
    assert io is not None and io.routing is Routing.FIXED and not io.inputs and not io.groups
