"""Browser UI load times on localhost, measured with Playwright driving Debian's Chromium.

1. Main page: time from navigation start until the page is interactive (project tree and server state shown),
   and the browser's own DOMContentLoaded time.
2. A 1,000-object dictionary (generated, imported through the real REST API into a throw-away user EDS directory):
   time until the parameter editor shows its rows, and time from a keystroke in the search field until the filtered
   rows are shown (this includes the editor's 60 ms typing debounce).

Each figure is the median of several runs. Run: `.venv/bin/python bench/ui_load.py` (after `make frontend`).
"""

from __future__ import annotations

import os
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import httpx
from playwright.sync_api import sync_playwright

REPO = Path(__file__).resolve().parent.parent
OBJECTS = 1000
RUNS = 5
GROUPS = [
    "General",
    "Motor",
    "Sensors",
    "Servo Loops",
    "Position Control",
    "Inputs/Outputs",
    "Homing Mode",
    "Profile Position Mode",
    "Error Control",
    "Factor",
]
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def synthetic_eds(directory: Path) -> tuple[Path, Path]:
    """A valid CiA 306 EDS with OBJECTS manufacturer objects (0x2000…) and its companion .props."""
    indices = [0x2000 + i for i in range(OBJECTS)]
    eds = [
        "[FileInfo]",
        "FileName=bench1000.eds",
        "FileVersion=1",
        "FileRevision=0",
        "EDSVersion=4.0",
        "Description=Synthetic 1000-object dictionary for the UI benchmark",
        "CreatedBy=Servo Studio bench",
        "",
        "[DeviceInfo]",
        "VendorName=Bench",
        "VendorNumber=0x00BE0C00",
        "ProductName=Bench 1000",
        "ProductNumber=0x00001000",
        "RevisionNumber=0x00000001",
        "BaudRate_1000=1",
        "SimpleBootUpSlave=1",
        "Granularity=8",
        "NrOfRxPDO=0",
        "NrOfTxPDO=0",
        "LSS_Supported=0",
        "",
        "[MandatoryObjects]",
        "SupportedObjects=3",
        "1=0x1000",
        "2=0x1001",
        "3=0x1018",
        "",
        "[1000]",
        "ParameterName=Device type",
        "ObjectType=0x7",
        "DataType=0x0007",
        "AccessType=ro",
        "DefaultValue=0x00020192",
        "PDOMapping=0",
        "",
        "[1001]",
        "ParameterName=Error register",
        "ObjectType=0x7",
        "DataType=0x0005",
        "AccessType=ro",
        "DefaultValue=0",
        "PDOMapping=1",
        "",
        "[1018]",
        "ParameterName=Identity object",
        "ObjectType=0x9",
        "SubNumber=3",
        "",
        "[1018sub0]",
        "ParameterName=Number of entries",
        "ObjectType=0x7",
        "DataType=0x0005",
        "AccessType=ro",
        "DefaultValue=2",
        "PDOMapping=0",
        "",
        "[1018sub1]",
        "ParameterName=Vendor-ID",
        "ObjectType=0x7",
        "DataType=0x0007",
        "AccessType=ro",
        "DefaultValue=0x00BE0C00",
        "PDOMapping=0",
        "",
        "[1018sub2]",
        "ParameterName=Product code",
        "ObjectType=0x7",
        "DataType=0x0007",
        "AccessType=ro",
        "DefaultValue=0x00001000",
        "PDOMapping=0",
        "",
        "[OptionalObjects]",
        "SupportedObjects=0",
        "",
        "[ManufacturerObjects]",
        f"SupportedObjects={OBJECTS}",
        *[f"{n}=0x{index:04X}" for n, index in enumerate(indices, start=1)],
        "",
    ]
    props = ["; properties of the synthetic benchmark dictionary", ""]
    for n, index in enumerate(indices):
        eds += [
            f"[{index:04X}]",
            f"ParameterName=Parameter {n} gain {n % 13}",
            "ObjectType=0x7",
            f"DataType={'0x0006' if n % 2 else '0x0004'}",
            "AccessType=rw",
            f"DefaultValue={n % 100}",
            "PDOMapping=0",
            "LowLimit=0",
            "HighLimit=30000",
            "",
        ]
        props += [
            f"[{index:04X}]",
            f"Group={GROUPS[n % len(GROUPS)]}",
            f"Description=Synthetic parameter {n}: loop gain {n % 13}, filter {n % 7}",
            f"Unit={'rpm' if n % 3 == 0 else 'A'}",
            "",
        ]
    eds_path, props_path = directory / "bench1000.eds", directory / "bench1000.props"
    eds_path.write_text("\n".join(eds), encoding="latin-1")
    props_path.write_text("\n".join(props), encoding="latin-1")
    return eds_path, props_path


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def start_server(scratch: Path) -> tuple[subprocess.Popen, str]:
    projects = scratch / "projects"
    shutil.copytree(REPO / "projects" / "demo", projects / "demo")
    port = free_port()
    env = {**os.environ, "SERVOSTUDIO_USER_EDS_DIR": str(scratch / "user-eds"), "PYTHONUNBUFFERED": "1"}
    process = subprocess.Popen(
        [sys.executable, "-m", "servostudio", "serve", "--port", str(port), "--projects", str(projects)],
        cwd=REPO,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            if httpx.get(url + "/api/health", timeout=1).status_code == 200:
                return process, url
        except httpx.HTTPError:
            time.sleep(0.2)
    process.kill()
    raise SystemExit("server did not start within 60 s")


FILTER_SCRIPT = """async (text) => {
  const input = document.querySelector('[data-testid=param-search]');
  const label = document.querySelector('[data-testid=param-count]');
  const start = performance.now();
  // The editor rewrites the count label once it has filtered and laid out the rows: wait for that, then a frame.
  const done = new Promise((resolve) => {
    const observer = new MutationObserver(() => {
      observer.disconnect();
      requestAnimationFrame(() => resolve());
    });
    observer.observe(label, { childList: true, characterData: true, subtree: true });
  });
  input.value = text;
  input.dispatchEvent(new Event('input'));
  await done;
  return [performance.now() - start, label.textContent];
}"""


def main() -> None:
    if not (REPO / "backend" / "servostudio" / "static" / "index.html").is_file():
        raise SystemExit("the UI is not built: run `make frontend` first")
    chromium = shutil.which("chromium")
    if chromium is None:
        raise SystemExit("Debian's chromium is needed: apt-get install chromium")
    with tempfile.TemporaryDirectory() as folder:
        scratch = Path(folder)
        process, url = start_server(scratch)
        try:
            eds, props = synthetic_eds(scratch)
            with eds.open("rb") as eds_file, props.open("rb") as props_file:
                answer = httpx.post(
                    url + "/api/dictionaries",
                    timeout=120,
                    files={"eds": (eds.name, eds_file), "props": (props.name, props_file)},
                )
            answer.raise_for_status()
            device = answer.json()["device"]
            dictionary = httpx.get(f"{url}/api/dictionaries/{device}", timeout=60).json()
            entries = sum(len(item["subs"]) for item in dictionary["objects"])
            results = measure(chromium, url, device)
        finally:
            process.terminate()
            process.wait(timeout=10)
    print(f"main page interactive (tree and server state shown): median {results['main']:.0f} ms")
    print(f"main page DOMContentLoaded: median {results['dcl']:.0f} ms")
    print(
        f"{len(dictionary['objects'])}-object dictionary ({entries} entries) shown in the editor: median {results['render']:.0f} ms "
        f"(of which fetching the dictionary: {results['fetch']:.0f} ms)"
    )
    print(
        f"filter {entries} entries on a keystroke (incl. 60 ms debounce): median {results['filter']:.0f} ms "
        f'("{results["label"]}")'
    )


def measure(chromium: str, url: str, device: str) -> dict[str, float | str]:
    main_times, dcl_times, render_times, fetch_times, filter_times = [], [], [], [], []
    label = ""
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=chromium, headless=True, args=CHROMIUM_ARGS)
        for _ in range(RUNS):
            context = browser.new_context(viewport={"width": 1366, "height": 768}, locale="de-DE")
            page = context.new_page()
            start = time.perf_counter()
            page.goto(url + "/")
            page.wait_for_selector("[data-testid=tree-project-demo]")
            page.wait_for_selector("[data-testid=server-status][data-state=online]")
            main_times.append((time.perf_counter() - start) * 1000)
            dcl_times.append(page.evaluate("performance.getEntriesByType('navigation')[0].domContentLoadedEventEnd"))

            start = time.perf_counter()
            page.goto(f"{url}/dictionaries/{device}")
            page.wait_for_selector(".prow.entry")
            render_times.append((time.perf_counter() - start) * 1000)
            fetch_times.append(
                page.evaluate(
                    f"performance.getEntriesByName(location.origin + '/api/dictionaries/{device}')[0].duration"
                )
            )
            for text in ("gain 3", "filter 5", "0x2100", "Parameter 999"):
                elapsed, label = page.evaluate(FILTER_SCRIPT, text)
                filter_times.append(elapsed)
            context.close()
        browser.close()
    return {
        "main": statistics.median(main_times),
        "dcl": statistics.median(dcl_times),
        "render": statistics.median(render_times),
        "fetch": statistics.median(fetch_times),
        "filter": statistics.median(filter_times),
        "label": label,
    }


if __name__ == "__main__":
    main()
