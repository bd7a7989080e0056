"""The drive commands on a PROFIBUS-DP bus (docs/profibus.md §9), in-process against the simulated TTA-PRO over
its TCP stream: scan, read and write PNUs, refusals with their exit codes, a lossless backup → change → restore
round trip of TTAPAR.TXT, and what a DP line cannot do (NMT, scope roll) refused."""

from __future__ import annotations

import json

import pytest
from tests.support.profibus_line import ttapro_line

from servostudio.cli import main


@pytest.fixture(scope="module")
def line():
    with ttapro_line(5) as line:
        yield line


def run(capsys, *argv: str) -> tuple[int, object, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, json.loads(captured.out) if captured.out.strip() else None, captured.err


def test_scan_finds_station_5_as_a_ttapro(line, capsys):
    code, nodes, _ = run(capsys, "scan", "--bus", line.spec)
    assert code == 0
    assert [(node["node"], node["device"], node["product_code"]) for node in nodes] == [(5, "ttapro", 0xC7)]


def test_read_and_write_pnus(line, capsys):
    code, values, _ = run(capsys, "read", "--bus", line.spec, "--node", "5", "PNU700", "max_motor_speed")
    assert code == 0 and [(value["index"], value["raw"]) for value in values] == [(700, 4), (721, 4000)]
    code, written, _ = run(capsys, "write", "--bus", line.spec, "--node", "5", "PNU760", "1500")
    assert code == 0 and written["raw"] == 1500 and line.slaves[5].memory.get(760) == 1500


@pytest.mark.parametrize(
    ("argv", "exit_code", "message"),
    [
        (("write", "PNU700", "99"), 3, "error: node 5: PNU 700 Number of motor pole pairs: 99 is outside 1..32"),
        (("write", "positioner_mode", "3"), 3, "error: node 5, PNU 720: lower or upper limit exceeded (PKW error 2)"),
        (("read", "PNU918"), 4, "error: node 5: object 'PNU918' is not in the ttapro dictionary"),
    ],
)
def test_refusals_are_readable_with_their_exit_codes(line, capsys, argv, exit_code, message):
    command, *rest = argv
    code, _, error = run(capsys, command, "--bus", line.spec, "--node", "5", *rest)
    assert code == exit_code and error.strip().splitlines()[-1] == message


def test_backup_change_restore_round_trip_is_lossless(line, capsys, tmp_path):
    memory = line.slaves[5].memory
    backup = tmp_path / "TTAPAR.TXT"
    code, result, _ = run(capsys, "backup", "--bus", line.spec, "--node", "5", "--out", str(backup))
    assert code == 0 and result["kind"] == "TTAPAR.TXT" and result["objects"] == 80 and result["skipped"] == []
    before = {(pnu, ind): memory.get(pnu, ind) for pnu, ind in _addresses(backup.read_text())}
    for name, value in (("kp_speed", "77"), ("following_error_window", "1000"), ("software_position_limit_max", "-5")):
        assert run(capsys, "write", "--bus", line.spec, "--node", "5", name, value)[0] == 0
    assert {key: memory.get(*key) for key in before} != before
    code, restored, _ = run(capsys, "restore", "--bus", line.spec, "--node", "5", "--in", str(backup))
    assert code == 0 and restored["ok"] and restored["counts"] == {"verified": 80} and restored["stored"] == "save"
    line.slaves[5].power_cycle()  # restored and saved to the EEPROM: the values survive a power cycle
    assert {key: memory.get(*key) for key in before} == before
    again = tmp_path / "again" / "TTAPAR.TXT"
    again.parent.mkdir()
    assert run(capsys, "backup", "--bus", line.spec, "--node", "5", "--out", str(again))[0] == 0
    assert again.read_text().splitlines()[1:] == backup.read_text().splitlines()[1:]  # all but the dated header


def test_the_sequence_table_round_trip_restores_the_eeprom_with_its_checksum(line, capsys, tmp_path):
    sequences = line.slaves[5].sequences
    sequences.eeprom[2] = {**sequences.eeprom[2], 782: 0x0005, 783: -2500, 784: 300, 785: 20, 786: 0, 788: 3}
    sequences.stored_checksum = sequences.checksum()
    table = tmp_path / "TTASEQ.TXT"
    code, result, _ = run(capsys, "backup", "--bus", line.spec, "--node", "5", "--out", str(table))
    assert code == 0 and result["kind"] == "TTASEQ.TXT" and result["objects"] == 1
    before = {pnu: sequences.eeprom[2][pnu] for pnu in range(782, 795)}  # 810 is the drive's: 784 in % of 721
    sequences.eeprom[2], sequences.eeprom[9] = {**before, 788: -1}, {**before}  # a link changed, one more in use
    code, restored, _ = run(capsys, "restore", "--bus", line.spec, "--node", "5", "--in", str(table))
    assert code == 0 and restored["ok"] and restored["counts"] == {"verified": 2}, restored
    assert restored["stored"] == "sequence checksum (sequence_write = 128)"
    assert {pnu: sequences.eeprom[2][pnu] for pnu in before} == before
    assert sequences.eeprom[9][782] == 0 and sequences.checksum_valid


def test_a_bad_file_is_refused_whole_before_anything_is_written(line, capsys, tmp_path):
    memory = line.slaves[5].memory
    bad = tmp_path / "TTAPAR.TXT"
    bad.write_text("730,0=11\n700,0=99\n")
    code, _, error = run(capsys, "restore", "--bus", line.spec, "--node", "5", "--in", str(bad))
    assert code == 3 and "TTAPAR.TXT:2: PNU 700 Number of motor pole pairs: 99 is outside 1..32" in error
    assert memory.get(730) != 11


def test_what_a_dp_line_cannot_do_is_refused(line, capsys, tmp_path):
    code, _, error = run(capsys, "nmt", "--bus", line.spec, "start")
    assert code == 3 and "is a PROFIBUS-DP line: an NMT command needs a CANopen bus" in error
    out = tmp_path / "roll.csv"
    argv = ("scope", "--bus", line.spec, "--node", "5", "--ch", "position_actual", "--roll", "--seconds", "1")
    code, _, error = run(capsys, *argv, "--out", str(out))
    assert code == 3 and "node 5 is a PROFIBUS-DP drive (ttapro): the scope's captures and roll mode" in error
    assert not out.exists()


def _addresses(text: str) -> list[tuple[int, int]]:
    assignments = [line.split("=")[0].split(",") for line in text.splitlines() if line[0].isdigit()]
    return [(int(pnu), int(ind)) for pnu, ind in assignments]
