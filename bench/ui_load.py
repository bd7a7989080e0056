"""Browser UI load times on localhost, measured with Playwright driving Debian's Chromium.

1. Main page: time from navigation start until the page is interactive (project tree and server state shown),
   and the browser's own DOMContentLoaded time.
2. A 1,000-object dictionary (generated, imported through the real REST API into a throw-away user EDS directory):
   time until the parameter editor shows its rows, and time from a keystroke in the search field until the filtered
   rows are shown (this includes the editor's 60 ms typing debounce).

Each figure is the median of several runs. Run: `.venv/bin/python bench/ui_load.py` (after `make frontend`).

`--baseline REF` (default `HEAD`, `none` to skip) also builds the UI of git revision REF into a temporary directory
and measures it side by side with the working tree's build, the runs interleaved (REF, ours, REF, ours, …) so that
both see the same machine load: the figures that matter are the ratios ours / REF.
"""

from __future__ import annotations

import argparse
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


def start_server(scratch: Path, ui_dir: Path) -> tuple[subprocess.Popen, str]:
    """`servostudio serve` of the working tree, serving the UI built in `ui_dir`, with the demo project."""
    projects = scratch / "projects"
    shutil.copytree(REPO / "projects" / "demo", projects / "demo")
    port = free_port()
    env = {**os.environ, "SERVOSTUDIO_USER_EDS_DIR": str(scratch / "user-eds"), "PYTHONUNBUFFERED": "1"}
    command = [sys.executable, "-m", "servostudio", "serve", "--port", str(port), "--projects", str(projects)]
    process = subprocess.Popen(
        [*command, "--ui", str(ui_dir)], cwd=REPO, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
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


def build_revision(revision: str, scratch: Path) -> Path:
    """The browser UI of git revision `revision`, built by its own package-lock into `scratch/ui`."""
    tree = scratch / "tree"
    subprocess.run(
        ["git", "worktree", "add", "--detach", str(tree), revision], cwd=REPO, check=True, stdout=subprocess.DEVNULL
    )
    try:
        frontend = tree / "frontend"
        subprocess.run(["npm", "ci", "--no-audit", "--no-fund", "--silent"], cwd=frontend, check=True)
        out = scratch / "ui"
        subprocess.run(
            ["npx", "vite", "build", "--outDir", str(out), "--emptyOutDir"],
            cwd=frontend,
            check=True,
            stdout=subprocess.DEVNULL,
        )
        return out
    finally:
        subprocess.run(["git", "worktree", "remove", "--force", str(tree)], cwd=REPO, check=False)


def import_dictionary(url: str, scratch: Path) -> tuple[str, int, int]:
    """Import the generated dictionary through the REST API; its device key, object and entry counts."""
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
    return device, len(dictionary["objects"]), sum(len(item["subs"]) for item in dictionary["objects"])


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default="HEAD", help="git revision to compare with, or 'none' (default HEAD)")
    return parser.parse_args()


def main() -> None:
    args = parse_args()
    ours = REPO / "backend" / "servostudio" / "static"
    if not (ours / "index.html").is_file():
        raise SystemExit("the UI is not built: run `make frontend` first")
    chromium = shutil.which("chromium")
    if chromium is None:
        raise SystemExit("Debian's chromium is needed: apt-get install chromium")
    with tempfile.TemporaryDirectory() as folder:
        scratch = Path(folder)
        builds = {"working tree": ours}
        if args.baseline != "none":
            (scratch / "baseline").mkdir()
            builds = {args.baseline: build_revision(args.baseline, scratch / "baseline"), **builds}
        results, counts = run_side_by_side(chromium, builds, scratch)
    report(results, counts)


def run_side_by_side(
    chromium: str, builds: dict[str, Path], scratch: Path
) -> tuple[dict[str, dict[str, float | str]], tuple[int, int]]:
    servers: dict[str, tuple[subprocess.Popen, str, str]] = {}
    counts = (0, 0)
    try:
        for number, (label, ui_dir) in enumerate(builds.items()):
            (scratch / str(number)).mkdir()
            process, url = start_server(scratch / str(number), ui_dir)
            servers[label] = (process, url, "")
            device, objects, entries = import_dictionary(url, scratch / str(number))
            servers[label] = (process, url, device)
            counts = (objects, entries)
        targets = {label: (url, device) for label, (_, url, device) in servers.items()}
        return measure(chromium, targets), counts
    finally:
        for process, _, _ in servers.values():
            process.terminate()
            process.wait(timeout=10)


ROWS = [
    ("main", "main page interactive (tree and server state shown)"),
    ("dcl", "main page DOMContentLoaded"),
    ("render", "{objects}-object dictionary ({entries} entries) shown in the editor"),
    ("fetch", "  of which fetching the dictionary"),
    ("filter", "filter {entries} entries on a keystroke (incl. 60 ms debounce)"),
]


def report(results: dict[str, dict[str, float | str]], counts: tuple[int, int]) -> None:
    labels = list(results)
    print(
        f"medians in ms of {RUNS} interleaved runs; columns: {', '.join(labels)}"
        + (", ratio" if len(labels) == 2 else "")
    )
    for key, title in ROWS:
        values = [float(results[label][key]) for label in labels]
        ratio = f"  {values[1] / values[0]:.2f}x" if len(values) == 2 and values[0] else ""
        cells = "  ".join(f"{value:7.0f}" for value in values)
        print(f"{title.format(objects=counts[0], entries=counts[1]):70s} {cells}{ratio}")
    print(f'last filter result: "{results[labels[-1]]["label"]}"')


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


def measure(chromium: str, targets: dict[str, tuple[str, str]]) -> dict[str, dict[str, float | str]]:
    """Every figure for every target, runs interleaved; the median of each."""
    samples: dict[str, dict[str, list[float]]] = {label: {key: [] for key, _ in ROWS} for label in targets}
    labels: dict[str, str] = {}
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=chromium, headless=True, args=CHROMIUM_ARGS)
        for _ in range(RUNS):
            for label, (url, device) in targets.items():
                labels[label] = one_run(browser, url, device, samples[label])
        browser.close()
    return {
        label: {**{key: statistics.median(values) for key, values in figures.items()}, "label": labels[label]}
        for label, figures in samples.items()
    }


def one_run(browser, url: str, device: str, samples: dict[str, list[float]]) -> str:
    context = browser.new_context(viewport={"width": 1366, "height": 768}, locale="de-DE")
    page = context.new_page()
    start = time.perf_counter()
    page.goto(url + "/")
    page.wait_for_selector("[data-testid=tree-project-demo]")
    page.wait_for_selector("[data-testid=server-status][data-state=online]")
    samples["main"].append((time.perf_counter() - start) * 1000)
    samples["dcl"].append(page.evaluate("performance.getEntriesByType('navigation')[0].domContentLoadedEventEnd"))
    start = time.perf_counter()
    page.goto(f"{url}/dictionaries/{device}")
    page.wait_for_selector(".prow.entry")
    samples["render"].append((time.perf_counter() - start) * 1000)
    samples["fetch"].append(
        page.evaluate(f"performance.getEntriesByName(location.origin + '/api/dictionaries/{device}')[0].duration")
    )
    label = ""
    for text in ("gain 3", "filter 5", "0x2100", "Parameter 999"):
        elapsed, label = page.evaluate(FILTER_SCRIPT, text)
        samples["filter"].append(elapsed)
    context.close()
    return label


if __name__ == "__main__":
    main()
