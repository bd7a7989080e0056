"""The hold-to-run watchdog and the quick test's limits, without a drive: a hold expires once its keepalives stop
(only the holder's count), a dropped hold never does, and limits refuse what is above them and accept raising."""

from __future__ import annotations

import threading
import time

import pytest
from hypothesis import given
from hypothesis import strategies as st

from servostudio.services.motion.hold import HoldWatch
from servostudio.services.motion.limits import LimitExceeded, LimitStore, MotionLimits

AXIS = ("sim", 1)


class Expiries:
    def __init__(self) -> None:
        self.seen: list[tuple[tuple[str, int], str, float, float]] = []
        self.event = threading.Event()

    def __call__(self, axis: tuple[str, int], client: str, last: float) -> None:
        self.seen.append((axis, client, last, time.monotonic()))
        self.event.set()


def test_a_hold_expires_after_its_last_keepalive_and_names_its_client():
    expiries = Expiries()
    watch = HoldWatch(expiries, timeout=0.1)
    watch.hold(AXIS, "a")
    for _ in range(5):
        assert watch.keepalive("a", AXIS) is not None
        time.sleep(0.01)
    assert expiries.event.wait(5)
    axis, client, last, fired = expiries.seen[0]
    assert (axis, client) == (AXIS, "a")
    assert fired - last >= 0.1  # never before the timeout
    assert watch.last(AXIS) is None  # forgotten once expired


def test_keepalives_of_another_client_keep_nothing_alive():
    expiries = Expiries()
    watch = HoldWatch(expiries, timeout=0.1)
    watch.hold(AXIS, "a")
    assert watch.keepalive("b", AXIS) is None
    assert watch.keepalive("a", ("sim", 2)) is None
    assert expiries.event.wait(5)


def test_keepalives_in_time_hold_and_a_dropped_hold_never_expires():
    expiries = Expiries()
    watch = HoldWatch(expiries, timeout=1.0)  # generous: a loaded host must not make this fail
    watch.hold(AXIS, "a")
    for _ in range(20):
        watch.keepalive("a", AXIS)
        time.sleep(0.02)
    assert not expiries.seen
    watch.drop(AXIS)
    assert not expiries.event.wait(1.5)


def test_close_ends_the_watchdog_thread_and_a_later_hold_starts_a_new_one():
    expiries = Expiries()
    watch = HoldWatch(expiries, timeout=0.1)
    watch.hold(AXIS, "a")
    first = watch._thread
    watch.close()
    assert first is not None and not first.is_alive()
    watch.hold(AXIS, "b")  # a server that holds again after a close is still watched
    assert expiries.event.wait(5) and expiries.seen[0][1] == "b"
    watch.close()


def test_limits_refuse_above_and_accept_what_a_user_raised():
    store = LimitStore()
    limits = store.of(AXIS)
    limits.check_velocity(AXIS, 300)
    with pytest.raises(LimitExceeded, match="velocity_rpm"):
        limits.check_velocity(AXIS, -300.5)
    with pytest.raises(LimitExceeded, match="distance_revolutions"):
        limits.check_distance(AXIS, 1.01)
    with pytest.raises(LimitExceeded, match="seconds"):
        limits.check_seconds(AXIS, 0)
    raised = store.set(AXIS, velocity_rpm=1000, distance_revolutions=None)
    assert raised == MotionLimits(velocity_rpm=1000.0)
    raised.check_velocity(AXIS, 999)
    assert store.of(("sim", 2)) == MotionLimits()  # per axis
    with pytest.raises(LimitExceeded):
        store.set(AXIS, seconds=float("nan"))
    with pytest.raises(LimitExceeded):
        store.set(AXIS, velocity_rpm=1e9)


@given(st.floats(allow_nan=True, allow_infinity=True))
def test_a_velocity_is_accepted_exactly_when_finite_and_within_the_limit(rpm):
    limits = MotionLimits()
    inside = abs(rpm) <= limits.velocity_rpm  # False for NaN
    try:
        limits.check_velocity(AXIS, rpm)
        accepted = True
    except LimitExceeded:
        accepted = False
    assert accepted == inside
