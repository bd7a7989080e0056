"""``servostudio seq …`` through a running server (``--server URL``): download, upload, and ``run`` as a live client
of the server (cli/liveclient.py), printing the manual's counter loop in order; ``stop`` likewise."""

from __future__ import annotations

import json

from tests.support.sequence_programs import COUNTER_LOOP

from servostudio.cli import main

NODE = "2"


def test_download_run_and_stop_through_the_server(tmp_path, capsys, live_server):
    path = tmp_path / "SEQUENCE.TXT"
    path.write_text(COUNTER_LOOP, encoding="latin-1")
    server = ["--server", live_server.url]
    assert main([*server, "seq", "download", "--bus", "sim", "--node", NODE, str(path)]) == 0
    assert json.loads(capsys.readouterr().out)["verified"] is True
    out = tmp_path / "back.TXT"
    assert main([*server, "seq", "upload", "--bus", "sim", "--node", NODE, "--out", str(out)]) == 0
    assert json.loads(capsys.readouterr().out)["sequences"] == [1, 2, 3]

    assert main([*server, "seq", "run", "--bus", "sim", "--node", NODE, "1", "--watch", "20"]) == 0
    printed = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [line["sequence"] for line in printed] == [1, 2, 1, 2, 3]
    assert all(line["phase"] == "END" and line["t"] >= 0 for line in printed)

    assert main([*server, "seq", "stop", "--bus", "sim", "--node", NODE]) == 0
    assert json.loads(capsys.readouterr().out)["stopped"] is True


def test_a_bad_file_through_the_server_is_exit_3_with_its_line(tmp_path, capsys, live_server):
    path = tmp_path / "SEQUENCE.TXT"
    path.write_text("SeqNb=1\nSeqType=SPEED\nAccelTime=200000\n", encoding="latin-1")
    assert main(["--server", live_server.url, "seq", "download", "--bus", "sim", "--node", NODE, str(path)]) == 3
    assert "SEQUENCE.TXT:3: AccelTime" in capsys.readouterr().err
