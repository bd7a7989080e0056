"""The virtual clock: events in time order, same-instant events in scheduling order, lazy events included."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from servostudio.sim.clock import VirtualClock


@given(st.lists(st.tuples(st.integers(0, 20), st.booleans()), max_size=40))
def test_lazy_and_other_events_run_in_time_then_scheduling_order(events):
    clock = VirtualClock()
    ran: list[int] = []
    for number, (tick, lazy) in enumerate(events):
        clock.call_at(tick * 1e-4, lambda number=number: ran.append(number), lazy=lazy)
    clock.run_until(1.0)
    assert ran == sorted(range(len(events)), key=lambda number: (events[number][0], number))


def test_the_next_event_the_real_time_loop_wakes_for_is_never_a_lazy_one():
    clock = VirtualClock()
    clock.call_at(0.001, lambda: None, lazy=True)
    assert clock.next_event_time() is None
    cancelled = clock.call_at(0.002, lambda: None)
    clock.call_at(0.003, lambda: None)
    cancelled.cancel()
    assert clock.next_event_time() == 0.003
