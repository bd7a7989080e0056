"""The scope page in Debian's Chromium (headless, software WebGL): the redraw of a 4 × 8,192-sample capture, and
live roll mode's redraw rate and main-thread share; side by side in one run.

- **redraw**: a capture of four 8-bit channels × 8,192 samples (the full 32 KB recorder buffer) is drawn, then a
  cursor is moved ``--redraws`` times; each move redraws every trace (``Plotly.react``, the page's ``data-draw-ms``:
  from the call to the promise's end). Baseline, the same run: the same channels × 512 samples (plotly's own cost
  for a small figure). Goal: < 100 ms.
- **roll**: a roll of 4 channels × 1 kHz of the axis for ``--seconds``: the frames drawn per second (the live
  canvas draws at most once per animation frame, so 60 at best; counted as the changes of the plot's
  ``data-samples``), the renderer's main-thread busy share (Chrome's ``TaskDuration`` per wall second), and the
  display latency (the newest drawn sample's SYNC → its frame). Goal: 60 frames/s using < 30 % of one core.
  Baseline: the same page idle for as long.

    .venv/bin/python bench/scope_browser.py [--redraws 7] [--seconds 10] [--ui DIR]    (after `make frontend`)

``--ui DIR`` serves another build of the UI (``vite build --outDir DIR``), e.g. to measure two versions in turn.
"""

from __future__ import annotations

import argparse
import re
import shutil
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import httpx
from playwright.sync_api import CDPSession, Page, expect, sync_playwright

from scope_roll import server

EIGHT_BIT = (
    ("scope-ch1", "error register", "0x1001,0"),
    ("scope-ch2", "trigger status", "0x5829,0"),
    ("scope-ch3", "modes of operation display", "0x6061,0"),
    ("scope-ch4", "Infranor error code", "0x3023,4"),
)
ROLLED = (
    ("scope-ch1", "position actual", "0x6064,0"),
    ("scope-ch2", "velocity actual", "0x606C,0"),
    ("scope-ch3", "statusword", "0x6041,0"),
    ("scope-ch4", "current actual", "0x6078,0"),
)
COUNT_DRAWS = """() => {
    window.__draws = 0;
    if (window.__counting) return;  // one observer: a second would count every frame twice
    window.__counting = true;
    const plot = document.querySelector('[data-testid=scope-roll-plot]');
    new MutationObserver((records) => (window.__draws += records.length))
        .observe(plot, {attributes: true, attributeFilter: ['data-samples']});
}"""
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking"]


def open_bus(url: str) -> None:
    """The demo project's bus ``sim`` on the server (the UI maps the project's bus to it by name)."""
    if not any(bus["id"] == "sim" for bus in httpx.get(f"{url}/api/buses", timeout=15).json()):
        httpx.post(f"{url}/api/buses", json={"spec": "sim", "id": "sim"}, timeout=30).raise_for_status()


def open_scope(page: Page, url: str) -> None:
    page.goto(f"{url}/projects/demo/axes/Z/scope")
    expect(page.get_by_test_id("scope-stage")).to_have_text(re.compile(r"Recorder: (idle|done)"), timeout=60_000)


def pick(page: Page, slot: str, query: str, key: str) -> None:
    page.get_by_test_id(slot).fill(query)
    page.get_by_test_id(f"{slot}-results").get_by_test_id("picker-result").filter(has_text=key).first.click()


def redraws(page: Page, samples: int, count: int) -> list[float]:
    """Capture ``samples`` of the four 8-bit channels, then the redraw time of ``count`` cursor moves (ms)."""
    page.get_by_test_id("scope-samples").fill(str(samples))
    plot = page.get_by_test_id("scope-plot")
    shown = plot.get_attribute("data-drawn") or ""
    page.get_by_test_id("scope-arm").click()
    page.wait_for_function(
        "(shown) => { const drawn = document.querySelector('[data-testid=scope-plot]').dataset.drawn;"
        " return drawn !== undefined && drawn !== shown && drawn.endsWith('time 4'); }",
        arg=shown,
        timeout=120_000,
    )  # the new capture drawn
    times = []
    for n in range(count):
        before = plot.get_attribute("data-draw-ms")
        page.get_by_test_id("scope-cursor-a").fill(f"0.00{n + 1}")
        page.get_by_test_id("scope-cursor-a").press("Enter")
        expect(plot).not_to_have_attribute("data-draw-ms", before or "")
        times.append(float(plot.get_attribute("data-draw-ms") or "nan"))
        time.sleep(0.2)
    return times


def task_seconds(cdp: CDPSession) -> float:
    """The renderer main thread's busy time so far (Chrome's ``TaskDuration``)."""
    return next(m["value"] for m in cdp.send("Performance.getMetrics")["metrics"] if m["name"] == "TaskDuration")


@dataclass
class Share:
    """What a stretch of ``seconds`` cost: the main thread's busy share, the CPU shares of the renderer and the GPU
    processes (all their threads: raster, compositor), the frames drawn per second and the latencies seen (ms)."""

    main: float
    renderer: float
    gpu: float
    frames: float
    latencies: list[float]


def process_seconds(browser: CDPSession) -> dict[str, float]:
    """CPU seconds so far of every renderer and of the GPU process, by kind (``SystemInfo.getProcessInfo``)."""
    spent: dict[str, float] = {}
    for process in browser.send("SystemInfo.getProcessInfo")["processInfo"]:
        spent[process["type"]] = spent.get(process["type"], 0.0) + process["cpuTime"]
    return spent


def busy_share(page: Page, browser: CDPSession, seconds: float, watch: bool) -> Share:
    """Sample the page for ``seconds``: its main thread, its processes' CPU, its frames, its display latencies."""
    cdp = page.context.new_cdp_session(page)
    cdp.send("Performance.enable")
    page.evaluate(COUNT_DRAWS)
    busy, cpu, started, latencies = task_seconds(cdp), process_seconds(browser), time.monotonic(), []
    while time.monotonic() - started < seconds:
        time.sleep(0.25)
        if watch:
            latencies.append(float(page.get_by_test_id("scope-roll-plot").get_attribute("data-latency-ms") or "nan"))
    wall, spent = time.monotonic() - started, process_seconds(browser)
    share = {kind: (spent[kind] - cpu.get(kind, 0.0)) / wall for kind in spent}
    main, frames = (task_seconds(cdp) - busy) / wall, page.evaluate("window.__draws") / wall
    return Share(main, share.get("renderer", 0.0), share.get("GPU", 0.0), frames, latencies)


def measure(page: Page, browser: CDPSession, args: argparse.Namespace) -> None:
    for slot, query, key in EIGHT_BIT:
        pick(page, slot, query, key)
    small, full = redraws(page, 512, args.redraws), redraws(page, 8192, args.redraws)
    idle = busy_share(page, browser, args.seconds, False)
    for slot, query, key in ROLLED:
        pick(page, slot, query, key)
    page.get_by_test_id("scope-roll-start").click()
    status = page.get_by_test_id("scope-roll-status")
    expect(status).to_contain_text(re.compile(r"rolling: [1-9]\d{3,} samples"), timeout=30_000)
    roll = busy_share(page, browser, args.seconds, True)
    page.get_by_test_id("scope-roll-stop").click()
    expect(page.get_by_test_id("scope-roll-status")).to_contain_text("stopped")
    print("| figure | value | against |")
    print("|---|---|---|")
    print(f"| redraw 4 x 8192 samples, median (min) | {statistics.median(full):.0f} ({min(full):.0f}) ms | "
          f"4 x 512: {statistics.median(small):.0f} ms ({statistics.median(full) / statistics.median(small):.1f}x); "
          "goal < 100 ms |")  # fmt: skip
    print(f"| browser roll | {roll.frames:.1f} frames/s, main thread {roll.main * 100:.0f} % of a core | idle page "
          f"{idle.main * 100:.0f} %; goal 60 frames/s using < 30 % |")  # fmt: skip
    print(f"| browser roll: CPU, renderer + GPU process | {roll.renderer * 100:.0f} % + {roll.gpu * 100:.0f} % of a "
          f"core | idle page {idle.renderer * 100:.0f} % + {idle.gpu * 100:.0f} % |")  # fmt: skip
    print(f"| roll: display latency SYNC → drawn, median (max) | {statistics.median(roll.latencies):.0f} "
          f"({max(roll.latencies):.0f}) ms | goal < 100 ms |")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--redraws", type=int, default=7)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--ui", type=Path, metavar="DIR", help="the UI built in DIR (default: the package's build)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch, server(Path(scratch), demo=True, ui=args.ui) as (url, _):
        open_bus(url)
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=shutil.which("chromium"), args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 1366, "height": 900})
            open_scope(page, url)
            print(
                f"scope page, headless Chromium (software WebGL) — {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}"
            )
            measure(page, browser.new_browser_cdp_session(), args)
            browser.close()


if __name__ == "__main__":
    main()
