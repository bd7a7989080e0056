"""The simulated TTA-PRO's PKW channel (TTA-PRO Profibus Communication Profile, Chapter 1 §3): a request is
served once, in the next positioner cycle, and its reply stays; procedures answer 0 while they run, then 1; the
same procedure again needs PKE = 0 in between; values and refusals travel as the manual says."""

from __future__ import annotations

from tests.support.ttapro_rig import Rig, request

from servostudio.od.pnu_model import ParameterDictionary


def test_a_request_is_served_in_the_next_cycle_and_its_reply_stays(rig: Rig) -> None:
    rig.slave.pkw.receive(request(1, 721))
    assert rig.slave.read_inputs()[:8] == bytes(8)  # not served before a positioner cycle
    rig.cycle(request(1, 721))
    assert rig.pkw_reply == (1, 721, 0, 4000)
    rig.cycle(request(1, 721), cycles=3)
    assert rig.pkw_reply == (1, 721, 0, 4000)
    rig.cycle()
    assert rig.pkw_reply == (0, 0, 0, 0)  # AK 0 clears the reply


def test_a_held_write_is_executed_once(rig: Rig) -> None:
    writes = []
    rig.slave.memory.on_write(763, lambda index, value: writes.append(value))
    rig.cycle(request(2, 763, 700), cycles=5)
    assert writes == [700]
    assert rig.pkw_reply == (1, 763, 0, 700)


def test_a_procedure_answers_running_then_done_and_needs_pke_0_to_run_again(rig: Rig) -> None:
    rig.write(760, 1234)
    rig.cycle(request(2, 729))
    assert rig.pkw_reply == (1, 729, 0, 0)  # running
    rig.cycle(request(2, 729), cycles=120)
    assert rig.pkw_reply == (1, 729, 0, 1)  # done after its 0.1 s
    assert rig.slave.memory.eeprom[(760, 0)] == 1234
    rig.slave.memory.set(760, 99)
    rig.cycle(request(2, 729), cycles=120)
    assert rig.slave.memory.eeprom[(760, 0)] == 1234  # the held request did not save again
    rig.cycle()
    rig.cycle(request(2, 729), cycles=120)
    assert rig.slave.memory.eeprom[(760, 0)] == 99


def test_saving_while_enabled_is_refused_and_unsimulated_procedures_say_so(rig: Rig) -> None:
    rig.enable()
    assert rig.transaction(2, 729)[0::3] == (7, 17)
    assert rig.transaction(2, 736, 1)[0::3] == (7, 18)


def test_feedback_programming_runs_with_the_drive_disabled_and_applies_the_selection(rig: Rig) -> None:
    rig.write(893, 1)  # motor feedback: the encoder input
    rig.enable()
    assert rig.transaction(2, 894, 1)[0::3] == (7, 17)  # "with disabled positioner" (L3105)
    assert rig.slave.feedback_programmings == []
    rig.control(0x0406, cycles=20)  # OFF1: back to Ready for ENABLE, the power stage off
    rig.cycle(cycles=2)
    rig.cycle(request(2, 894, 1))
    assert rig.pkw_reply == (1, 894, 0, 0)  # running: the simulator's 0.2 s, the real drive's ≈ 5 s
    assert rig.run_procedure(894, 1, cycles=300) == 1
    applied = rig.slave.feedback_programmings
    assert len(applied) == 1 and applied[0][893] == 1 and set(applied[0]) == {890, 891, 892, 893, 898}


def test_signed_values_travel_in_twos_complement(rig: Rig) -> None:
    assert rig.write(768, -5)[3] == 0xFFFFFFFB
    assert rig.read(768) == 0xFFFFFFFB
    assert rig.write(788, -1)[3] == 0xFFFF  # link "none" of the sequence buffer, a signed word


def test_a_word_reply_uses_bytes_7_and_8_and_a_double_word_bytes_5_to_8(rig: Rig) -> None:
    rig.cycle(request(1, 721), cycles=2)
    assert rig.slave.read_inputs()[4:8] == bytes((0, 0, 0x0F, 0xA0))
    rig.cycle()
    rig.cycle(request(1, 747), cycles=2)
    assert rig.slave.read_inputs()[4:8] == bytes((0x7F, 0xFF, 0xFF, 0xFF))


def test_the_double_word_reply_code_can_be_the_profidrive_one(parameters: ParameterDictionary) -> None:
    rig = Rig(parameters, double_reply_ak=2)
    assert rig.transaction(1, 747)[0] == 2
    assert rig.transaction(1, 721)[0] == 1


def test_mapping_writes_take_only_documented_signal_codes(rig: Rig) -> None:
    assert rig.write(828, 0x22ED, index=1)[0] == 1
    assert rig.write(828, 0x1234, index=1)[0::3] == (7, 2)
    assert rig.transaction(1, 828, index=3)[0::3] == (7, 3)
