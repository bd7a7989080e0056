/**
 * How long a what-if update takes (issue #16: < 50 ms per slider change), as a benchmark instead of a timing
 * assertion in a test: one update is the closed and open loop of the model on a 400-point measured plant, the
 * bandwidth and margins marked, and the 0.1-s step simulated period by period; the same-run baseline is the model's
 * loop elements alone at those 400 points (what any prediction must at least compute). `bench/whatif_update.py` runs
 * it and reports the update in ms, against the 50-ms budget and as a ratio to the baseline.
 */

import { bench, describe } from "vitest";
import { complex, div, type Complex } from "../lib/whatif/complex";
import { elements, loopResponses, type LoopParams, type Response } from "../lib/whatif/loop";
import { bandwidth, margins } from "../lib/whatif/markers";
import { stepResponse, type PlantFit } from "../lib/whatif/step";

const FIT: PlantFit = { inertia_kgm2: 2.4e-4, viscous_friction_nms_per_rad: 1.2e-3 };
const KT = 0.6;
const POINTS = 400;

/** A rigid plant 1/(J·s + B) on 400 log-spaced points from 1 Hz to 2 kHz, as a measurement would give it. */
function rigidPlant(): Response {
  const freq = Array.from({ length: POINTS }, (_, n) => 2000 ** (n / (POINTS - 1)));
  const value = freq.map((f): Complex => div(complex(1, 0), complex(FIT.viscous_friction_nms_per_rad, 2 * Math.PI * f * FIT.inertia_kgm2)));
  return { freq, value };
}

/** The gains a slider position gives: KPv for a crossover of `hz`, KIv = KPv·ωc/4 (docs/control-loops.md §4). */
function gains(hz: number): LoopParams {
  const wc = 2 * Math.PI * hz;
  const kp = (FIT.inertia_kgm2 * wc) / KT;
  return { kp, ki: (kp * wc) / 4, kiLeakHz: 0, kc: 0, kd: 0, kdFilterHz: 0, currentFiltersHz: [], speedFilterS: 0.5e-3, periodS: 250e-6, kt: KT };
}

const plant = rigidPlant();
let slider = 0;

describe("what-if update", () => {
  bench("update: loops, markers and the 0.1-s step", () => {
    const params = gains(30 + (slider++ % 50));
    const loops = loopResponses(plant, params);
    bandwidth(loops.closedLoop);
    margins(loops.openLoop);
    stepResponse(params, FIT, 0.1);
  });

  bench("baseline: the loop's elements at the 400 points", () => {
    const params = gains(30 + (slider++ % 50));
    for (const f of plant.freq) elements(params, f);
  });
});
