"""`servostudio user …`, `token …` and `setup --passwordless`: on the data directory, and through a running
server with `--server URL --token TOKEN` (or `SERVOSTUDIO_TOKEN`). Exit codes: 3 refused, 6 who the caller is
could not be established (no or bad token), 7 the caller's level is too low."""

from __future__ import annotations

import io
import json
import os
import stat
import subprocess
import sys

import pytest
from tests.support.live_server import REPO_ROOT, LiveServer

from servostudio.cli import main
from servostudio.errors import OUTCOMES, ErrorKind
from servostudio.services.users import Level, UserStore

PASSWORD = "correct horse battery"


def run(capsys, monkeypatch, *argv: str, stdin: str = "") -> tuple[int, object, str]:
    """``main(argv)`` in-process with ``stdin``; (exit code, JSON output or None, stderr)."""
    monkeypatch.setattr(sys, "stdin", io.StringIO(stdin))
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, json.loads(out) if out.strip() else None, err


def test_user_add_and_list_on_the_data_directory(capsys, monkeypatch, tmp_path):
    data = str(tmp_path / "data")
    code, added, _ = run(
        capsys,
        monkeypatch,
        "user",
        "add",
        "alice",
        "--level",
        "expert",
        "--password-stdin",
        "--data-dir",
        data,
        stdin=PASSWORD + "\n",
    )
    assert code == 0 and (added["name"], added["level"]) == ("alice", "expert")
    code, users, _ = run(capsys, monkeypatch, "user", "list", "--data-dir", data)
    assert code == 0 and [(user["name"], user["level"]) for user in users] == [("alice", "expert")]
    assert UserStore(tmp_path / "data").authenticate("alice", PASSWORD) is not None
    assert stat.S_IMODE((tmp_path / "data" / "users.json").stat().st_mode) == 0o600


def test_a_password_comes_from_a_terminal_or_stdin_never_the_command_line(capsys, monkeypatch, tmp_path):
    data = str(tmp_path / "data")
    code, _, error = run(capsys, monkeypatch, "user", "add", "bob", "--level", "operator", "--data-dir", data)
    assert code == OUTCOMES[ErrorKind.INVALID_INPUT].exit_code and "--password-stdin" in error
    code, _, error = run(
        capsys,
        monkeypatch,
        "user",
        "add",
        "bob",
        "--level",
        "operator",
        "--password-stdin",
        "--data-dir",
        data,
        stdin="short\n",
    )
    assert code == 3 and "at least 10 characters" in error
    with pytest.raises(SystemExit):  # argparse: 2, an unknown level
        main(["user", "add", "bob", "--level", "root", "--password-stdin", "--data-dir", data])


def test_token_create_prints_the_token_once(capsys, monkeypatch, tmp_path):
    data = str(tmp_path / "data")
    code, made, _ = run(
        capsys, monkeypatch, "token", "create", "--level", "maintenance", "--expires", "7", "--data-dir", data
    )
    assert code == 0 and made["token"].startswith("sst_") and made["level"] == "maintenance"
    assert 6.9 * 86_400 < made["expires"] - made["created"] < 7.1 * 86_400
    code, listed, _ = run(capsys, monkeypatch, "token", "list", "--data-dir", data)
    assert [token["id"] for token in listed] == [made["id"]] and "token" not in listed[0]
    assert made["token"] not in (tmp_path / "data" / "users.json").read_text()
    assert UserStore(tmp_path / "data").token_caller(made["token"]).level is Level.MAINTENANCE


def test_password_less_mode_refuses_a_server_with_users_and_other_machines(capsys, monkeypatch, tmp_path):
    data = str(tmp_path / "data")
    assert run(capsys, monkeypatch, "setup", "--passwordless", "--data-dir", data)[0] == 0
    code, _, error = run(capsys, monkeypatch, "serve", "--host", "0.0.0.0", "--allow-remote", "--data-dir", data)
    assert code == 3 and "password-less mode is for localhost only" in error
    UserStore(tmp_path / "data").add_user("admin", Level.ADMINISTRATOR, PASSWORD)  # ends password-less mode
    assert not UserStore(tmp_path / "data").contents().passwordless
    code, _, error = run(capsys, monkeypatch, "setup", "--passwordless", "--data-dir", data)
    assert code == 3 and "has users" in error


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    root = tmp_path_factory.mktemp("cli-users")
    (root / "projects").mkdir()
    UserStore(root / "data").add_user("admin", Level.ADMINISTRATOR, PASSWORD)
    live = LiveServer(root / "projects", extra_args=["--bus", "virtual:cli-users"], data_dir=root / "data")
    live.wait_ready()
    yield live
    live.stop()


def cli(*argv: str, token: str | None = None, stdin: str = "") -> subprocess.CompletedProcess:
    """The command as a script runs it, in its own process."""
    env = {key: value for key, value in os.environ.items() if key != "SERVOSTUDIO_TOKEN"}
    if token is not None:
        env["SERVOSTUDIO_TOKEN"] = token
    command = [sys.executable, "-m", "servostudio", *argv]
    return subprocess.run(command, cwd=REPO_ROOT, env=env, input=stdin, capture_output=True, text=True, timeout=60)


def test_user_and_token_commands_through_a_server(server):
    admin, _ = UserStore(server.data_dir).create_token(Level.ADMINISTRATOR, days=1, owner="admin")
    added = cli(
        "--server",
        server.url,
        "--token",
        admin,
        "user",
        "add",
        "erin",
        "--level",
        "operator",
        "--password-stdin",
        stdin=PASSWORD + "\n",
    )
    assert added.returncode == 0, added.stderr
    listed = cli("user", "list", "--server", server.url, token=admin)  # the token from SERVOSTUDIO_TOKEN
    assert {user["name"] for user in json.loads(listed.stdout)} == {"admin", "erin"}
    made = cli("token", "create", "--level", "expert", "--expires", "2", "--server", server.url, "--token", admin)
    assert made.returncode == 0 and json.loads(made.stdout)["owner"] == "admin"


def test_through_a_server_the_exit_code_says_who_was_refused(server):
    operator, _ = UserStore(server.data_dir).create_token(Level.OPERATOR, days=1)
    below = cli("user", "list", "--server", server.url, "--token", operator)
    assert below.returncode == OUTCOMES[ErrorKind.FORBIDDEN].exit_code == 7 and "administrator level" in below.stderr
    higher = cli("token", "create", "--level", "expert", "--server", server.url, "--token", operator)
    assert higher.returncode == 7
    nobody = cli("user", "list", "--server", server.url)
    assert nobody.returncode == OUTCOMES[ErrorKind.UNAUTHENTICATED].exit_code == 6 and "log in" in nobody.stderr
    assert cli("user", "list", "--server", server.url, "--token", "sst_bad_token").returncode == 6
    unreachable = cli("user", "list", "--server", "http://127.0.0.1:9", "--token", operator)
    assert unreachable.returncode == 5 and "cannot be reached" in unreachable.stderr


def test_commands_running_at_once_lose_no_change(tmp_path):
    """Each change is read-modify-write under the store's lock: eight processes, eight tokens."""
    command = [sys.executable, "-m", "servostudio", "token", "create", "--level", "operator", "--data-dir"]
    running = [
        subprocess.Popen([*command, str(tmp_path)], cwd=REPO_ROOT, stdout=subprocess.PIPE, text=True) for _ in range(8)
    ]
    made = {json.loads(process.communicate(timeout=60)[0])["id"] for process in running}
    assert len(made) == 8 and {token.id for token in UserStore(tmp_path).contents().tokens} == made
    assert not list(tmp_path.glob(".users.json.*.tmp"))  # no temporary file left behind
