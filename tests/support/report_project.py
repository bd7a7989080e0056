"""Support of the report's tests (service, CLI, REST, browser): a project commissioned on the simulator — seed
101's hidden plant commissioned through the procedure service (current loop, auto-phasing, auto-tuning with its
verification steps), the results saved under axis X as the service saves them, a capture naming the drive by the
scope's store, a plant frequency response of the TRUE plant by the frequency store, one parameter set in the
project — and a reader of the report's HTML."""

from __future__ import annotations

import functools
import json
import math
import shutil
from dataclasses import dataclass, replace
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

from tests.support.procedure_bench import commission, open_bench

from servostudio.od import builtin_library
from servostudio.services.audit import Actor, AuditLog, acting_as
from servostudio.services.frequency import store as frequency_store
from servostudio.services.procedures.recording import record
from servostudio.services.procedures.store import ResultStore
from servostudio.services.projects import ProjectService
from servostudio.services.scope import Capture, CaptureDefinition, CaptureStore
from servostudio.services.scope.service import identity_of

DEMO = Path(__file__).resolve().parents[2] / "projects" / "demo"
SEED = 101
#: the saved frequency response's name and its plant fit (values a test can find in the report)
BODE_NAME = "plant sweep"
PLANT_FIT = {"inertia_kgm2": 1.234e-4, "viscous_friction_nms_per_rad": 5.6e-5}


@dataclass(frozen=True)
class Commissioned:
    projects: ProjectService
    plant: Any  # the hidden plant (servostudio.sim)
    current: dict[str, Any]
    phasing: dict[str, Any]
    tuning: dict[str, Any]
    capture: Capture


def commissioned(root: Path, audit: AuditLog | None = None) -> Commissioned:
    """``root/demo``: the shipped demo project with axis X commissioned and its records saved (by alice)."""
    shutil.copytree(DEMO, root / "demo")
    projects = ProjectService(root, builtin_library(), audit=audit)
    plant, current, phasing, tuning, capture = _commissioning()
    results = ResultStore(projects.store)
    with acting_as(Actor("alice", "expert")):
        for name, result in (("current_loop", current), ("auto_phasing", phasing), ("auto_tuning", tuning)):
            results.save("demo", "X", name, result)
        CaptureStore(projects.store).save("demo", "X", capture, "identity")
        frequency_store.save(projects.store, "demo", "X", bode_of(plant), BODE_NAME)
        projects.parameters.set("demo", "X", {"0x6410,11": 250})
    return Commissioned(projects, plant, current, phasing, tuning, capture)


@functools.cache
def _commissioning() -> tuple[Any, dict[str, Any], dict[str, Any], dict[str, Any], Capture]:
    """The simulated commissioning, once per test process (the report tests only read its results)."""
    bench = open_bench("1", seed=SEED, speed=5.0)
    try:
        plant, current, phasing, tuning = commission(bench, 75)
        drive = bench.machine()
        capture = record(drive, CaptureDefinition(channels=("velocity_actual",), period_us=500.0, samples=50),
                         lambda event: None)  # fmt: skip
        return plant, current, phasing, tuning, replace(capture, drive=identity_of(bench.connection, drive))
    finally:
        bench.manager.close_all()


def bode_of(plant: Any) -> dict[str, Any]:
    """A plant frequency response in the contract's shape (docs/frequency-response.md), of the true plant."""
    points = []
    for number in range(20):
        frequency = 5.0 * 1.2**number
        response = 1 / complex(plant.viscous_friction, 2 * math.pi * frequency * plant.total_inertia)
        points.append(
            {
                "freq_hz": frequency,
                "magnitude_db": 20 * math.log10(abs(response)),
                "phase_deg": math.degrees(math.atan2(response.imag, response.real)),
                "coherence": 0.99,
            }
        )
    return {
        "kind": "frequency_response",
        "loop": "plant",
        "node": 1,
        "device": "xtrapulspac",
        "axis": "X",
        "time": "2026-12-02T05:01:02Z",
        "user": "bob",
        "excitation": {"type": "multisine", "from_hz": 5},
        "points": points,
        "markers": {"bandwidth_hz": None, "resonance_hz": 180.0},
        "plant_fit": dict(PLANT_FIT),
        "aborted": None,
    }


class Page(HTMLParser):
    """What the tests look for in the document: script tags and their sources, element ids, text."""

    def __init__(self, html: str) -> None:
        super().__init__()
        self.scripts: list[dict[str, str | None]] = []
        self.ids: set[str] = set()
        self.text: list[str] = []
        self.feed(html)
        self.close()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "script":
            self.scripts.append(dict(attrs))
        self.ids.update(value for key, value in attrs if key == "id" and value)

    def handle_data(self, data: str) -> None:
        self.text.append(data)


def plotted(html: str, div_id: str) -> list[dict]:
    """The traces plotly draws in ``div_id``, read back from the page's own script."""
    start = html.index(f'Plotly.newPlot(                        "{div_id}",')
    data = html.index("[", start)
    return json.JSONDecoder().raw_decode(html, data)[0]
