"""A TTAPAR.TXT restore follows the manual's order (the extraction's §5.2, L467-480): the maximum speed 721 and the
position resolution 740/870 first, then the feedback selection 890-893/898, then the feedback programming 894 when
the restore changed that selection, then the rest in the file's order, then the save 729; observed on the simulated
slave's PKW writes and the programmings it carried out, through pyprofibus and the project's own master."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from tests.support.dp_masters import TRANSPORTS, dp_drive, simulated_line

from servostudio.drive.access import Drive
from servostudio.services.backup import FileKind, restore_text
from servostudio.sim.profibus.line import ProfibusLine

ADDRESS = 5
FILE_ORDER = (730, 893, 700, 870, 721, 740, 757)
"""The entries as a file may list them: scaled values and the feedback ahead of what they depend on."""


@pytest.fixture
def line() -> Iterator[ProfibusLine]:
    with simulated_line(ADDRESS) as line:
        yield line


@pytest.fixture(params=TRANSPORTS)
def drive(request: pytest.FixtureRequest, line: ProfibusLine) -> Iterator[Drive]:
    with dp_drive(request.param, line, ADDRESS) as drive:
        yield drive


def test_restore_writes_in_the_manuals_order_then_saves(drive: Drive, line: ProfibusLine) -> None:
    slave = line.slaves[ADDRESS]
    written: list[int] = []
    for pnu in FILE_ORDER:
        slave.memory.on_write(pnu, lambda index, value, pnu=pnu: written.append(pnu))
    values = {pnu: slave.memory.get(pnu) for pnu in FILE_ORDER} | {730: 1234}
    text = "".join(f"{pnu},0={values[pnu]}\n" for pnu in FILE_ORDER)
    result = restore_text(drive, text, FileKind.TTAPAR)
    assert not result.error and result.stored == "save"
    assert written[: len(FILE_ORDER)] == [721, 740, 870, 893, 730, 700, 757]
    assert [outcome.status for outcome in result.outcomes] == ["verified"] * len(FILE_ORDER)
    assert slave.feedback_programmings == []  # the file holds the feedback selection the drive has: no 894
    slave.power_cycle()  # the save (PNU 729) came after every write
    assert slave.memory.get(730) == 1234


def test_a_restore_that_changes_the_feedback_programs_it_right_after_writing_it(
    drive: Drive, line: ProfibusLine
) -> None:
    slave = line.slaves[ADDRESS]
    written: list[tuple[int, int]] = []  # (PNU, feedback programmings carried out when it was written)
    for pnu in FILE_ORDER:
        slave.memory.on_write(pnu, lambda i, v, pnu=pnu: written.append((pnu, len(slave.feedback_programmings))))
    values = {pnu: slave.memory.get(pnu) for pnu in FILE_ORDER} | {893: 1 - slave.memory.get(893), 730: 1234}
    text = "".join(f"{pnu},0={values[pnu]}\n" for pnu in FILE_ORDER)
    result = restore_text(drive, text, FileKind.TTAPAR)
    assert result.ok and result.stored == "save", result.as_dict()
    assert written[: len(FILE_ORDER)] == [(721, 0), (740, 0), (870, 0), (893, 0), (730, 1), (700, 1), (757, 1)]
    assert [programmed[893] for programmed in slave.feedback_programmings] == [values[893]]  # 894 once, after 893
