"""The first SYNC of a TPDO capture asks which nodes are OPERATIONAL (docs/scope.md §7, step 3). On a loaded host
an OPERATIONAL node's answer to it may come after the probe's wait: that late frame must not become sample 0 (it
would shift every sample of its TPDO by one SYNC), and the node, OPERATIONAL before, must stay so after."""

from __future__ import annotations

import threading
import time

from tests.support.sync_probe import POSITION, STATUS_WORD, SyncProbe, moving, offset_of, rows_of

from servostudio.drive.nmt import NmtCommand, send_nmt
from servostudio.services.scope import CaptureDefinition, capture, stream
from servostudio.services.scope import identity_of as identity


def late_first_frame(on_frame):
    """Each receiver's first frame (the answer to the probe SYNC) delivered 25 ms late: after the probe's wait."""
    seen: set[int] = set()

    def delayed(receiver, cob_id, data, timestamp) -> None:
        if id(receiver) in seen:
            on_frame(receiver, cob_id, data, timestamp)
        else:
            seen.add(id(receiver))
            threading.Timer(0.025, on_frame, (receiver, cob_id, data, timestamp)).start()

    return delayed


def test_a_late_answer_to_the_probe_sync_is_no_sample_and_an_operational_node_stays_so(bench, monkeypatch):
    moving(bench, 2, "cd1k", 50_000)
    send_nmt(bench.connection.link, NmtCommand.START, 2)
    deadline = time.monotonic() + 5
    while bench.network.node(2).state.name != "OPERATIONAL":
        assert time.monotonic() < deadline
        time.sleep(0.01)
    started: list[int] = []
    real_nmt = stream.send_nmt

    def noted(link, command, node):
        if command is NmtCommand.START:
            started.append(node)
        return real_nmt(link, command, node)

    monkeypatch.setattr(stream, "send_nmt", noted)
    monkeypatch.setattr(stream, "PROBE_SECONDS", 0.0)
    monkeypatch.setattr(stream._Receiver, "on_frame", late_first_frame(stream._Receiver.on_frame))
    cd1k = bench.drive(2)
    probe = SyncProbe(bench.network, 2, [POSITION, STATUS_WORD])
    definition = CaptureDefinition(("0x6064,0", "0x6041,0"), period_us=1000, samples=200, timeout_s=10)
    made = capture(cd1k, identity(bench.connection, cd1k), definition, axes=bench.connection.drive)
    assert started == [2]  # the answer was late: the node looked silent
    assert offset_of(probe.values(), rows_of(made)) == 1  # sample 0 answers the capture's first SYNC, not the probe
    with bench.network.lock:
        assert bench.network.node(2).state.name == "OPERATIONAL"  # as it was before the capture
