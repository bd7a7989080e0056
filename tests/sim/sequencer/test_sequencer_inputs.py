"""The simulated drive's logic inputs: the simulator-only object 0x5F00 (IN1..IN5 wiring), the virtual inputs,
their polarity and the 0x3050 routing that feeds the conditional input 0x3601,3 and the START bit."""

from __future__ import annotations

import canopen
import pytest
from tests.support.sequencer_bench import EXECUTED, SIM_PHYSICAL_INPUTS, Bench
from tests.support.waits import wait_for

from servostudio.od import builtin_library

IN1_TO_CONDITION_BIT_15 = 0x3601030F
IN8_TO_CONDITION_BIT_7 = 0x36010307
IN2_TO_START = 0x60400004
VALUE_TOO_HIGH = 0x06090031


def test_the_physical_inputs_object_exists_only_in_the_simulated_drive(bench: Bench):
    assert 0x5F00 not in builtin_library().load("xtrapulspac")
    assert 0x5F00 not in bench.node.object_dictionary
    bench.set_physical_inputs(0b10011)
    assert int.from_bytes(bench.node.sdo.upload(SIM_PHYSICAL_INPUTS, 0), "little") == 0b10011
    with pytest.raises(canopen.SdoAbortedError) as refused:
        bench.set_physical_inputs(0b100000)  # there is no IN6 to wire
    assert refused.value.code == VALUE_TOO_HIGH


def test_inputs_show_through_their_polarity_in_0x60fd_and_0x3058(bench: Bench):
    bench.write(0x3051, 0b0000000001)  # IN1 inverted
    bench.write(0x3059, 0b0010000000, 1)  # virtual IN8 on
    bench.set_physical_inputs(0b10101)
    assert bench.read(0x3058, 3) == 0b10101  # raw hardware
    assert bench.read(0x3058, 1) == 0b0010010100
    assert bench.read(0x60FD) >> 16 & 0x3FF == 0b0010010100


def test_routed_inputs_set_their_destination_bits(bench: Bench):
    bench.write(0x3050, IN1_TO_CONDITION_BIT_15, 1)
    bench.write(0x3050, IN8_TO_CONDITION_BIT_7, 8)
    bench.set_physical_inputs(0b1)
    bench.write(0x3059, 0b0010000000, 1)
    assert bench.read(0x3601, 3) == -0x8000 + 0x80  # bit 15 of the Integer16
    bench.set_physical_inputs(0)
    assert bench.read(0x3601, 3) == 0x80


def test_the_wiring_survives_a_warm_reset(bench: Bench):
    bench.set_physical_inputs(0b01100)
    bench.write(0x205D, 2)
    bench.node.nmt.state = "RESET"
    wait_for(lambda: bench.network.node(1).state.value == "PRE-OPERATIONAL", bool, "the node booted")
    assert bench.read(0x3058, 3) == 0b01100 and bench.read(0x60FD) >> 16 & 0x1F == 0b01100


def test_an_input_routed_to_the_start_bit_starts_the_selected_sequence(bench: Bench):
    bench.load_program("SeqNb=7\nSeqType=SPEED\nSpeed=0\nAccelTime=1\nTempo=20\n")
    bench.write(0x3050, IN2_TO_START, 2)
    bench.enable_sequence_mode()
    bench.write(0x3601, 7, 1)
    mark = len(bench.rows())
    bench.set_physical_inputs(0b10)
    rows = bench.wait_program_end(mark)
    assert 7 in {row[EXECUTED] for row in rows}
