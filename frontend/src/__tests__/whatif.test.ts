import { describe, expect, it } from "vitest";
import { complex, db, div, mul, scale, unit, unwrapDeg, type Complex } from "../lib/whatif/complex";
import { loopResponses, paramsOf, withoutFilters, type LoopParams, type Response } from "../lib/whatif/loop";
import { bandwidth, margins, resonances } from "../lib/whatif/markers";
import { stepBandwidth, stepResponse, type PlantFit } from "../lib/whatif/step";

const T = 250e-6;
const FIT: PlantFit = { inertia_kgm2: 2.4e-4, viscous_friction_nms_per_rad: 1.2e-3 };
const KT = 0.6;

/** Exact zero-order-hold response of J·dω/dt = T − Bω from the held torque to the per-period position difference
 * (what the drive measures as speed), independent of the model under test. */
function rigidPlant(fit: PlantFit, freq: number[]): Response {
  const beta = fit.viscous_friction_nms_per_rad / fit.inertia_kgm2;
  const a = Math.exp(-beta * T);
  const b = fit.viscous_friction_nms_per_rad;
  const c = (1 - a) / beta, d = (T - (1 - a) / beta) / b;
  const value = freq.map((f): Complex => {
    const zi = unit(-2 * Math.PI * f * T);
    const omega = div(scale(zi, (1 - a) / b), complex(1 - a * zi.re, -a * zi.im));
    const turned = mul(zi, { re: c * omega.re + d, im: c * omega.im });
    return scale(turned, 1 / T);
  });
  return { freq, value };
}

const logspace = (from: number, to: number, count: number) =>
  Array.from({ length: count }, (_, n) => from * (to / from) ** (n / (count - 1)));

/** Gains for a crossover ωc (docs/control-loops.md §4: KPv = J·ωc/Kt, KIv = KPv·ωc/4). */
function tuned(crossoverHz: number, extra: Partial<LoopParams> = {}): LoopParams {
  const wc = 2 * Math.PI * crossoverHz;
  const kp = (FIT.inertia_kgm2 * wc) / KT;
  return { kp, ki: (kp * wc) / 4, kiLeakHz: 0, kc: 0, kd: 0, kdFilterHz: 0, currentFiltersHz: [], speedFilterS: 0.5e-3, periodS: T, kt: KT, ...extra };
}

describe("the speed-loop model", () => {
  it("predicts the same bandwidth in the frequency domain as its period-by-period step simulation", () => {
    const plant = rigidPlant(FIT, logspace(2, 1500, 400));
    const cases: [number, Partial<LoopParams>][] = [[30, {}], [50, { currentFiltersHz: [600, 0, 0] }], [80, { speedFilterS: 1e-3, kiLeakHz: 2 }]];
    for (const [crossover, extra] of cases) {
      const params = tuned(crossover, extra);
      const fromBode = bandwidth(loopResponses(plant, params).closedLoop)!;
      const fromStep = stepBandwidth(stepResponse(params, FIT, 0.25), T)!;
      expect(fromBode).toBeGreaterThan(crossover);
      expect(fromStep / fromBode).toBeCloseTo(1, 2);
    }
  });

  it("a higher KPv widens the predicted bandwidth and a step settles at the reference", () => {
    const plant = rigidPlant(FIT, logspace(2, 1000, 120));
    const slow = bandwidth(loopResponses(plant, tuned(30)).closedLoop)!;
    const fast = bandwidth(loopResponses(plant, { ...tuned(30), kp: tuned(30).kp * 2 }).closedLoop)!;
    expect(fast).toBeGreaterThan(slow * 1.5);
    const step = stepResponse(tuned(30), FIT, 0.3);
    expect(step.speed[step.speed.length - 1]).toBeCloseTo(1, 3);
  });

  it("dividing the measured filters out and applying them again gives the plant back", () => {
    const plant = rigidPlant(FIT, logspace(5, 400, 30));
    const bare = withoutFilters(plant, [300, 500], T);
    const again = withoutFilters(bare, [], T);
    expect(db(bare.value[29])).toBeGreaterThan(db(plant.value[29]));
    expect(db(again.value[3])).toBeCloseTo(db(bare.value[3]), 9);
  });

  it("reads the server's speed-loop answer", () => {
    const params = paramsOf({
      kp_a_per_rad_s: 0.2, ki_a_per_rad: 30, ki_leak_hz: 0, kc_a_per_rad_s: 0, kd_a_per_rad_s2: 0,
      current_filters_hz: [0, 0, 0], speed_filter_s: 0.001, control_period_s: T, torque_constant_nm_per_a: null,
    });
    expect(params.kt).toBe(1);
    expect(params.speedFilterS).toBe(0.001);
  });
});

describe("markers", () => {
  it("margins of a known open loop ωc/s·e^{−sτ}", () => {
    const wc = 2 * Math.PI * 50, tau = 1e-3;
    const freq = logspace(5, 2000, 600);
    const value = freq.map((f) => {
      const w = 2 * Math.PI * f;
      return mul(complex(0, -wc / w), unit(-w * tau));
    });
    const found = margins({ freq, value });
    expect(found.phase_margin_deg!).toBeCloseTo(90 - (wc * tau * 180) / Math.PI, 0);
    expect(found.gain_margin_db!).toBeCloseTo(-20 * Math.log10(wc / (Math.PI / 2 / tau)), 1);
    expect(unwrapDeg(value).at(-1)!).toBeLessThan(-360);
  });

  it("resonance and anti-resonance of a two-mass plant", () => {
    const jm = 1e-4, jl = 3e-4, k = 400, c = 0.01;
    const freq = logspace(5, 400, 160);
    const value = freq.map((f) => {
      const s = complex(0, 2 * Math.PI * f);
      const load = { re: jl * s.re * s.re - jl * s.im * s.im + c * s.re + k, im: 2 * jl * s.re * s.im + c * s.im };
      const total = mul(s, { re: jm * load.re + jl * (c * s.re + k) + 0, im: jm * load.im + jl * c * s.im });
      return div(load, total);
    });
    const found = resonances({ freq, value });
    const anti = Math.sqrt(k / jl) / 2 / Math.PI;
    const resonance = Math.sqrt((k * (jm + jl)) / (jm * jl)) / 2 / Math.PI;
    expect(found.antiresonance_hz! / anti).toBeCloseTo(1, 1);
    expect(found.resonance_hz! / resonance).toBeCloseTo(1, 1);
  });
});
