"""How every CLI command answers: JSON on stdout, a readable error on stderr, a meaningful exit code."""

from __future__ import annotations

import json
import sys
from typing import Any

EXIT_OK = 0
EXIT_USAGE = 2  # argparse's own code for bad arguments
EXIT_INVALID_INPUT = 3  # a file or value was refused (nothing was written)
EXIT_NOT_FOUND = 4  # unknown device, project, node or object
EXIT_COMMUNICATION = 5  # the bus or a drive did not answer, or refused (SDO abort)


class CommandError(Exception):
    """A failure the CLI reports as `error: MESSAGE` with its exit code."""

    def __init__(self, message: str, exit_code: int) -> None:
        super().__init__(message)
        self.exit_code = exit_code


def emit(result: Any) -> int:
    """Print `result` as JSON on stdout; the command succeeded."""
    json.dump(result, sys.stdout, indent=2, sort_keys=False, default=str)
    sys.stdout.write("\n")
    return EXIT_OK
