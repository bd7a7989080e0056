"""SEQUENCE.TXT in the drive's flash through the signatures of 0x1010 / 0x1011 (decisions.md §4): `sseq` saves
the sequence memory, a warm reset and `lseq` (LOAD) give it back exactly, `mseq` (MERGE) keeps the sequences the
file does not declare, and a file the drive cannot take is error 44 (EMCY 0x6320) with the flash copy intact."""

from __future__ import annotations

from tests.support.sequencer_bench import REV, Bench
from tests.support.waits import wait_for

from servostudio.formats.sequence_model import BitPattern, Sequence
from servostudio.formats.sequence_spec import SequenceType
from servostudio.sim.flash import LOAD_SEQUENCES, MERGE_SEQUENCES, SAVE_SEQUENCES

DONE, ERROR = 5, 4
STORE, RESTORE = 0x1010, 0x1011
WARM_RESET = 2  # 0x205D: reset node reloads every flash file

PROGRAM = {
    0: Sequence.of(SequenceType.POS, PosType=1, Pos=-REV, Speed=10 * REV, Accel=50 * REV, Decel=0, SeqNext=5),
    5: Sequence.of(
        SequenceType.SPEED,
        Speed=3 * REV,
        AccelTime=120,
        DecelTime=0,
        RunTime=65535,
        EndCond=BitPattern(zeros=0x01, ones=0x80),
        Trigger=2,
        Output=BitPattern(zeros=0x0C, ones=0x30),
        SeqNext=6,
        SeqCount=3,
        SeqLink=0,
    ),
    6: Sequence.of(SequenceType.TORQUE, Speed=-REV, Accel=40, Decel=10, RunTime=300, Torque=250, Tempo=16000),
    64: Sequence.of(SequenceType.HOME, Method=-3, HomeOfs=-77, Speed=REV, Speed2=REV // 4, Accel=30, Torque=500),
    127: Sequence.of(SequenceType.GEAR, Config=0x2101, Factor=-16384, Accel=200, MasterDtn=9, SlaveDtn=8, SyncDtn=7),
}


def write_program(bench: Bench, program: dict[int, Sequence]) -> dict[int, dict[int, int]]:
    for number, sequence in program.items():
        bench.write_record(number, sequence.to_object_values())
    return {number: bench.read_record(number) for number in program}


def warm_reset(bench: Bench) -> None:
    bench.write(0x205D, WARM_RESET)
    bench.node.nmt.state = "RESET"
    wait_for(lambda: bench.network.node(1).state.value == "PRE-OPERATIONAL", bool, "the node booted")


def test_sseq_warm_reset_and_lseq_give_the_sequence_memory_back_exactly(bench: Bench):
    saved = write_program(bench, PROGRAM)
    assert bench.procedure(STORE, SAVE_SEQUENCES) == DONE
    warm_reset(bench)
    assert {number: bench.read_record(number) for number in PROGRAM} == saved  # loaded at power-on
    bench.write_record(3, PROGRAM[0].to_object_values())
    bench.write_record(5, Sequence.of(SequenceType.POS).to_object_values())
    assert bench.procedure(RESTORE, LOAD_SEQUENCES) == DONE
    assert {number: bench.read_record(number) for number in PROGRAM} == saved
    assert bench.read_record(3)[1] == 0  # LOAD clears what the file does not declare


def test_mseq_merges_the_file_into_the_sequence_memory(bench: Bench):
    kept = write_program(bench, {1: PROGRAM[0], 2: PROGRAM[5]})[1]
    bench.flash_dir.mkdir(parents=True, exist_ok=True)
    merged = "SeqNb=2\nSeqType=TORQUE\nTorque=100\nSeqNb=9\nSeqType=HOME\nMethod=35\n"
    (bench.flash_dir / "SEQUENCE.TXT").write_text(merged)
    assert bench.procedure(RESTORE, MERGE_SEQUENCES) == DONE
    assert bench.read_record(1) == kept
    assert bench.read_record(2)[1] == SequenceType.TORQUE and bench.read_record(2)[25] == 100
    assert bench.read_record(9)[1] == SequenceType.HOME and bench.read_record(9)[22] == 35


def test_a_memory_sseq_cannot_write_is_error_44_and_the_flash_copy_stays(bench: Bench):
    write_program(bench, PROGRAM)
    assert bench.procedure(STORE, SAVE_SEQUENCES) == DONE
    flash_copy = (bench.flash_dir / "SEQUENCE.TXT").read_bytes()
    bench.write(0x3610, 6)
    bench.write(0x3611, 0x0001, 8)  # a toggle mask: SEQUENCE.TXT has no syntax for it
    assert bench.procedure(STORE, SAVE_SEQUENCES) == ERROR
    assert_error_44(bench)
    assert (bench.flash_dir / "SEQUENCE.TXT").read_bytes() == flash_copy


def test_a_bad_sequence_file_is_error_44_and_changes_neither_memory_nor_file(bench: Bench):
    """The manual's own example file: AccelTime=200000 is beyond the U16 of 0x3611,19."""
    saved = write_program(bench, {3: PROGRAM[6]})
    bench.flash_dir.mkdir(parents=True, exist_ok=True)
    bad = b"SeqNb=1\nSeqType=pos\nPos=0x001000\nSeqNext=3\nSeqNb=3\nSeqType=speed\nAccelTime=200000\nRunTime=10000\n"
    (bench.flash_dir / "SEQUENCE.TXT").write_bytes(bad)
    assert bench.procedure(RESTORE, LOAD_SEQUENCES) == ERROR
    assert_error_44(bench)
    assert bench.read_record(3) == saved[3] and bench.read_record(1)[1] == 0
    assert (bench.flash_dir / "SEQUENCE.TXT").read_bytes() == bad


def assert_error_44(bench: Bench) -> None:
    emcy = wait_for(lambda: len(bench.node.emcy.log), bool, "an EMCY")
    assert emcy == 1
    error = bench.node.emcy.log[0]
    assert error.code == 0x6320 and error.data[0] == 44  # byte 3 of the frame: the Infranor error code
    assert bench.read(0x603F) == 0x6320 and bench.read(0x3022, 2) & 1 << 11
