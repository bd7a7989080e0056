"""DP-V0 service payloads and the PPO configurations (EN 50170 vol. 2 part 3; TTA-PRO Profibus Communication
Profile, Chapter 1 §2, L181-267)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.transport.profibus import dp_services as dp
from servostudio.transport.profibus.ppo import PPO1, PPO2, PPO3, PPO4, module_identifier, ppo_for_config

byte = st.integers(0, 255)
word = st.integers(0, 0xFFFF)


def test_the_ppo_identifiers_are_the_manuals() -> None:
    assert PPO1.identifiers == bytes((0xF3, 0xF1))
    assert PPO2.identifiers == bytes((0xF3, 0xF5))
    assert PPO3.identifiers == bytes((0xF1,))
    assert PPO4.identifiers == bytes((0xF5,))
    assert [ppo.length for ppo in (PPO1, PPO2, PPO3, PPO4)] == [12, 20, 4, 12]
    assert ppo_for_config(bytes((0xF3, 0xF5))) is PPO2
    assert ppo_for_config(bytes((0xF3, 0xF7))) is None  # 4 + 8 words: PPO5, not supported


def test_a_general_identifier_describes_1_to_16_words() -> None:
    assert module_identifier(1) == 0xF0 and module_identifier(16) == 0xFF
    with pytest.raises(ValueError):
        module_identifier(17)


@given(byte, byte, byte, byte, word, byte, st.binary(max_size=20))
def test_set_prm_reads_back(status, factor_1, factor_2, tsdr, ident, group, user) -> None:
    prm = dp.SetPrm(status, factor_1, factor_2, tsdr, ident, group, user)
    assert dp.SetPrm.decode(prm.encode()) == prm


def test_the_watchdog_is_10_ms_times_both_factors() -> None:
    assert dp.SetPrm(dp.STATUS_WATCHDOG, 5, 2, 0, 0, 0).watchdog == pytest.approx(0.1)
    assert dp.SetPrm(0, 5, 2, 0, 0, 0).watchdog is None


@given(byte, byte, byte, byte, word, st.binary(max_size=10))
def test_slave_diag_reads_back(status_1, status_2, status_3, master, ident, extended) -> None:
    diag = dp.SlaveDiag(status_1, status_2, status_3, master, ident, extended)
    assert dp.SlaveDiag.decode(diag.encode()) == diag


@given(byte, byte)
def test_global_control_reads_back(command, group) -> None:
    assert dp.GlobalControl.decode(dp.GlobalControl(command, group).encode()) == dp.GlobalControl(command, group)


@pytest.mark.parametrize(
    ("service", "data", "reason"),
    [
        (dp.SetPrm, bytes(6), "Set_Prm needs at least 7 bytes, got 6"),
        (dp.SlaveDiag, bytes(5), "Slave_Diag needs at least 6 bytes, got 5"),
        (dp.GlobalControl, bytes(3), "Global_Control has 2 bytes, got 3"),
    ],
)
def test_short_payloads_are_refused_with_their_length(service, data: bytes, reason: str) -> None:
    with pytest.raises(dp.DpServiceError, match=reason):
        service.decode(data)


def test_group_select_0_addresses_everyone() -> None:
    assert dp.GlobalControl(dp.SYNC, 0).addresses(0x00)
    assert dp.GlobalControl(dp.SYNC, 0x04).addresses(0x06)
    assert not dp.GlobalControl(dp.SYNC, 0x04).addresses(0x02)
