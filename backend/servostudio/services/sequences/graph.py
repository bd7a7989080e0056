"""The chaining graph of a sequence set: where a program goes from each sequence, and what looks wrong.

Edges follow the sequencer's rules (decisions.md §3, docs/sequences.md "Chaining"):

- ``next``: SeqNext, taken after the sequence ends (with a counter: once the counter reached 0);
- ``counter``: SeqLink of a sequence with SeqCount > 0, taken while its loop counter is not 0;
- ``condition``: SeqLink of a sequence with a start condition, taken when the condition does not hold (skip);
- ``link``: a SeqLink neither rule ever takes (no SeqCount, no StartCond): drawn, never followed.

Findings: loops without exit, dangling links (to an empty slot or past the drive's 0x3612: the program ends
there), unreachable sequences, more than one counter active in one loop (the drive has one counter: nested loops
never end), and types the drive does not support (0x360F).  The graph judges a table the file reader already
validated (``servostudio.formats.sequence``): validation has one implementation, the reader's.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from servostudio.formats.sequence import MAX_SEQUENCES, BitPattern, SequenceTable, SequenceType

#: 0x360F when the drive is not asked: POS, HOME, SPEED, TORQUE and GEAR (bits 0..4)
ALL_TYPES = 0b11111
NO_SEQUENCE = -1
EXITS = ("next", "counter", "condition")  # the edges a program can take; ``link`` is never followed


@dataclass(frozen=True)
class Edge:
    source: int
    target: int
    kind: str
    dangling: bool = False

    def as_dict(self) -> dict[str, object]:
        return {"from": self.source, "to": self.target, "kind": self.kind, "dangling": self.dangling}


@dataclass(frozen=True)
class Finding:
    kind: str
    sequences: tuple[int, ...]
    message: str

    def as_dict(self) -> dict[str, object]:
        return {"kind": self.kind, "sequences": list(self.sequences), "message": self.message}


@dataclass
class ChainingGraph:
    nodes: list[dict[str, object]] = field(default_factory=list)
    edges: list[Edge] = field(default_factory=list)
    findings: list[Finding] = field(default_factory=list)

    def as_dict(self) -> dict[str, object]:
        return {
            "nodes": self.nodes,
            "edges": [edge.as_dict() for edge in self.edges],
            "findings": [finding.as_dict() for finding in self.findings],
        }


def supported(kind: SequenceType, types_mask: int) -> bool:
    """0x360F bit n−1 lists type n (bit 0 POS … bit 4 GEAR)."""
    return bool(types_mask >> (int(kind) - 1) & 1)


def chaining_graph(
    table: SequenceTable, types_mask: int = ALL_TYPES, max_sequences: int = MAX_SEQUENCES
) -> ChainingGraph:
    """The graph of ``table`` on a drive that supports ``types_mask`` (0x360F) and ``max_sequences`` (0x3612)."""
    edges = [edge for number in table for edge in _edges(table, number, max_sequences)]
    graph = ChainingGraph(edges=edges)
    followed = _successors(table, edges)
    entries = _entries(table, followed)
    reachable = _reach(entries, followed)
    for number, sequence in table.sequences.items():
        graph.nodes.append(
            {
                "sequence": number,
                "type": sequence.type.name,
                "supported": supported(sequence.type, types_mask),
                "entry": number in entries,
                "reachable": number in reachable,
                "waits": _waits(table, number),
            }
        )
    graph.findings = [
        *_dangling(edges),
        *_loops_without_exit(table, followed),
        *_counters(table, followed),
        *_unreachable(table, reachable),
        *_unsupported(table, types_mask),
    ]
    return graph


def _edges(table: SequenceTable, number: int, max_sequences: int) -> list[Edge]:
    following, count, link = (_number(table, number, key) for key in ("SeqNext", "SeqCount", "SeqLink"))
    has_condition = _has_condition(table, number)
    link_kind = "counter" if count > 0 else "condition" if has_condition else "link"
    made = [(following, "next"), (link, link_kind)]
    if count > 0 and has_condition:
        made.append((link, "condition"))
    return [
        Edge(number, target, kind, target not in table or target >= max_sequences)
        for target, kind in made
        if target != NO_SEQUENCE
    ]


def _number(table: SequenceTable, number: int, keyword: str) -> int:
    value = table[number][keyword]
    assert isinstance(value, int)  # SeqNext, SeqCount and SeqLink are numbers, never patterns
    return value


def _has_condition(table: SequenceTable, number: int) -> bool:
    condition = table[number]["StartCond"]
    return isinstance(condition, BitPattern) and bool(condition.zeros | condition.ones)


def _waits(table: SequenceTable, number: int) -> bool:
    """A start condition with SeqLink = −1: the sequencer waits for it instead of skipping."""
    return _has_condition(table, number) and _number(table, number, "SeqLink") == NO_SEQUENCE


def _successors(table: SequenceTable, edges: Iterable[Edge]) -> dict[int, set[int]]:
    """Where a program can go from each sequence (edges it can take, to defined sequences)."""
    followed: dict[int, set[int]] = {number: set() for number in table}
    for edge in edges:
        if edge.kind in EXITS and not edge.dangling:
            followed[edge.source].add(edge.target)
    return followed


def _entries(table: SequenceTable, followed: dict[int, set[int]]) -> set[int]:
    """Sequences no other one leads to: where programs start (the lowest number if every one is led to)."""
    targets = {target for source, found in followed.items() for target in found if target != source}
    roots = {number for number in table if number not in targets}
    return roots or ({min(table)} if len(table) else set())


def _reach(starts: Iterable[int], followed: dict[int, set[int]]) -> set[int]:
    seen: set[int] = set()
    stack = list(starts)
    while stack:
        number = stack.pop()
        if number not in seen:
            seen.add(number)
            stack.extend(followed.get(number, ()))
    return seen


def _ends(table: SequenceTable, followed: dict[int, set[int]]) -> set[int]:
    """Sequences from which a program can end: an exit to −1 or to an empty slot, or a path to one."""
    ending = {number for number in table if _has_end_exit(table, number)}
    changed = True
    while changed:
        grown = {number for number, found in followed.items() if found & ending} - ending
        ending |= grown
        changed = bool(grown)
    return ending


def _has_end_exit(table: SequenceTable, number: int) -> bool:
    """SeqNext = −1, or a next sequence that is no defined one, ends the program (so does a counter's or a
    skipping condition's SeqLink of that kind); a waiting condition does not."""
    exits = [_number(table, number, "SeqNext")]
    if _number(table, number, "SeqCount") > 0 or (_has_condition(table, number) and not _waits(table, number)):
        exits.append(_number(table, number, "SeqLink"))
    return any(target == NO_SEQUENCE or target not in table for target in exits)


def _components(followed: dict[int, set[int]]) -> list[set[int]]:
    """Strongly connected components that hold a cycle (Tarjan, iterative enough for 128 nodes)."""
    index: dict[int, int] = {}
    low: dict[int, int] = {}
    stack: list[int] = []
    found: list[set[int]] = []

    def visit(node: int) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for target in followed[node]:
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = set()
            while True:
                member = stack.pop()
                component.add(member)
                if member == node:
                    break
            if len(component) > 1 or node in followed[node]:
                found.append(component)

    for node in sorted(followed):
        if node not in index:
            visit(node)
    return found


def _loops_without_exit(table: SequenceTable, followed: dict[int, set[int]]) -> list[Finding]:
    ending = _ends(table, followed)
    return [
        Finding(
            "loop_without_exit",
            tuple(sorted(loop)),
            f"sequences {_listed(loop)} loop for ever: no path from them ends the program (SeqNext −1, a counter, "
            "a start condition that skips out)",
        )
        for loop in _components(followed)
        if not loop & ending
    ]


def _counters(table: SequenceTable, followed: dict[int, set[int]]) -> list[Finding]:
    """Two sequences with SeqCount in one loop: the drive's one counter is taken over, the loops never end."""
    findings = []
    for loop in _components(followed):
        counting = sorted(number for number in loop if _number(table, number, "SeqCount") > 0)
        if len(counting) > 1:
            findings.append(
                Finding(
                    "counters",
                    tuple(counting),
                    f"sequences {_listed(counting)} each have a SeqCount in one loop: the drive has one counter "
                    '("only one SeqCount at a time"), so nested loops take it over and never end',
                )
            )
    return findings


def _dangling(edges: Iterable[Edge]) -> list[Finding]:
    return [
        Finding(
            "dangling",
            (edge.source,),
            f"sequence {edge.source}: {_field(edge.kind)} = {edge.target} names no defined sequence; "
            "the program ends there",
        )
        for edge in edges
        if edge.dangling and edge.kind != "link"
    ]


def _unreachable(table: SequenceTable, reachable: set[int]) -> list[Finding]:
    lost = sorted(set(table) - reachable)
    if not lost:
        return []
    return [Finding("unreachable", tuple(lost), f"sequences {_listed(lost)} are in a loop no program enters")]


def _unsupported(table: SequenceTable, types_mask: int) -> list[Finding]:
    return [
        Finding(
            "unsupported_type",
            (number,),
            f"sequence {number}: the drive does not support {sequence.type.name} sequences "
            f"(0x360F = 0x{types_mask:X}); a program ends when it reaches it",
        )
        for number, sequence in table.sequences.items()
        if not supported(sequence.type, types_mask)
    ]


def _field(kind: str) -> str:
    return "SeqNext" if kind == "next" else "SeqLink"


def _listed(numbers: Iterable[int]) -> str:
    return ", ".join(str(number) for number in sorted(numbers))
