"""How every CLI command answers: JSON on stdout, a readable error on stderr, the exit code of the error's kind.

The exit codes come from the one table of ``servostudio.errors`` (3 refused — nothing written, 4 not found, 5 the
bus or the drive failed, 6 not logged in — no or a bad token, 7 the caller's level is too low); 2 is argparse's own
for bad arguments, 70 an unexpected error (a bug).
"""

from __future__ import annotations

import json
import sys
import traceback
from typing import Any

from servostudio.errors import OUTCOMES, ErrorKind, ServoStudioError

EXIT_OK = 0


def emit(result: Any) -> int:
    """Print `result` as JSON on stdout; the command succeeded."""
    json.dump(result, sys.stdout, indent=2, sort_keys=False, default=str)
    sys.stdout.write("\n")
    return EXIT_OK


def refused(error: ServoStudioError) -> int:
    """Report a refusal or failure on stderr; its kind gives the exit code."""
    print(f"error: {error}", file=sys.stderr)
    return error.outcome.exit_code


def crashed(error: Exception) -> int:
    """Report an exception outside the taxonomy as what it is, a bug, with its traceback."""
    traceback.print_exception(error, file=sys.stderr)
    print(
        f"error: unexpected {type(error).__name__}: {error} (a bug: please report it with the trace above)",
        file=sys.stderr,
    )
    return OUTCOMES[ErrorKind.INTERNAL].exit_code
