"""What every CLI command that runs one long job shares (procedures, identification, frequency response, motion):
interruption by a signal turned into an event, that event forwarded to the job's cancellation, progress on stderr,
and following a server's job until it ends."""

from __future__ import annotations

import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from servostudio.cli.liveclient import LiveClient
from servostudio.services.cancel import Cancellation

POLL = 0.1


@contextmanager
def interruptible() -> Iterator[threading.Event]:
    """Ctrl-C, SIGTERM and SIGHUP set the event (the job is then aborted, the axis stopped) instead of killing us."""
    interrupted = threading.Event()
    main = threading.current_thread() is threading.main_thread()
    signals = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP) if main else ()
    previous = {sig: signal.signal(sig, lambda *_: interrupted.set()) for sig in signals}
    try:
        yield interrupted
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def forward_interrupt(interrupted: threading.Event, cancellation: Cancellation) -> Callable[[], None]:
    """Cancel the run when the command is interrupted; returns what stops watching."""
    done = threading.Event()

    def watch() -> None:
        while not done.wait(POLL):
            if interrupted.is_set():
                cancellation.cancel()
                return

    threading.Thread(target=watch, name="command-interrupt", daemon=True).start()
    return done.set


def print_progress(event: dict[str, object]) -> None:
    message, fraction = event.get("message"), event.get("fraction")
    shown = f" {float(fraction) * 100:.0f} %" if isinstance(fraction, (int, float)) else ""
    print(f"{event.get('phase')}: {message}{shown}", file=sys.stderr, flush=True)


def follow_job(live: LiveClient, job_id: str, interrupted: threading.Event) -> dict[str, Any]:
    """The server's job once it ended; interrupted before: it is cancelled (= aborted) and waited for."""
    cancelled = False
    while True:
        job: dict[str, Any] = live.call("GET", f"/api/jobs/{job_id}")
        if job["state"] != "running":
            return job
        if interrupted.is_set() and not cancelled:
            live.call("POST", f"/api/jobs/{job_id}/cancel")
            cancelled = True
        time.sleep(POLL)
