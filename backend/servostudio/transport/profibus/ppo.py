"""PPO types of PROFIdrive-style drives and their Chk_Cfg identifiers (DP general identifier format).

A PPO is one or two consistent input/output modules: PKW (4 words, the parameter channel) and PZD (2 or 6 words of
process data). A general identifier byte is: bit 7 consistency over the whole module, bit 6 word units, bits 4..5
direction (11 = input and output), bits 0..3 length − 1. So PKW = 0xF3, 2 PZD = 0xF1, 6 PZD = 0xF5, as the TTA-PRO
manual lists them (TTA-PRO Profibus Communication Profile, Chapter 1 §2, L181-267). PPO5 is not supported by the
TTA-PRO (Chapter 1 §1, L73-74).
"""

from __future__ import annotations

from dataclasses import dataclass

CONSISTENT = 0x80
WORDS = 0x40
INPUT_OUTPUT = 0x30
LENGTH_MASK = 0x0F
PKW_WORDS = 4
WORD_BYTES = 2


def module_identifier(words: int) -> int:
    """General identifier of a consistent input/output module of `words` words (1..16)."""
    if not 1 <= words <= LENGTH_MASK + 1:
        raise ValueError(f"a general identifier describes 1..16 words, not {words}")
    return CONSISTENT | WORDS | INPUT_OUTPUT | (words - 1)


@dataclass(frozen=True)
class Ppo:
    """One PPO type: whether it has the PKW module and how many PZD words."""

    name: str
    has_pkw: bool
    pzd_words: int

    @property
    def identifiers(self) -> bytes:
        """The Chk_Cfg data a master sends for this PPO: PKW module first, then PZD."""
        pkw = (module_identifier(PKW_WORDS),) if self.has_pkw else ()
        return bytes((*pkw, module_identifier(self.pzd_words)))

    @property
    def length(self) -> int:
        """Bytes of the Data_Exchange data unit, the same in both directions (input/output modules)."""
        return WORD_BYTES * (self.pzd_words + (PKW_WORDS if self.has_pkw else 0))

    @property
    def pzd_offset(self) -> int:
        """Byte where PZD1 starts in the data unit."""
        return WORD_BYTES * PKW_WORDS if self.has_pkw else 0


PPO1 = Ppo("PPO1", has_pkw=True, pzd_words=2)
PPO2 = Ppo("PPO2", has_pkw=True, pzd_words=6)
PPO3 = Ppo("PPO3", has_pkw=False, pzd_words=2)
PPO4 = Ppo("PPO4", has_pkw=False, pzd_words=6)
PPO_TYPES = (PPO1, PPO2, PPO3, PPO4)


def ppo_for_config(config: bytes) -> Ppo | None:
    """The PPO whose identifiers are exactly `config` (a Chk_Cfg data unit), None when none is."""
    return next((ppo for ppo in PPO_TYPES if ppo.identifiers == bytes(config)), None)
