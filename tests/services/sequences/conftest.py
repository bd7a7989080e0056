"""One embedded simulated XtrapulsPac (spec ``sim:1``) reached the way the server reaches it, and programs for it."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from tests.support.embedded_sim import open_sim

from servostudio.services.bus import ConnectionManager

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


@pytest.fixture
def manager() -> Iterator[ConnectionManager]:
    manager = ConnectionManager()
    open_sim(manager, "sim:1")
    yield manager
    manager.close_all()


@pytest.fixture
def connection(manager):
    return manager.get("sim")


@pytest.fixture
def drive(connection):
    return connection.drive(1)
