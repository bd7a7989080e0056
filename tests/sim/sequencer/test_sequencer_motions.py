"""Each sequence type on the simulated drive: POS with the profile generator and its output trigger, SPEED with
its RunTime, TORQUE with the captured position, HOME with the drive's homing methods, GEAR on the virtual master.
Timing is judged on the probe's control periods; the peer loads the programs as SEQUENCE.TXT."""

from __future__ import annotations

import pytest
from tests.support.sequencer_bench import (
    BEGIN,
    CAPTURED,
    CRUISE,
    CURRENT,
    DECEL,
    END,
    EXECUTED,
    HOLD,
    INPOS,
    OUTPUTS,
    PHASE,
    POSITION,
    REV,
    STATUS_WORD,
    VELOCITY,
    Bench,
    Row,
    first,
    phase_rows,
)

from servostudio.sim.plant import Plant

PERIOD = 250e-6
TIMING = 1.5 * PERIOD  # a duration measured between two control periods
STATUS_REFRESH = 4  # control periods: the status word 0x6041 is published every 1 ms
OUTPUT_1 = 1 << 1  # Output="......1." sets bit 1
VIRTUAL_MASTER = (0x3906, 0)


def run(bench: Bench, program: str) -> list[Row]:
    bench.load_program(program)
    bench.enable_sequence_mode()
    return bench.wait_program_end(bench.start(1))


def phases_seen(rows: list[Row]) -> list[int]:
    """The phases sequence 1 reached, in the order 0x3605 gained their bits (one entry per control period)."""
    seen, previous = [], 0
    for row in phase_rows(rows):
        if row[EXECUTED] == 1:
            seen.append(row[PHASE] & ~previous)
            previous = row[PHASE]
    return [bits for bits in seen if bits]


def at_phase(rows: list[Row], phase: int) -> Row:
    """The control period in which sequence 1 reached `phase`."""
    return first(rows, lambda row: row[EXECUTED] == 1 and row[PHASE] & phase, f"phase {phase}")


@pytest.mark.parametrize(
    ("trigger", "phase"), [("BEGIN", BEGIN), ("CRUISE", CRUISE), ("DECEL", DECEL), ("HOLD", HOLD), ("END", END)]
)
def test_pos_sequence_arrives_at_its_target_with_the_output_switched_at_its_trigger(
    bench: Bench, trigger: str, phase: int
):
    rows = run(
        bench,
        f"SeqNb=1\nSeqType=POS\nPosType=ABS\nPos={3 * REV}\nSpeed={10 * REV}\nAccel={100 * REV}\nDecel={100 * REV}\n"
        f'Tempo=50\nTrigger={trigger}\nOutput="......1."\n',
    )
    assert phases_seen(rows) == [BEGIN, CRUISE, DECEL, HOLD | INPOS, END]  # 0x6067 = 0: in position at HOLD
    switched = first(rows, lambda row: row[OUTPUTS] & OUTPUT_1, "output bit 1 set")
    assert switched is at_phase(rows, phase)  # in the very control period the phase is reached
    assert at_phase(rows, END)[POSITION] == 3 * REV
    assert at_phase(rows, END).time - at_phase(rows, INPOS).time == pytest.approx(0.050, abs=TIMING)
    over = rows.index(first(rows[rows.index(at_phase(rows, END)) :], lambda row: row[EXECUTED] == -1, "the end"))
    published = rows[over + STATUS_REFRESH]  # the drive refreshes its status word every 1 ms
    assert published[STATUS_WORD] & 0x1400 == 0x1400  # SW10 program over at its target, SW12 POS
    bench.run_for(0.002)
    assert bench.read(0x6041) & 0x1400 == 0x1400


def test_inpos_trigger_switches_when_the_position_is_inside_the_window(bench: Bench):
    """INPOS (trigger bit 4) has no file keyword: the record is written by SDO."""
    bench.write(0x6067, 2)  # position window, user units
    record = {sub: 0 for sub in range(1, 27)} | {1: 1, 2: -1, 4: -1, 13: REV, 15: 10 * REV, 17: 100 * REV}
    bench.write_record(1, record | {18: 100 * REV, 5: INPOS, 7: OUTPUT_1})
    bench.enable_sequence_mode()
    rows = bench.wait_program_end(bench.start(1))
    switched = first(rows, lambda row: row[OUTPUTS] & OUTPUT_1, "output bit 1 set")
    assert switched is at_phase(rows, INPOS)
    assert abs(switched[POSITION] - REV) <= 2
    assert at_phase(rows, HOLD).time < switched.time  # the axis settles into the window after the reference


def test_speed_sequence_holds_its_speed_for_its_run_time(bench: Bench):
    speed = 10 * REV
    rows = run(bench, f"SeqNb=1\nSeqType=SPEED\nSpeed={speed}\nAccelTime=100\nRunTime=400\nDecelTime=100\n")
    assert phases_seen(rows) == [BEGIN, CRUISE, DECEL, HOLD | END]  # no Tempo: over at standstill
    cruise, decel = at_phase(rows, CRUISE), at_phase(rows, DECEL)
    assert cruise.time - at_phase(rows, BEGIN).time == pytest.approx(0.100, abs=TIMING)
    assert decel.time - cruise.time == pytest.approx(0.400, abs=TIMING)
    running = [row[VELOCITY] for row in rows if cruise.time + 0.05 <= row.time <= decel.time]
    assert min(running) >= 0.98 * speed and max(running) <= 1.02 * speed
    assert abs(bench.read(0x606C)) < 0.02 * speed


def test_torque_sequence_presses_holds_its_current_and_captures_its_position(bench_factory):
    """Against a hard stop one revolution away: the current rises to Torque ‰ of 0x6075, is held for RunTime with
    the following error disabled (0x6065 is far smaller than the lag), and the position is captured in 0x360B."""
    plant = Plant(negative_limit_switch=None, positive_limit_switch=None, home_switch=None, positive_hard_stop=1.0)
    bench = bench_factory(probe=(POSITION, CURRENT, CAPTURED, STATUS_WORD), plant=plant)
    bench.write(0x6065, 50)  # following error window: would trip at once in a position loop
    rows = run(bench, f"SeqNb=1\nSeqType=TORQUE\nSpeed={2 * REV}\nAccel=50\nDecel=50\nRunTime=200\nTorque=400\n")
    assert phases_seen(rows) == [BEGIN, CRUISE, HOLD, DECEL, END]
    hold, decel = at_phase(rows, HOLD), at_phase(rows, DECEL)
    assert decel.time - hold.time == pytest.approx(0.200, abs=TIMING)
    pressing = [row[CURRENT] for row in rows if hold.time + 0.02 <= row.time <= decel.time]
    assert min(pressing) >= 360 and max(pressing) <= 410  # ‰ of 0x6075, the limit is 400
    assert decel[CAPTURED] == decel[POSITION] and abs(decel[CAPTURED] - REV) < REV // 50
    assert not any(row[STATUS_WORD] & 0x08 for row in rows)  # no fault


def test_home_sequence_runs_homing_on_the_index_and_returns_to_the_reference(bench: Bench):
    """Method 34 (first index moving positive) with an offset and the return option (sub 21, no file keyword)."""
    home = {sub: 0 for sub in range(1, 27)} | {1: 2, 2: -1, 4: -1, 13: 1000, 15: 2 * REV, 16: REV, 19: 50}
    bench.write_record(1, home | {21: 1, 22: 34})
    bench.enable_sequence_mode()
    rows = bench.wait_program_end(bench.start(1))
    assert phases_seen(rows) == [BEGIN, HOLD | INPOS | END]
    assert abs(bench.settled_position() - 1000) <= 2 and bench.read(0x3218) == 1


def test_home_sequence_on_the_negative_limit_switch_runs_into_the_switch(bench: Bench):
    """Method 17: the sequencer lets the homing run onto the limit switch it is looking for."""
    rows = run(bench, f"SeqNb=1\nSeqType=HOME\nMethod=17\nHomeOfs=-500\nSpeed={40 * REV}\nSpeed2={REV}\nAccel=100\n")
    assert phases_seen(rows) == [BEGIN, HOLD | INPOS | END]
    assert abs(bench.read(0x6064) + 500) < REV // 8 and bench.read(0x3218) == 1


def test_gear_sequence_follows_the_virtual_master_at_its_ratio_for_its_sync_distance(bench_factory):
    bench = bench_factory(probe=(POSITION, VELOCITY, VIRTUAL_MASTER))
    bench.write(0x3921, 3, 1)  # ratio set 1: 3 / 2
    bench.write(0x3921, 2, 2)
    bench.write(0x3910, 0x39060020)  # master input: the virtual master
    bench.write(0x3902, 2 * REV)  # the virtual master runs at 2 rev/s (0x3903 = 0: at once)
    rows = run(bench, f"SeqNb=1\nSeqType=GEAR\nAccel=100\nSyncDtn={3 * REV}\n")
    assert phases_seen(rows) == [BEGIN, CRUISE, DECEL, HOLD | END]
    cruise, decel = at_phase(rows, CRUISE), at_phase(rows, DECEL)
    assert cruise.time - at_phase(rows, BEGIN).time == pytest.approx(0.100, abs=TIMING)
    slave, master = decel[POSITION] - cruise[POSITION], decel[VIRTUAL_MASTER] - cruise[VIRTUAL_MASTER]
    assert slave == pytest.approx(3 * REV, abs=4) and slave / master == pytest.approx(1.5, rel=1e-3)
    in_gear = [row[VELOCITY] for row in rows if cruise.time + 0.05 <= row.time <= decel.time]
    assert min(in_gear) >= 0.98 * 3 * REV and max(in_gear) <= 1.02 * 3 * REV
