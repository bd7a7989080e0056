/**
 * What the Bode page marks on a response: the closed loop's −3 dB bandwidth, the open loop's gain and phase
 * margins, the plant's resonance and anti-resonance (docs/what-if.md). Between two measured points the crossing is
 * interpolated linearly in dB (or degrees) over log-frequency. Only coherent points count, as in the backend's
 * services/frequency/markers.py (docs/frequency-response.md §6; both are run on tests/fixtures/markers.json).
 */

import { abs, db, unwrapDeg } from "./complex";
import type { Response } from "./loop";

export interface Markers {
  bandwidth_hz: number | null;
  gain_margin_db: number | null;
  phase_margin_deg: number | null;
  resonance_hz: number | null;
  antiresonance_hz: number | null;
}

/** γ² a point needs to make or move a marker: at or above the 95 % noise floor of γ² for every allowed number of
 * periods (2 … 32), and a point's random magnitude error is then ≤ 0.7 dB at 4 periods. */
export const MIN_COHERENCE = 0.95;
/** An anti-resonance's dip has a small output and, by nature, a lower γ² (markers.py MIN_DIP_COHERENCE). */
export const MIN_DIP_COHERENCE = 0.8;

const isCoherent = (coherence: number | null | undefined, threshold: number): boolean =>
  typeof coherence === "number" && Number.isFinite(coherence) && coherence >= threshold;

/** The points of a response a marker may stand on: γ² ≥ MIN_COHERENCE (a computed response, without coherence, is
 * all coherent; a coherence not estimated supports nothing). The others neither make nor move a marker. */
export function coherentPart(response: Response, threshold = MIN_COHERENCE): Response {
  const coherence = response.coherence;
  if (!coherence) return response;
  const keep = (_: unknown, n: number) => isCoherent(coherence[n], threshold);
  return { freq: response.freq.filter(keep), value: response.value.filter(keep), coherence: coherence.filter(keep) };
}

/** Log-frequency where `values` (one per frequency) first crosses `level` going down; null when it never does. */
export function crossingDown(freq: number[], values: number[], level: number): number | null {
  for (let n = 1; n < freq.length; n++) {
    if (values[n - 1] >= level && values[n] < level) {
      const share = (values[n - 1] - level) / (values[n - 1] - values[n]);
      return 10 ** (Math.log10(freq[n - 1]) + share * (Math.log10(freq[n]) - Math.log10(freq[n - 1])));
    }
  }
  return null;
}

function interpolate(freq: number[], values: number[], at: number): number {
  for (let n = 1; n < freq.length; n++) {
    if (freq[n] >= at) {
      const share = (Math.log10(at) - Math.log10(freq[n - 1])) / (Math.log10(freq[n]) - Math.log10(freq[n - 1]));
      return values[n - 1] + share * (values[n] - values[n - 1]);
    }
  }
  return values[values.length - 1];
}

/** |T| = 1/√2: the speed loop integrates, so its closed loop's static gain is 1 (a low-frequency point may sit above
 * it, where the PI zero lifts the response: it is not the reference). */
const HALF_POWER_DB = -10 * Math.log10(2);

/** −3 dB bandwidth of a closed loop: where its magnitude first falls below 1/√2. */
export function bandwidth(response: Response): number | null {
  const closed = coherentPart(response);
  return crossingDown(closed.freq, closed.value.map(db), HALF_POWER_DB);
}

/** Phase margin at the gain crossover (|L| = 1) and gain margin at the phase crossover (∠L = −180°). */
export function margins(response: Response): { gain_margin_db: number | null; phase_margin_deg: number | null } {
  const open = coherentPart(response);
  const magnitudes = open.value.map(db);
  const phases = unwrapDeg(open.value);
  const crossover = crossingDown(open.freq, magnitudes, 0);
  const phaseCrossover = crossingDown(open.freq, phases, -180);
  return {
    phase_margin_deg: crossover === null ? null : 180 + interpolate(open.freq, phases, crossover),
    gain_margin_db: phaseCrossover === null ? null : -interpolate(open.freq, magnitudes, phaseCrossover),
  };
}

/** Detrended plant magnitude: a rigid plant 1/(Js) falls 20 dB/decade, so dB + 20·log10 f is flat for it. */
const detrended = (plant: Response) => plant.value.map((value, n) => db(value) + 20 * Math.log10(plant.freq[n]));

/** The strongest local peak (sign +1) or dip (−1) standing out by `prominence` dB from both sides. */
function extremum(freq: number[], values: number[], sign: 1 | -1, prominence = 3): number | null {
  let best: number | null = null;
  let bestHeight = prominence;
  for (let n = 1; n < values.length - 1; n++) {
    const v = sign * values[n];
    if (v < sign * values[n - 1] || v < sign * values[n + 1]) continue;
    const left = Math.min(...values.slice(0, n).map((x) => sign * x));
    const right = Math.min(...values.slice(n + 1).map((x) => sign * x));
    const height = v - Math.max(left, right);
    if (height >= bestHeight) [best, bestHeight] = [freq[n], height];
  }
  return best;
}

/** The points of a response below `limit` Hz. */
function below(response: Response, limit: number): Response {
  const keep = (_: unknown, n: number) => response.freq[n] < limit;
  const coherence = response.coherence?.filter(keep);
  return { freq: response.freq.filter(keep), value: response.value.filter(keep), ...(coherence ? { coherence } : {}) };
}

/** The strongest peak, and the strongest dip below it (measured on the motor, a two-mass plant's zero pair lies below
 * its pole pair): without a resonance there is no anti-resonance, so noise digging a dip among a rigid plant's top
 * points is not one (markers.py). */
export function resonances(response: Response): { resonance_hz: number | null; antiresonance_hz: number | null } {
  const plant = coherentPart(response);
  if (plant.freq.length < 2) return { resonance_hz: null, antiresonance_hz: null };
  const resonance = extremum(plant.freq, detrended(plant), 1);
  if (resonance === null) return { resonance_hz: null, antiresonance_hz: null };
  const dips = below(coherentPart(response, MIN_DIP_COHERENCE), resonance);
  return { resonance_hz: resonance, antiresonance_hz: extremum(dips.freq, detrended(dips), -1) };
}

/** Every marker of a set of responses (the plant may be absent: a closed-loop measurement). */
export function markersOf(closed: Response, open: Response | null, plant: Response | null): Markers {
  const none = { gain_margin_db: null, phase_margin_deg: null };
  const nothing = { resonance_hz: null, antiresonance_hz: null };
  return { bandwidth_hz: bandwidth(closed), ...(open ? margins(open) : none), ...(plant ? resonances(plant) : nothing) };
}

/** |value| of a response at its first frequency (a closed loop's static gain), for tests and readouts. */
export const staticGain = (response: Response): number => abs(response.value[0]);
