"""Starting, stopping and conditions: control word bits 4 and 5, RunTime 65535 left by an end condition, a start
condition waited for (SeqLink = −1), the SEQ output's minimum pulse 0x3603, pulse outputs 0x3604, and what a
disable does to a running program."""

from __future__ import annotations

import pytest
from tests.support.sequencer_bench import (
    BEGIN,
    CRUISE,
    DECEL,
    DEDICATED,
    END,
    EXECUTED,
    HOLD,
    OUTPUTS,
    PHASE,
    REV,
    STATUS_WORD,
    Bench,
    first,
)
from tests.support.waits import wait_for

SEQ = 1 << 1  # dedicated output bit 1
IN1_TO_CONDITION_BIT_0 = 0x36010300  # 0x3050,1: IN1 -> 0x3601,3 bit 0
ENDLESS = f"SeqNb=1\nSeqType=SPEED\nSpeed={5 * REV}\nAccelTime=50\nDecelTime=50\nRunTime=65535\n"


def test_run_time_65535_runs_until_the_end_condition_then_chains(bench: Bench):
    bench.write(0x3050, IN1_TO_CONDITION_BIT_0, 1)
    bench.load_program(ENDLESS + 'EndCond=".......1"\nSeqNext=2\n' + "SeqNb=2\nSeqType=SPEED\nSpeed=0\nAccelTime=1\n")
    bench.enable_sequence_mode()
    mark = bench.start(1)
    bench.run_for(0.5)
    assert bench.read(0x3601, 2) == 1 and abs(bench.read(0x606C) - 5 * REV) < 0.02 * 5 * REV
    bench.set_physical_inputs(0b1)
    rows = bench.wait_program_end(mark)
    decel = first(rows, lambda row: row[PHASE] & DECEL, "the deceleration")
    assert decel.time - first(rows, lambda row: row[PHASE] & CRUISE, "cruise").time > 0.4
    assert first(rows, lambda row: row[EXECUTED] == 2, "sequence 2").time > decel.time


def test_bit_5_stops_the_program_without_its_end_and_without_chaining(bench: Bench):
    bench.load_program(ENDLESS + "SeqNext=2\nSeqNb=2\nSeqType=SPEED\nSpeed=0\nAccelTime=1\n")
    bench.enable_sequence_mode()
    mark = bench.start(1)
    bench.run_for(0.3)
    bench.stop()
    rows = bench.wait_program_end(mark)
    assert {row[EXECUTED] for row in rows} == {-1, 1}
    assert rows[-1][PHASE] == BEGIN | CRUISE | DECEL | HOLD  # braked to standstill, no END
    bench.run_for(0.1)  # 0x606C is filtered (80 Hz): it lags the standstill
    assert bench.read(0x606C) == pytest.approx(0, abs=0.02 * 5 * REV)
    status = wait_for(lambda: bench.read(0x6041), lambda status: status & 0x400, "target reached (SW10)")
    assert not status & 0x2000  # SW13: no sequence running


def test_a_start_condition_is_waited_for_when_seq_link_is_minus_1(bench: Bench):
    bench.write(0x3050, IN1_TO_CONDITION_BIT_0, 1)
    move = f"SeqType=POS\nPosType=REL\nPos={REV}\nSpeed={10 * REV}\nAccel={100 * REV}\nDecel={100 * REV}\n"
    bench.load_program(f'SeqNb=3\n{move}StartCond=".......1"\n')
    bench.enable_sequence_mode()
    mark = bench.start(3)
    bench.run_for(0.2)
    waiting = bench.rows(mark)[-1]
    assert (waiting[EXECUTED], waiting[PHASE]) == (3, 0) and waiting[STATUS_WORD] & 0x2000  # shown, not begun; SEQ
    assert bench.read(0x6064) == 0
    bench.set_physical_inputs(0b1)
    rows = bench.wait_program_end(mark)
    assert first(rows, lambda row: row[PHASE] & END, "the end")
    assert abs(bench.settled_position() - REV) <= 2


def test_the_seq_output_lasts_at_least_the_minimum_sequence_pulse(bench: Bench):
    bench.write(0x3603, 100)  # ms
    bench.load_program("SeqNb=1\nSeqType=SPEED\nSpeed=0\nAccelTime=1\n")  # over in one control period
    bench.enable_sequence_mode()
    mark = bench.start(1)
    bench.wait_program_end(mark)
    bench.run_for(0.2)
    rows = bench.rows(mark)
    rise = first(rows, lambda row: row[DEDICATED] & SEQ, "SEQ on")
    fall = first(rows, lambda row: row.time > rise.time and not row[DEDICATED] & SEQ, "SEQ off")
    over = first(rows, lambda row: row[EXECUTED] == -1 and row.time > rise.time, "the program over")
    assert over.time - rise.time < 0.01
    assert fall.time - rise.time == pytest.approx(0.100, abs=0.0005)
    seq_bit = [bool(row[STATUS_WORD] & 0x2000) for row in rows if rise.time + 0.002 <= row.time <= fall.time + 0.05]
    assert seq_bit == sorted(seq_bit, reverse=True) and seq_bit[0] and not seq_bit[-1]  # SW13 follows SEQ (1 ms)


def test_a_pulse_output_goes_off_after_the_pulse_duration(bench: Bench):
    bench.write(0x3604, 0b0100, 1)  # output bit 2 is a pulse output
    bench.write(0x3604, 30, 2)  # of 30 ms
    bench.load_program(
        f'SeqNb=1\nSeqType=SPEED\nSpeed={REV}\nAccelTime=10\nRunTime=200\nDecelTime=10\nTrigger=BEGIN\nOutput=".....11."\n'
    )
    bench.enable_sequence_mode()
    rows = bench.wait_program_end(bench.start(1))
    begin = first(rows, lambda row: row[PHASE] == BEGIN and row[EXECUTED] == 1, "the beginning")
    assert begin[OUTPUTS] == 0b0110
    off = first(rows, lambda row: row.time > begin.time and not row[OUTPUTS] & 0b0100, "the pulse over")
    assert off.time - begin.time == pytest.approx(0.030, abs=0.0005)
    assert rows[-1][OUTPUTS] == 0b0010  # the level output stays


def test_a_disable_ends_the_running_program(bench: Bench):
    bench.load_program(ENDLESS)
    bench.enable_sequence_mode()
    mark = bench.start(1)
    bench.run_for(0.2)
    bench.write(0x6040, 0x07)  # disable operation
    rows = bench.wait_program_end(mark)
    assert rows[-1][EXECUTED] == -1 and not rows[-1][DEDICATED] & SEQ


def test_starting_an_empty_slot_runs_nothing(bench: Bench):
    bench.enable_sequence_mode()
    mark = bench.start(50)
    bench.run_for(0.1)
    assert {row[EXECUTED] for row in bench.rows(mark)} == {-1}
    assert bench.read(0x6041) & 0x2400 == 0x0400  # SW10 at its reference, SW13 no sequence
