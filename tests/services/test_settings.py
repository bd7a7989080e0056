"""Settings are read when they are built — flags over environment over defaults — never when a module is imported."""

from __future__ import annotations

from pathlib import Path

from servostudio.od.library import BUILTIN_EDS_DIR
from servostudio.services.projects.motors import BUILTIN_MOTORS_DIR
from servostudio.services.settings import Settings

VARIABLES = ("SERVOSTUDIO_EDS_DIR", "SERVOSTUDIO_USER_EDS_DIR", "SERVOSTUDIO_MOTORS_DIR", "XDG_DATA_HOME")


def test_defaults_without_environment(monkeypatch, tmp_path):
    for name in VARIABLES:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("HOME", str(tmp_path))
    settings = Settings()
    assert (settings.builtin_eds_dir, settings.motors_dir) == (BUILTIN_EDS_DIR, BUILTIN_MOTORS_DIR)
    assert settings.user_eds_dir == tmp_path / ".local" / "share" / "servostudio" / "eds"
    assert (settings.host, settings.port, settings.buses) == ("127.0.0.1", 8000, ())


def test_environment_set_after_import_is_what_a_new_settings_reads(monkeypatch, tmp_path):
    monkeypatch.setenv("SERVOSTUDIO_EDS_DIR", str(tmp_path / "eds"))
    monkeypatch.setenv("SERVOSTUDIO_MOTORS_DIR", str(tmp_path / "motors"))
    monkeypatch.delenv("SERVOSTUDIO_USER_EDS_DIR", raising=False)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    settings = Settings()
    assert settings.builtin_eds_dir == tmp_path / "eds"
    assert settings.motors_dir == tmp_path / "motors"
    assert settings.user_eds_dir == tmp_path / "data" / "servostudio" / "eds"
    monkeypatch.setenv("SERVOSTUDIO_USER_EDS_DIR", str(tmp_path / "mine"))
    assert Settings().user_eds_dir == tmp_path / "mine"


def test_a_flag_wins_and_a_missing_flag_keeps_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("SERVOSTUDIO_USER_EDS_DIR", str(tmp_path / "env"))
    assert Settings.given(user_eds_dir=None).user_eds_dir == tmp_path / "env"
    given = Settings.given(user_eds_dir=tmp_path / "flag", projects_dir=Path("p"), port=9000)
    assert (given.user_eds_dir, given.projects_dir, given.port) == (tmp_path / "flag", Path("p"), 9000)
