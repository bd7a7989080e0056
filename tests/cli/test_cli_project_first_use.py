"""Issue 14 from the command line: compare sets read-only entries apart (``--read-only``, key ``read_only``, the
other keys unchanged), and a kept revision is listed and restored (``revisions``, ``revision-restore``)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from servostudio.cli import main
from servostudio.od import builtin_library
from servostudio.services.projects import Axis, Bus, ProjectService


def ok(capsys: pytest.CaptureFixture[str], store: Path, *args: str):
    code = main(["project", "--projects", str(store), *args])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    return json.loads(captured.out)


@pytest.fixture
def store(tmp_path: Path) -> Path:
    service = ProjectService(tmp_path / "projects", builtin_library())
    service.store.create("p", buses=(Bus("sim", "sim"),))
    service.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    return tmp_path / "projects"


def test_compare_with_the_drive_gives_read_only_entries_apart(capsys, store: Path):
    plain = ok(capsys, store, "compare", "p", "X", "--drive")
    assert "read_only" not in plain and set(plain) == {"columns", "rows", "revision", "refused"}
    found = ok(capsys, store, "compare", "p", "X", "--drive", "--read-only")
    assert len(found["rows"]) == len(plain["rows"])
    apart = {(row["index"], row["subindex"]): row for row in found["read_only"]}
    assert apart[(0x6041, 0)]["values"]["drive"] is not None  # the status word, read from the drive
    assert not {(row["index"], row["subindex"]) for row in found["rows"]} & set(apart)


def test_revisions_are_listed_and_restored(capsys, store: Path):
    service = ProjectService(store, builtin_library())
    before = service.store.open("p").revision
    service.parameters.set("p", "X", {"0x60F9,2": 1500}, keep="backup of node 1")
    kept = ok(capsys, store, "revisions", "p")
    assert [(item["revision"], item["reason"]) for item in kept] == [(before, "backup of node 1")]
    assert ok(capsys, store, "revision-restore", "p", before)["revision"] == before
    assert main(["project", "--projects", str(store), "revision-restore", "p", "0000000000000000"]) == 4
