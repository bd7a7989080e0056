"""The chaining graph: edges by kind and the findings, on small tables read by the file reader."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st
from tests.support.sequence_programs import CONDITIONAL_JUMP, COUNTER_LOOP, program

from servostudio.services import sequences


def graph(text: str, types_mask: int = 0b11111) -> dict:
    return sequences.chaining_graph(sequences.parse(text), types_mask).as_dict()


def kinds(found: dict) -> set[str]:
    return {finding["kind"] for finding in found["findings"]}


def test_the_counter_loop_has_a_counter_edge_and_no_finding():
    found = graph(COUNTER_LOOP)
    edges = {(edge["from"], edge["to"], edge["kind"]) for edge in found["edges"]}
    assert edges == {(1, 2, "next"), (2, 3, "next"), (2, 1, "counter")}
    assert found["findings"] == []


def test_the_conditional_jump_has_a_condition_edge():
    edges = {(edge["from"], edge["to"], edge["kind"]) for edge in graph(CONDITIONAL_JUMP)["edges"]}
    assert (2, 4, "condition") in edges and (2, 3, "next") in edges


def test_a_loop_without_exit_and_the_sequences_nothing_reaches():
    found = graph(program((1, "SeqNext=2"), (2, "SeqNext=1"), (5, "SeqNext=-1")))
    loops = [f for f in found["findings"] if f["kind"] == "loop_without_exit"]
    assert [loop["sequences"] for loop in loops] == [[1, 2]]
    assert [f["sequences"] for f in found["findings"] if f["kind"] == "unreachable"] == [[1, 2]]


def test_a_dangling_link_and_an_unused_one():
    found = graph(program((1, "SeqNext=9\nSeqLink=4")))
    assert kinds(found) == {"dangling"}
    assert {(edge["kind"], edge["dangling"]) for edge in found["edges"]} == {("next", True), ("link", True)}


def test_two_counters_in_one_loop():
    text = program((1, "SeqNext=2"), (2, "SeqCount=2\nSeqLink=3\nSeqNext=-1"), (3, "SeqCount=3\nSeqLink=1\nSeqNext=2"))
    assert "counters" in kinds(graph(text))


def test_a_type_the_drive_does_not_support():
    found = graph(COUNTER_LOOP, types_mask=0b11110)
    assert [f["sequences"] for f in found["findings"] if f["kind"] == "unsupported_type"] == [[1], [2], [3]]
    assert not any(node["supported"] for node in found["nodes"])


@st.composite
def programs(draw) -> str:
    """Small random programs: numbers 0..9, links anywhere in −1..11 (some to empty slots), counters, conditions."""
    numbers = draw(st.lists(st.integers(0, 9), min_size=1, max_size=6, unique=True))
    target = st.integers(-1, 11)
    chains = []
    for number in numbers:
        count = draw(st.sampled_from([0, 0, 2]))
        condition = draw(st.sampled_from(["", 'StartCond="1......."\n']))
        chains.append((number, f"SeqNext={draw(target)}\nSeqLink={draw(target)}\nSeqCount={count}\n{condition}"))
    return program(*chains)


@settings(max_examples=150, deadline=None)
@given(programs())
def test_the_graph_is_consistent_with_its_table(text):
    found = graph(text)
    nodes = {node["sequence"] for node in found["nodes"]}
    assert nodes == set(sequences.parse(text))
    for edge in found["edges"]:
        assert edge["from"] in nodes and edge["dangling"] == (edge["to"] not in nodes)
    reachable = {node["sequence"] for node in found["nodes"] if node["reachable"]}
    unreachable = [f["sequences"] for f in found["findings"] if f["kind"] == "unreachable"]
    assert unreachable in ([], [sorted(nodes - reachable)])
    assert all(set(f["sequences"]) <= nodes for f in found["findings"])
    entries = {node["sequence"] for node in found["nodes"] if node["entry"]}
    assert entries and entries <= reachable
