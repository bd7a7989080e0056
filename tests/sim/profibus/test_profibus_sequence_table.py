"""The sequence table of the simulated TTA-PRO through its PNUs (TTA-PRO Profibus Communication Profile,
Chapter 3, L1870-2365): the buffer, PNU 780 / 781, the checksum (781 = 128) checked at power-up, and the RAM
modifications with IND."""

from __future__ import annotations

from tests.support.ttapro_rig import Rig

VALID_POSITIONING = 0x0001
CHECKSUM = 128


def write_sequence(rig: Rig, number: int, position: int) -> None:
    """Fill the buffer (782-784), then PNU 781 = number copies it into the EEPROM."""
    rig.write(782, VALID_POSITIONING)
    rig.write(783, position)
    rig.write(784, 1000)
    assert rig.run_procedure(781, number) == 1


def test_a_sequence_goes_through_the_buffer_into_the_eeprom_and_back(rig: Rig) -> None:
    write_sequence(rig, 7, 12345)
    rig.write(783, 0)
    assert rig.run_procedure(780, 7) == 1
    assert rig.read(783) == 12345
    assert rig.read(810) == round(1000 * 32767 / 4000)  # the same speed in % of PNU 721


def test_ram_modification_needs_a_valid_sequence_and_an_index_in_range(rig: Rig) -> None:
    write_sequence(rig, 2, 100)
    assert rig.write(797, 1500, index=2)[0] == 1  # the manual's example: sequence 2 speed (0x231D)
    assert rig.read(815, index=2) == round(1500 * 32767 / 4000)
    assert rig.write(796, 200, index=3)[0::3] == (7, 17)  # sequence 3 is not valid
    assert rig.transaction(1, 796, index=128)[0::3] == (7, 3)


def test_a_table_without_its_checksum_fails_at_the_next_power_up(rig: Rig) -> None:
    write_sequence(rig, 0, 500)
    rig.slave.power_cycle()
    assert rig.slave.faults.drive_error_code() == 2  # EEPROM sequences checksum
    assert rig.slave.memory.read(773, 0) & 1 << 18  # E2PSEQ


def test_the_checksum_write_makes_the_table_valid_and_sequences_survive_power_off(rig: Rig) -> None:
    write_sequence(rig, 0, 500)
    assert rig.run_procedure(781, CHECKSUM) == 1
    rig.write(760, 777)
    assert rig.run_procedure(729) == 1
    rig.slave.power_cycle()
    assert not rig.slave.faults.faulted
    assert rig.slave.memory.get(796, 0) == 500
    assert rig.slave.memory.get(760) == 777
