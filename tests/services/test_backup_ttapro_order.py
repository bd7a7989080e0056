"""A TTAPAR.TXT restore follows the manual's order (the extraction's §5.2, L467-480): the maximum speed 721 and the
position resolution 740/870 first, then the feedback selection 890-893/898, then the rest in the file's order, then
the save 729; observed on the simulated slave's PKW writes, through pyprofibus and the project's own master."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from tests.support.dp_masters import TRANSPORTS, dp_master, simulated_line

from servostudio.drive.access import Drive
from servostudio.drive.profibus.engine import PkwEngine
from servostudio.drive.profibus.link import ProfibusLink
from servostudio.drive.profiles import profile_for
from servostudio.od.pnu import builtin_parameter_list
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
    with dp_master(request.param, line) as master:
        parameters = builtin_parameter_list()
        link = ProfibusLink("pb", master)
        link.start()
        try:
            yield Drive(PkwEngine(link, lambda node: parameters), ADDRESS, parameters, profile_for("ttapro"))
        finally:
            link.close()


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
    slave.power_cycle()  # the save (PNU 729) came after every write
    assert slave.memory.get(730) == 1234
