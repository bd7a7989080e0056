"""The SDO engine against canopen slaves on a python-can virtual bus."""

from __future__ import annotations

import can
import pytest

from servostudio.drive.link import BusLink
from servostudio.drive.sdo import SdoAbortError, SdoEngine, SdoLinkError, SdoTimeoutError


@pytest.fixture
def engine(slaves, virtual_channel):
    link = BusLink("test", lambda: can.Bus(interface="virtual", channel=virtual_channel, receive_own_messages=False))
    assert link.start(wait=2.0)
    yield SdoEngine(link, timeout=0.3)
    link.close()


def test_expedited_and_segmented_uploads(engine):
    assert engine.upload(1, 0x1000, 0).result(2) == (0x00020192).to_bytes(4, "little")
    assert engine.upload(5, 0x2002, 0).result(2) == (-300).to_bytes(2, "little", signed=True)
    assert engine.upload(5, 0x2004, 0).result(2) == b"axis name longer than four"


def test_downloads_reach_the_slave(engine, slaves):
    engine.download(1, 0x2003, 0, (987654).to_bytes(4, "little")).result(2)
    assert slaves[1].sdo[0x2003].raw == 987654
    engine.download(5, 0x2004, 0, b"a new, long axis name!").result(2)  # segmented, 4 segments
    assert slaves[5].sdo[0x2004].raw == "a new, long axis name!"
    assert engine.upload(5, 0x2004, 0).result(2) == b"a new, long axis name!"


def test_many_transfers_to_several_nodes_complete_in_order(engine, slaves):
    futures = [
        (node, value, engine.download(node, 0x2003, 0, value.to_bytes(4, "little")))
        for value in range(20)
        for node in (1, 5)
    ]
    for _, _, future in futures:
        future.result(5)
    assert slaves[1].sdo[0x2003].raw == 19 and slaves[5].sdo[0x2003].raw == 19
    reads = [engine.upload(node, 0x2001, 0) for node in (1, 5) for _ in range(10)]
    assert all(future.result(5) == b"\x07" for future in reads)


def test_abort_names_node_object_and_meaning(engine):
    with pytest.raises(SdoAbortError) as error:
        engine.upload(1, 0x2FFF, 0).result(2)
    assert error.value.code == 0x06020000
    assert str(error.value) == (
        "node 1, object 0x2FFF,0: object does not exist in the object dictionary (SDO abort 0x06020000)"
    )


def test_timeout_names_node_and_object(engine):
    with pytest.raises(
        SdoTimeoutError,
        match=r"node 9, object 0x1000,0: no SDO response within 300 ms on bus test "
        r"\(request sent twice\)",
    ):
        engine.upload(9, 0x1000, 0).result(3)
    with pytest.raises(SdoTimeoutError, match=r"node 9, object 0x2003,0: no SDO response within 300 ms on bus test$"):
        engine.download(9, 0x2003, 0, b"\x01").result(3)
    # The node's queue goes on after a timeout.
    assert engine.upload(1, 0x2001, 0).result(2) == b"\x07"


def test_link_down_fails_transfers_clearly(engine):
    engine.link.close()
    with pytest.raises(SdoLinkError, match="bus test was closed"):  # not "not connected": nobody will reconnect it
        engine.upload(1, 0x2001, 0).result(2)


def test_a_read_whose_request_was_lost_is_sent_again(virtual_channel):
    """A responder that ignores the first request of node 20, as if the frame had been lost."""
    import threading

    drive_side = can.Bus(interface="virtual", channel=virtual_channel, receive_own_messages=False)
    requests: list[bytes] = []
    stop = threading.Event()

    def respond() -> None:
        while not stop.is_set():
            message = drive_side.recv(0.05)
            if message is None or message.arbitration_id != 0x614:
                continue
            requests.append(bytes(message.data))
            if len(requests) > 1:
                drive_side.send(
                    can.Message(
                        arbitration_id=0x594,
                        is_extended_id=False,
                        data=bytes([0x4F]) + bytes(message.data[1:4]) + bytes([42, 0, 0, 0]),
                    )
                )

    responder = threading.Thread(target=respond, daemon=True)
    responder.start()
    link = BusLink("lossy", lambda: can.Bus(interface="virtual", channel=virtual_channel, receive_own_messages=False))
    assert link.start(wait=2.0)
    try:
        assert SdoEngine(link, timeout=0.2).upload(20, 0x2001, 0).result(3) == b"\x2a"
        assert len(requests) == 2 and requests[0] == requests[1]
    finally:
        stop.set()
        responder.join()
        link.close()
        drive_side.shutdown()


def test_a_late_answer_about_another_object_is_ignored(virtual_channel):
    """After a timeout, the drive's late reply must not be taken for the answer to the next request."""
    import threading

    drive_side = can.Bus(interface="virtual", channel=virtual_channel, receive_own_messages=False)
    stop = threading.Event()

    def respond() -> None:
        while not stop.is_set():
            message = drive_side.recv(0.05)
            if message is None or message.arbitration_id != 0x615 or message.data[0] != 0x40:
                continue
            if bytes(message.data[1:3]) == b"\x02\x20":  # 0x2002: answer the earlier 0x2001 first (late), then it
                late = bytes([0x4F, 0x01, 0x20, 0x00, 11, 0, 0, 0])
                drive_side.send(can.Message(arbitration_id=0x595, is_extended_id=False, data=late))
            reply = bytes([0x4F]) + bytes(message.data[1:4]) + bytes([22, 0, 0, 0])
            drive_side.send(can.Message(arbitration_id=0x595, is_extended_id=False, data=reply))

    responder = threading.Thread(target=respond, daemon=True)
    responder.start()
    link = BusLink("late", lambda: can.Bus(interface="virtual", channel=virtual_channel, receive_own_messages=False))
    assert link.start(wait=2.0)
    try:
        assert SdoEngine(link, timeout=0.5).upload(21, 0x2002, 0).result(3) == bytes([22])
    finally:
        stop.set()
        responder.join()
        link.close()
        drive_side.shutdown()


def test_a_batch_of_reads_gives_every_outcome_in_order(engine):
    """One future for many reads: values in request order, an abort where the object is missing, each reported."""
    objects = [(0x1000, 0), (0x2FFF, 0), (0x2004, 0), (0x2002, 0)]
    reported: list[int] = []
    batch = engine.upload_all(
        5,
        objects,
        convert=lambda position, data: (position, data),
        on_each=lambda position, outcome: reported.append(position),
    )
    outcomes = batch.future.result(5)
    assert outcomes[0] == (0, (0x00020192).to_bytes(4, "little"))
    assert isinstance(outcomes[1], SdoAbortError) and outcomes[1].code == 0x06020000
    assert outcomes[2] == (2, b"axis name longer than four")
    assert outcomes[3] == (3, (-300).to_bytes(2, "little", signed=True))
    assert sorted(reported) == [0, 1, 2, 3]


def test_a_cancelled_batch_sends_no_more_requests(engine, slaves):
    """Cancelling drops the reads not yet sent (they end as CancelledError); the node serves the next caller."""
    from concurrent.futures import CancelledError

    batch = engine.upload_all(1, [(0x2001, 0)] * 200)
    batch.cancel()
    outcomes = batch.future.result(5)
    cancelled = [outcome for outcome in outcomes if isinstance(outcome, CancelledError)]
    read = [outcome for outcome in outcomes if outcome == b"\x07"]
    assert len(cancelled) + len(read) == 200 and len(cancelled) >= 190
    assert engine.upload(1, 0x2001, 0).result(2) == b"\x07"


def test_a_conversion_error_ends_only_its_own_read(engine):
    def convert(position: int, data: bytes) -> int:
        if position == 1:
            raise ValueError("not a value of this type")
        return data[0]

    outcomes = engine.upload_all(1, [(0x2001, 0)] * 3, convert=convert).future.result(5)
    assert outcomes[0] == 7 and outcomes[2] == 7
    assert isinstance(outcomes[1], ValueError)


def test_a_lost_link_ends_a_batch_with_link_errors(engine):
    engine.link.close()
    outcomes = engine.upload_all(1, [(0x2001, 0), (0x2002, 0)]).future.result(2)
    assert all(isinstance(outcome, SdoLinkError) for outcome in outcomes)


def test_an_empty_batch_is_done_at_once(engine):
    assert engine.upload_all(1, []).future.result(0) == []


def test_a_drive_that_stops_answering_ends_the_batch_at_the_first_silent_read(engine):
    from concurrent.futures import CancelledError

    outcomes = engine.upload_all(9, [(0x1000, 0)] * 50).future.result(10)
    assert isinstance(outcomes[0], SdoTimeoutError)
    assert all(isinstance(outcome, CancelledError) for outcome in outcomes[1:])


def test_a_batch_of_writes_reaches_the_drive_in_order(engine, slaves):
    writes = [
        (0x2003, 0, (1).to_bytes(4, "little")),
        (0x2FFF, 0, b"\x01"),
        (0x2004, 0, b"a long new axis name"),
        (0x2003, 0, (2).to_bytes(4, "little")),
    ]
    outcomes = engine.download_all(1, writes, convert=lambda position, _: position).future.result(5)
    assert outcomes[0] == 0 and outcomes[2] == 2 and outcomes[3] == 3
    assert isinstance(outcomes[1], SdoAbortError) and outcomes[1].code == 0x06020000
    assert slaves[1].sdo[0x2003].raw == 2  # the later write of the same object came later
    assert slaves[1].sdo[0x2004].raw == "a long new axis name"


def test_a_batch_write_without_data_is_refused_before_anything_is_sent(engine, slaves):
    with pytest.raises(ValueError, match="at least one byte"):
        engine.download_all(1, [(0x2003, 0, (5).to_bytes(4, "little")), (0x2001, 0, b"")])
    assert slaves[1].sdo[0x2003].raw != 5


class _Counter:
    """Counts the finished transfers of batches (``on_each`` runs on the bus reader thread)."""

    def __init__(self) -> None:
        self.done = 0

    def __call__(self, position: int, outcome: object) -> None:
        self.done += 1


def test_a_single_read_is_served_ahead_of_the_queued_batches(engine):
    """Interactive reads go ahead of bulk work: behind five queued 300-read batches (a backup each), a read waits
    for the transfer on the wire only, not for 1500 reads."""
    counter = _Counter()
    batches = [engine.upload_all(1, [(0x2001, 0)] * 300, on_each=counter) for _ in range(5)]
    single = engine.upload(1, 0x2001, 0)
    submitted = counter.done  # read after the submission: a descheduled test thread only makes the margin larger
    answered: list[int] = []
    single.add_done_callback(lambda _: answered.append(counter.done))  # counted by the engine's thread, at the answer
    assert single.result(5) == b"\x07"
    assert answered[0] - submitted <= 2  # the transfer on the wire, and at most one that finished meanwhile
    outcomes = [outcome for batch in batches for outcome in batch.future.result(20)]
    assert outcomes == [b"\x07"] * 1500  # the batches themselves are unharmed, in order


def test_closing_the_bus_fails_the_work_in_flight_at_once(engine):
    """Nothing answers or times out a transfer once the reader thread stopped: closing must end them itself."""
    batch = engine.upload_all(1, [(0x2001, 0)] * 1000)
    single = engine.upload(1, 0x2002, 0)
    engine.link.close()
    outcomes = batch.future.result(1)
    assert isinstance(outcomes[-1], SdoLinkError) and "bus test was closed" in str(outcomes[-1])
    with pytest.raises(SdoLinkError, match="was closed"):
        single.result(1)
    with pytest.raises(SdoLinkError, match="bus test was closed"):  # a request after the close too
        engine.upload(1, 0x2001, 0).result(1)


def test_a_wait_is_bounded_even_when_no_outcome_comes():
    """`settle` is the safety net of every wait: a future nobody completes ends in the taxonomy's timeout."""
    from concurrent.futures import Future

    from servostudio.drive.sdo import OutcomeOverdue, settle
    from servostudio.errors import ErrorKind

    with pytest.raises(OutcomeOverdue) as overdue:
        settle(Future(), 0.05)
    assert overdue.value.kind is ErrorKind.TIMEOUT
