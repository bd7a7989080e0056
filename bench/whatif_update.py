"""How long a what-if update takes in the browser's code (issue #16: under 50 ms per slider change).

Runs the vitest benchmark `frontend/src/bench/whatif.bench.ts` (Node, the page's own TypeScript): one update — the
model's closed and open loop on a 400-point measured plant, bandwidth and margins, the 0.1-s step period by
period — against the same run's baseline, the loop's elements alone at those points. Reports the update's median and
p99 in ms, its p99 as a share of the 50-ms budget, and update / baseline (the cost of the whole update in units of
the least any prediction computes). Run: `.venv/bin/python bench/whatif_update.py` (after `make frontend`).
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

FRONTEND = Path(__file__).resolve().parent.parent / "frontend"
BUDGET_MS = 50.0


def run_benchmark() -> dict[str, dict]:
    """The benchmark's results by name (vitest's JSON report)."""
    with tempfile.TemporaryDirectory() as scratch:
        report = Path(scratch) / "whatif.json"
        command = ["npx", "vitest", "bench", "--run", "src/bench/whatif.bench.ts", "--outputJson", str(report)]
        subprocess.run(command, cwd=FRONTEND, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        files = json.loads(report.read_text())["files"]
    return {
        bench["name"].split(":")[0]: bench
        for file in files
        for group in file["groups"]
        for bench in group["benchmarks"]
    }


def main() -> int:
    results = run_benchmark()
    update, baseline = results["update"], results["baseline"]
    print("| what-if | median ms | p99 ms | samples |")
    print("|---|---|---|---|")
    for name in ("update", "baseline"):
        bench = results[name]
        print(f"| {bench['name']} | {bench['median']:.3f} | {bench['p99']:.3f} | {bench['sampleCount']} |")
    print(f"\nupdate / baseline (medians): {update['median'] / baseline['median']:.2f}")
    print(f"update p99 / the {BUDGET_MS:.0f}-ms budget: {update['p99'] / BUDGET_MS:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
