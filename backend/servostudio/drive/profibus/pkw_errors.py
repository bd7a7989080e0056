"""Negative PKW replies as readable errors naming the parameter (TTA-PRO Profibus Communication Profile,
Chapter 1 §3.2, L334-344): AK 7 with an error number in PWE, AK 8 when the PKW interface is inhibited."""

from __future__ import annotations

from servostudio.errors import Conflict

ERROR_TEXTS = {
    0: "illegal PNU",
    1: "parameter cannot be modified",
    2: "lower or upper limit exceeded",
    3: "index error",
    5: "incorrect data type",
    17: "instruction cannot be executed in the current operating state",
    18: "other error",
}


class PkwError(Conflict):
    """A parameter request the drive did not carry out (like an SDO abort: the drive's state or rules refused it)."""

    def __init__(self, pnu: int, index: int, reason: str) -> None:
        self.pnu = pnu
        self.index = index
        self.reason = reason
        address = f"PNU {pnu}" if index == 0 else f"PNU {pnu}[{index}]"
        super().__init__(f"{address}: {reason}")


class PkwRefused(PkwError):
    """AK 7: the drive refused the instruction with `error_number`."""

    def __init__(self, pnu: int, index: int, error_number: int) -> None:
        self.error_number = error_number
        text = ERROR_TEXTS.get(error_number, "unknown error")
        super().__init__(pnu, index, f"{text} (PKW error {error_number})")


class PkwInhibited(PkwError):
    """AK 8: the PKW interface is inhibited (e.g. the drive is controlled locally over RS-232)."""

    def __init__(self, pnu: int, index: int) -> None:
        super().__init__(pnu, index, "PKW interface inhibited (AK 8)")


class ProcedureFailed(PkwError):
    """A procedure PNU ended with PWE 2."""

    def __init__(self, pnu: int, index: int) -> None:
        super().__init__(pnu, index, "procedure ended with an error (PWE 2)")
