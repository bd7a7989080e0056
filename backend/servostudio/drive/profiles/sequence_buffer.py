"""A sequence table reached through a buffer, as the TTA-PRO keeps its 128 sequences (docs/profibus.md §13).

The sequences live in the drive's EEPROM, which no request reaches directly: a procedure copies sequence n into a
buffer of fields (``read``), the fields are read or written one by one, another procedure copies the buffer into
sequence n (``write``), and writing ``checksum_value`` to that procedure after the last sequence updates the
table's checksum — without it the drive reports an EEPROM fault at its next power-up. All names are the profile's
semantic names, so the backup service never sees a PNU.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class SequenceBuffer:
    #: the backup file the table is kept in
    file: str
    #: sequences 0 .. count − 1
    count: int
    #: the procedure copying sequence n into the buffer, and the one copying the buffer into sequence n
    read: str
    write: str
    #: the value of ``write`` that stores the checksum of the whole table
    checksum_value: int
    #: the buffer's fields in the order they are written; the first is the sequence's control word, 0 when the
    #: sequence is not used (writing 0 invalidates it)
    fields: tuple[str, ...]

    @property
    def control(self) -> str:
        return self.fields[0]
