"""``servostudio ARGS…`` in this process, for a bench that splits the server's CPU time by thread: on SIGUSR1 the
CPU seconds of each live thread, by its Python name (``sim-clock``: the simulated drives; ``bus sim``: the bus
reader; ``MainThread``: the event loop and the WebSockets; ``job-…``: the jobs), go to the JSON file named first.
Python 3.11 does not give its threads' names to the OS, so ``/proc`` alone cannot tell them apart.

    python bench/serve_threads.py TIMES.json serve --port …
"""

from __future__ import annotations

import json
import os
import signal
import sys
import threading
from pathlib import Path

from servostudio.cli import main

TICKS = os.sysconf("SC_CLK_TCK")


def thread_seconds() -> dict[str, float]:
    """User + system CPU seconds of every live thread (``/proc/self/task/<native id>/stat``), summed by name."""
    seconds: dict[str, float] = {}
    for thread in threading.enumerate():
        try:
            stat = Path(f"/proc/self/task/{thread.native_id}/stat").read_text()
        except OSError:  # the thread ended meanwhile
            continue
        fields = stat.rsplit(")", 1)[1].split()
        seconds[thread.name] = seconds.get(thread.name, 0.0) + (int(fields[11]) + int(fields[12])) / TICKS
    return seconds


def write_times(path: Path) -> None:
    """The threads' CPU seconds into ``path``, whole or not at all (the reader waits for the file)."""
    partial = path.with_suffix(".partial")
    partial.write_text(json.dumps(thread_seconds()))
    partial.replace(path)


if __name__ == "__main__":
    times = Path(sys.argv[1])
    signal.signal(signal.SIGUSR1, lambda *_: write_times(times))
    sys.exit(main(sys.argv[2:]))
