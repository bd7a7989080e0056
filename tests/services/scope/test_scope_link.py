"""A link cut during the upload of a recording: a clear error, nothing kept, the recorder left clean, and the next
capture works once the link is back (the simulated drives over socketcand, whose endpoint the test cuts)."""

from __future__ import annotations

import pytest
from tests.support.sim_endpoints import wait_connected

from servostudio.services.scope import CaptureDefinition, UploadFailed, capture, identity_of
from servostudio.services.scope.stream import StreamFailed

FULL = CaptureDefinition(("0x6064,0", "0x606C,0", "0x6062,0", "0x60F4,0"), samples=2048)  # 32 KB


def test_a_cut_during_the_upload_fails_cleanly_and_the_next_capture_works(connection, socketcand, sim_network, slow):
    drive = connection.drive(1)
    cut: list[dict] = []

    def cut_mid_upload(event: dict) -> None:
        if event["stage"] == "uploading" and event["done"] > 0 and not cut:
            cut.append(event)
            socketcand.cut()

    with slow(sim_network), pytest.raises(UploadFailed) as failed:
        capture(drive, identity_of(connection, drive), FULL, cut_mid_upload)
    assert cut and cut[0]["done"] < cut[0]["total"] == 32768
    assert "the upload of the recording failed" in str(failed.value) and "nothing was kept" in str(failed.value)
    assert failed.value.kind.value == "communication"

    socketcand.restore()
    wait_connected(connection)
    with sim_network.lock:
        assert sim_network.node(1).store.get(0x5829, 0) == 4  # done: the recording is still there, nothing armed
    again = capture(drive, identity_of(connection, drive), CaptureDefinition(("0x6041,0",), samples=64))
    assert again.samples == 64 and again.columns[0][0] == drive.read("0x6041").raw


def test_a_cut_during_a_tpdo_capture_fails_clearly_and_the_next_one_works(connection, socketcand):
    drive = connection.drive(2)
    stages: list[str] = []

    def cut_while_recording(event: dict) -> None:
        stages.append(event["stage"])
        if event["stage"] == "recording":
            socketcand.cut()

    definition = CaptureDefinition(("0x6041,0",), period_us=1000, samples=5000, source="tpdo", timeout_s=30)
    with pytest.raises(StreamFailed) as failed:
        capture(drive, identity_of(connection, drive), definition, cut_while_recording)
    assert "recording" in stages and failed.value.kind.value == "communication"
    message = str(failed.value)  # what failed, that nothing was kept, and what could not be put back
    assert "the capture's SYNC stopped" in message and "nothing was kept" in message
    assert "the drives' TPDO configuration could not be written back (node 2 TPDO 4" in message

    socketcand.restore()
    wait_connected(connection)
    again = capture(drive, identity_of(connection, drive), CaptureDefinition(("0x6041,0",), period_us=1000,
                                                                              samples=20, source="tpdo"))  # fmt: skip
    assert again.source == "tpdo" and again.samples == 20 and again.columns[0][0] == drive.read("0x6041").raw
