"""`servostudio project dcf-import`: a DCF's configured values set an axis's offline values (in-process)."""

from __future__ import annotations

import json
from pathlib import Path

from servostudio.cli import main
from servostudio.od import builtin_library
from servostudio.services.projects import Axis, Bus, ProjectService


def test_dcf_import_sets_the_configured_values_and_lists_what_it_skipped(tmp_path: Path, capsys) -> None:
    store = tmp_path / "projects"
    service = ProjectService(store, builtin_library())
    service.store.create("p", buses=(Bus("sim", "sim"),))
    service.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    eds = builtin_library().load("xtrapulspac").source.read_text(encoding="latin-1")
    dcf = tmp_path / "X.dcf"
    dcf.write_text(
        eds.replace("[1400sub2]\n", "[1400sub2]\nParameterValue=1\n").replace("[6041]\n", "[6041]\nParameterValue=7\n"),
        encoding="latin-1",
    )
    code = main(["project", "--projects", str(store), "dcf-import", "p", "X", str(dcf)])
    result = json.loads(capsys.readouterr().out)
    assert code == 0
    assert [(row["index"], row["subindex"], row["value"]) for row in result["parameters"]] == [(0x1400, 2, 1)]
    assert len(result["skipped"]) == 1 and "0x6041" in result["skipped"][0]
    assert service.parameters.get("p", "X", "0x1400,2")[0].value == 1


def test_a_dry_run_says_what_would_change_and_writes_nothing(tmp_path: Path, capsys) -> None:
    store = tmp_path / "projects"
    service = ProjectService(store, builtin_library())
    service.store.create("p", buses=(Bus("sim", "sim"),))
    service.store.add_axis("p", Axis("X", "xtrapulspac", 1, "sim"))
    before = service.store.open("p").revision
    eds = builtin_library().load("xtrapulspac").source.read_text(encoding="latin-1")
    dcf = tmp_path / "X.dcf"
    dcf.write_text(eds.replace("[1400sub2]\n", "[1400sub2]\nParameterValue=1\n"), encoding="latin-1")
    code = main(["project", "--projects", str(store), "dcf-import", "p", "X", str(dcf), "--dry-run"])
    result = json.loads(capsys.readouterr().out)
    assert code == 0
    changes = [(row["index"], row["subindex"], row["old"], row["new"]) for row in result["changes"]]
    assert changes == [(0x1400, 2, 255, 1)]
    assert result["revision"] == before == service.store.open("p").revision
    assert service.parameters.get("p", "X", "0x1400,2")[0].file is None


def test_dcf_import_of_a_missing_file_is_refused_input(tmp_path: Path, capsys) -> None:
    store = tmp_path / "projects"
    ProjectService(store, builtin_library()).store.create("p", buses=(Bus("sim", "sim"),))
    code = main(["project", "--projects", str(store), "dcf-import", "p", "X", str(tmp_path / "none.dcf")])
    assert code == 3 and "none.dcf" in capsys.readouterr().err
