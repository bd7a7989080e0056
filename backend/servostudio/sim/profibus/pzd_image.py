"""What the PZD words of a PPO carry (TTA-PRO Profibus Communication Profile, Chapter 2 §5, L848-894; Chapter 3,
PNU 828/829, L2429-2508).

PZD1 is the control / status word, PZD2 the input command / feedback of the mode. PZD3-6 hold the signals PNU 829
(command) and 828 (feedback) map, slot by slot from PZD3; a signal code's high nibble is its size in words and its
low 12 bits are the PNU that holds the signal (0x1309 = one word of PNU 777, 0x2306 = two words of PNU 774; this
reading fits every documented code, docs/profibus.md §5). Code 0x1348 ("not affected") maps nothing. A double word
travels most significant word first (PZD5 = MSW).
"""

from __future__ import annotations

from dataclasses import dataclass

FEEDBACK_MAPPING = 828
COMMAND_MAPPING = 829
SLOTS = range(3)
MAPPED_WORDS = 4
"""PZD3..PZD6."""
NOT_AFFECTED = 0x1348
FEEDBACK_CODES = frozenset({0x1309, 0x1308, 0x2306, 0x22ED, 0x12F3, 0x12C2, NOT_AFFECTED})
COMMAND_CODES = frozenset({0x22FF, 0x12C9, 0x12C3, 0x12C4, 0x12CA, NOT_AFFECTED})


@dataclass(frozen=True)
class MappedSignal:
    """One signal in the mapped area: the PNU behind it, its first word (0 = PZD3) and its size in words."""

    pnu: int
    first_word: int
    words: int


def signal_pnu(code: int) -> int:
    return code & 0x0FFF


def signal_words(code: int) -> int:
    return code >> 12


def layout(codes: list[int]) -> list[MappedSignal]:
    """The signals of the mapping slots in order, as far as they fit in PZD3..PZD6."""
    signals = []
    word = 0
    for code in codes:
        size = signal_words(code)
        if word + size > MAPPED_WORDS:
            break
        if code != NOT_AFFECTED:
            signals.append(MappedSignal(signal_pnu(code), word, size))
        word += size
    return signals


def read_signal(words: tuple[int, ...], signal: MappedSignal, signed: bool) -> int | None:
    """A command signal's value from PZD3.. words; None when the PPO is too short to carry it."""
    part = words[signal.first_word : signal.first_word + signal.words]
    if len(part) < signal.words:
        return None
    raw = part[0] if signal.words == 1 else part[0] << 16 | part[1]
    bits = 16 * signal.words
    return raw - (1 << bits) if signed and raw >= 1 << (bits - 1) else raw


def write_signal(words: list[int], signal: MappedSignal, value: int) -> None:
    """Put a feedback value into the PZD3.. words it occupies (as far as the PPO has them)."""
    raw = value & ((1 << (16 * signal.words)) - 1)
    parts = [raw] if signal.words == 1 else [raw >> 16, raw & 0xFFFF]
    for offset, part in enumerate(parts):
        if signal.first_word + offset < len(words):
            words[signal.first_word + offset] = part
