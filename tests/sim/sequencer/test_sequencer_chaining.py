"""The manual's two chaining examples (*XtrapulsPac User Guide* §3.2.3.8, "COUNTER LOOP" L10258–10293 and
"CONDITIONAL JUMP" L10294–10339), run on the simulated drive and watched by the peer on TPDO 2: the sequence
numbers must come in exactly the documented order (decisions.md §3)."""

from __future__ import annotations

import pytest
from tests.support.sequencer_bench import EXECUTED, REV, Bench
from tests.support.waits import wait_for

MOVE = f"""SeqType=POS
PosType=REL
Pos={REV // 2}
Speed={10 * REV}
Accel={200 * REV}
Decel={200 * REV}
Tempo=10
"""

COUNTER_LOOP = f"""; the manual's counter loop: 1 -> 2 (first run, SeqLink) -> 1 -> 2 (second run, SeqNext) -> 3
SeqNb=1
{MOVE}SeqCount=0
SeqNext=2
SeqLink=-1
SeqNb=2
{MOVE}SeqCount=2
SeqNext=3
SeqLink=1
SeqNb=3
{MOVE}SeqCount=0
SeqNext=-1
SeqLink=-1
"""

CONDITIONAL_JUMP = f"""; the manual's conditional jump: sequence 2 runs only with logic input 8 (leftmost bit)
SeqNb=1
{MOVE}SeqNext=2
SeqCount=0
SeqLink=-1
SeqNb=2
{MOVE}SeqNext=3
SeqCount=0
SeqLink=4
Start Cond="1......."
SeqNb=3
{MOVE}SeqNext=-1
SeqCount=0
SeqLink=-1
SeqNb=4
{MOVE}SeqNext=-1
SeqCount=0
SeqLink=-1
"""

IN1_TO_CONDITION_BIT_7 = 0x36010307  # 0x3050,1: IN1 -> 0x3601,3 bit 7


def run_program(bench: Bench, program: str, first: int = 1) -> list[int]:
    """Load and run a program; the sequence numbers TPDO 2 reported, checked against the probe's."""
    bench.load_program(program)
    bench.enable_sequence_mode()
    since = bench.network.now
    rows = bench.wait_program_end(bench.start(first))
    probed = collapsed([row[EXECUTED] for row in rows])
    wait_for(lambda: bench.executed(since)[-1:] == [-1], bool, "TPDO 2 reporting the end")
    reported = bench.executed(since)
    assert reported == probed[probed.index(first) :]
    return reported


def collapsed(numbers: list[int]) -> list[int]:
    return [number for n, number in enumerate(numbers) if n == 0 or numbers[n - 1] != number]


def test_counter_loop_runs_1_2_1_2_3(bench: Bench):
    assert run_program(bench, COUNTER_LOOP) == [1, 2, 1, 2, 3, -1]
    assert abs(bench.settled_position() - 5 * REV // 2) <= 2  # five relative moves of half a revolution


@pytest.mark.parametrize(("input_8", "order"), [(True, [1, 2, 3, -1]), (False, [1, 4, -1])])
def test_conditional_jump_follows_logic_input_8(bench: Bench, input_8: bool, order: list[int]):
    bench.write(0x3050, IN1_TO_CONDITION_BIT_7, 1)
    bench.set_physical_inputs(1 if input_8 else 0)
    assert bench.read(0x3601, 3) & 0xFF == (0x80 if input_8 else 0)
    assert run_program(bench, CONDITIONAL_JUMP) == order
