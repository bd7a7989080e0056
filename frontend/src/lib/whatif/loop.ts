/**
 * The drive's speed loop as a discrete-time model (docs/what-if.md, docs/control-loops.md §1–2), evaluated at
 * z = e^{jωT} on a measured plant frequency response. Every element runs once per control period T exactly as the
 * drive computes it:
 *
 *   S(z) = α_s / (1 − (1 − α_s) z⁻¹)                 speed-measurement filter, α_s = 1 − e^{−T/τ}
 *   I(z) = T z⁻¹ / (1 − (1 − 2π·KIvf·T) z⁻¹)          forward-Euler integral with leak (used before it is updated)
 *   D(z) = (1 − z⁻¹)/T · α_d / (1 − (1 − α_d) z⁻¹)    derivative of the filtered speed, low-pass KDvf
 *   F(z) = Π α_i / (1 − (1 − α_i) z⁻¹)                current-command filters, α_i = 1 − e^{−2π f_i T}
 *   A = KPv + KIv·I      B = KCv + KDv·D               i_ref = A·(ω_ref − S·ω) − B·S·ω
 *
 * With the plant P (rad/s per N·m, from the current command to the shaft speed) and the torque constant Kt:
 * open loop L = P·Kt·F·(A + B)·S, closed loop ω/ω_ref = P·Kt·F·A / (1 + L).
 */

import { add, complex, div, fromBode, mul, scale, unit, type Complex } from "./complex";

/** The speed loop in physical units (the server's `GET …/speed-loop` answer, docs/what-if.md). */
export interface LoopParams {
  kp: number; // A/(rad/s)
  ki: number; // A/rad
  kiLeakHz: number;
  kc: number; // A/(rad/s)
  kd: number; // A/(rad/s²)
  kdFilterHz: number; // 0 = no filter
  currentFiltersHz: number[]; // 0 = off
  speedFilterS: number;
  periodS: number;
  /** N·m/A; 1 when the drive has none (the plant is then per ampere). */
  kt: number;
}

/** What `GET …/speed-loop` answers (the fields the model reads). */
export interface SpeedLoopReading {
  kp_a_per_rad_s: number;
  ki_a_per_rad: number;
  ki_leak_hz: number;
  kc_a_per_rad_s: number;
  kd_a_per_rad_s2: number;
  kd_filter_hz?: number;
  current_filters_hz: number[];
  speed_filter_s: number;
  control_period_s: number;
  torque_constant_nm_per_a: number | null;
}

export function paramsOf(loop: SpeedLoopReading): LoopParams {
  return {
    kp: loop.kp_a_per_rad_s, ki: loop.ki_a_per_rad, kiLeakHz: loop.ki_leak_hz, kc: loop.kc_a_per_rad_s,
    kd: loop.kd_a_per_rad_s2, kdFilterHz: loop.kd_filter_hz ?? 0, currentFiltersHz: [...loop.current_filters_hz],
    speedFilterS: loop.speed_filter_s, periodS: loop.control_period_s, kt: loop.torque_constant_nm_per_a ?? 1,
  };
}

export interface BodePoint {
  freq_hz: number;
  magnitude_db: number;
  phase_deg: number;
  /** γ² of a measured point; null when it was not estimated */
  coherence?: number | null;
}

/** A frequency response: frequencies and complex values; a measured one (and what the model computes on it) carries
 * each point's coherence, which the markers weigh (markers.ts). */
export interface Response {
  freq: number[];
  value: Complex[];
  coherence?: (number | null)[];
}

export function responseOf(points: BodePoint[]): Response {
  const freq = points.map((p) => p.freq_hz), value = points.map((p) => fromBode(p.magnitude_db, p.phase_deg));
  return points.some((p) => p.coherence !== undefined) ? { freq, value, coherence: points.map((p) => p.coherence ?? null) } : { freq, value };
}

const ONE = complex(1);

/** A first-order discrete low-pass y += α(x − y) at z⁻¹ = `zi`. */
function lowPass(alpha: number, zi: Complex): Complex {
  return div(complex(alpha), add(ONE, scale(zi, -(1 - alpha))));
}

const cornerAlpha = (hz: number, period: number) => 1 - Math.exp(-2 * Math.PI * hz * period);

/** The loop's elements at one frequency. */
export interface Elements {
  /** Kt·F: current command to torque per ampere of demand. */
  actuator: Complex;
  a: Complex;
  b: Complex;
  speedFilter: Complex;
}

export function elements(params: LoopParams, freqHz: number): Elements {
  const period = params.periodS;
  const zi = unit(-2 * Math.PI * freqHz * period);
  const speedFilter = params.speedFilterS > 0 ? lowPass(1 - Math.exp(-period / params.speedFilterS), zi) : ONE;
  const leak = 1 - 2 * Math.PI * params.kiLeakHz * period;
  const integral = div(scale(zi, period), add(ONE, scale(zi, -leak)));
  const difference = scale(add(ONE, scale(zi, -1)), 1 / period);
  const derivative = params.kdFilterHz > 0 ? mul(difference, lowPass(cornerAlpha(params.kdFilterHz, period), zi)) : difference;
  let actuator = complex(params.kt);
  for (const hz of params.currentFiltersHz) if (hz > 0) actuator = mul(actuator, lowPass(cornerAlpha(hz, period), zi));
  return {
    actuator,
    a: add(complex(params.kp), scale(integral, params.ki)),
    b: add(complex(params.kc), scale(derivative, params.kd)),
    speedFilter,
  };
}

export interface LoopResponses {
  openLoop: Response;
  closedLoop: Response;
}

/** Open and closed loop of the model on a plant response (the same frequencies). */
export function loopResponses(plant: Response, params: LoopParams): LoopResponses {
  const open: Complex[] = [];
  const closed: Complex[] = [];
  for (let n = 0; n < plant.freq.length; n++) {
    const e = elements(params, plant.freq[n]);
    const forward = mul(plant.value[n], e.actuator);
    const loop = mul(mul(forward, add(e.a, e.b)), e.speedFilter);
    open.push(loop);
    closed.push(div(mul(forward, e.a), add(ONE, loop)));
  }
  const { freq, coherence } = plant;
  return { openLoop: { freq, value: open, coherence }, closedLoop: { freq, value: closed, coherence } };
}

/** The filters of a loop that the plant measurement included (they are divided out, then the new ones applied). */
export function withoutFilters(plant: Response, filtersHz: number[], periodS: number): Response {
  const params: LoopParams = {
    kp: 0, ki: 0, kiLeakHz: 0, kc: 0, kd: 0, kdFilterHz: 0, currentFiltersHz: filtersHz, speedFilterS: 0, periodS, kt: 1,
  };
  return { ...plant, value: plant.value.map((value, n) => div(value, elements(params, plant.freq[n]).actuator)) };
}
