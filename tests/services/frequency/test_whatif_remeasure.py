"""The what-if prediction against the re-measurement, on simulated XtrapulsPacs commissioned for HIDDEN seeded
plants (issue #16: "the what-if prediction of the closed-loop bandwidth after a gain change agrees with the
re-measurement within 10 %"): the plant is measured, the gains are changed in the model the Bode page runs
(frontend/src/lib/bode.ts and lib/whatif/, compiled by tsc and run by node: the browser's code, not a Python copy),
the same gains are written to the drive, the closed loop is measured again, and the two bandwidths are compared."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from servostudio.services.audit import acting_as
from servostudio.services.frequency.speed_loop import read_speed_loop, write_speed_loop
from servostudio.sim.plant import Plant

FRONTEND = Path(__file__).parents[3] / "frontend"
MEASURE = {"amplitude_pct": 100, "base_speed_rad_s": 15, "periods": 6, "position_window": 40}
PREDICT = """
const bode = require(process.argv[1]);
const input = JSON.parse(require("fs").readFileSync(0, "utf8"));
const plant = bode.barePlant(input.plant, input.loop.control_period_s);
const predicted = bode.predict(plant, null, bode.paramsWith(input.loop, input.draft));
process.stdout.write(JSON.stringify(predicted.markers));
"""


@pytest.fixture(scope="module")
def predictor(tmp_path_factory):
    """The Bode page's model as node runs it: ``predict(plant result, speed loop, draft) → markers``."""
    node, tsc = shutil.which("node"), FRONTEND / "node_modules" / ".bin" / "tsc"
    if node is None or not tsc.exists():
        pytest.fail("node and the frontend's node_modules are needed (make test installs them)")
    out = tmp_path_factory.mktemp("whatif-js")
    options = ["--outDir", str(out), "--module", "commonjs", "--target", "es2022", "--skipLibCheck", "--strict"]
    subprocess.run([str(tsc), *options, str(FRONTEND / "src" / "lib" / "bode.ts")], check=True, cwd=FRONTEND)

    def predict(plant: dict, loop: dict, draft: dict) -> dict:
        given = json.dumps({"plant": plant, "loop": loop, "draft": draft})
        answer = subprocess.run([node, "-e", PREDICT, str(out / "bode.js")], input=given, capture_output=True,
                                text=True, check=True)  # fmt: skip
        return json.loads(answer.stdout)

    return predict


#: gain changes whose bandwidth stays where the plant measurement is accurate (≤ 1 dB, 10° up to 200 Hz)
@pytest.mark.parametrize(("seed", "factor"), [(3, 0.6), (21, 1.25)])
def test_the_predicted_bandwidth_after_a_gain_change_is_the_re_measured_one(frequency_bench, predictor, seed, factor):
    plant = Plant.from_seed(seed)
    bench = frequency_bench(plant)
    measured = bench.measure(loop="plant", **MEASURE)
    assert measured["aborted"] is None
    loop = read_speed_loop(bench.drive())
    change = {"kp_a_per_rad_s": loop["kp_a_per_rad_s"] * factor, "ki_a_per_rad": loop["ki_a_per_rad"] * factor}
    draft = {"kp": change["kp_a_per_rad_s"], "ki": change["ki_a_per_rad"], "filtersHz": loop["current_filters_hz"],
             "speedFilterS": loop["speed_filter_s"]}  # fmt: skip
    before = predictor(measured, loop, {**draft, "kp": loop["kp_a_per_rad_s"], "ki": loop["ki_a_per_rad"]})
    predicted = predictor(measured, loop, draft)
    assert predicted["bandwidth_hz"] != pytest.approx(before["bandwidth_hz"], rel=0.15)  # a change that shows
    with acting_as(bench.controller()):
        write_speed_loop(bench.drive(), change)
    closed = bench.measure(loop="closed", **{**MEASURE, "amplitude_pct": 40})
    assert closed["aborted"] is None
    print(f"seed {seed}: KPv, KIv × {factor}: predicted {predicted['bandwidth_hz']:.1f} Hz (before "
          f"{before['bandwidth_hz']:.1f} Hz), re-measured {closed['markers']['bandwidth_hz']:.1f} Hz")  # fmt: skip
    assert closed["markers"]["bandwidth_hz"] == pytest.approx(predicted["bandwidth_hz"], rel=0.10)
