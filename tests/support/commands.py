"""Running a ``servostudio`` command the way the CLI tests do: in this process (its exit code, output and error
text, the output also read as the JSON document the command prints) or as a subprocess of this interpreter."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from servostudio.cli import main


def run(capsys, *argv: str) -> tuple[int, str, str]:
    """``servostudio ARGV`` in this process: its exit code, standard output and standard error."""
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def run_json(capsys, *argv: str) -> tuple[int, object, str]:
    """As ``run``, the output read as the JSON document the command prints (None when it printed nothing)."""
    code, out, err = run(capsys, *argv)
    return code, json.loads(out) if out.strip() else None, err


def servostudio(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """``python -m servostudio ARGS`` as a subprocess with this environment: its exit code and texts."""
    command = [sys.executable, "-m", "servostudio", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=dict(os.environ))
