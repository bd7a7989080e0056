"""SEQUENCE.TXT programs of short relative moves for the simulated XtrapulsPac: a counter loop and a conditional
jump, shared by the sequence service, API and CLI tests."""

from __future__ import annotations

REV = 4096  # user units per revolution (0x6093 at its default)
MOVE = f"SeqType=POS\nPosType=REL\nPos={REV // 4}\nSpeed={20 * REV}\nAccel={400 * REV}\nDecel={400 * REV}\nTempo=5\n"


def program(*sequences: tuple[int, str]) -> str:
    """SEQUENCE.TXT of short relative moves: (number, its chaining lines)."""
    return "".join(f"SeqNb={number}\n{MOVE}{chaining}\n" for number, chaining in sequences)


COUNTER_LOOP = program(
    (1, "SeqCount=0\nSeqNext=2\nSeqLink=-1"),
    (2, "SeqCount=2\nSeqNext=3\nSeqLink=1"),
    (3, "SeqCount=0\nSeqNext=-1\nSeqLink=-1"),
)
CONDITIONAL_JUMP = program(
    (1, "SeqNext=2\nSeqCount=0\nSeqLink=-1"),
    (2, 'SeqNext=3\nSeqCount=0\nSeqLink=4\nStart Cond="1......."'),
    (3, "SeqNext=-1\nSeqCount=0\nSeqLink=-1"),
    (4, "SeqNext=-1\nSeqCount=0\nSeqLink=-1"),
)
