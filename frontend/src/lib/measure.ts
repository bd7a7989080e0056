/**
 * Measurements of a captured signal, pure functions over evenly spaced samples (`dt` seconds apart): the statistics
 * an oscilloscope shows per channel, the step response of a loop (rise time, overshoot, settling), the math traces
 * and the cursor readings. The FFT is in `lib/fft.ts`.
 */

export interface Stats {
  min: number;
  max: number;
  mean: number;
  rms: number;
  peakToPeak: number;
  /** From the crossings of the mean (with a hysteresis of 10 % of peak-to-peak); null without two periods' edges. */
  frequency: number | null;
}

export function stats(values: readonly number[], dt: number): Stats | null {
  if (values.length === 0) return null;
  let min = Infinity, max = -Infinity, sum = 0, squares = 0;
  for (const value of values) {
    if (value < min) min = value;
    if (value > max) max = value;
    sum += value;
    squares += value * value;
  }
  const mean = sum / values.length;
  return { min, max, mean, rms: Math.sqrt(squares / values.length), peakToPeak: max - min, frequency: frequency(values, dt, mean, max - min) };
}

/** Frequency from the rising crossings of `level`: (crossings − 1) periods between the first and the last one. */
export function frequency(values: readonly number[], dt: number, level: number, peakToPeak: number): number | null {
  const crossings = risingCrossings(values, level, peakToPeak * 0.1);
  if (crossings.length < 2 || peakToPeak === 0) return null;
  return (crossings.length - 1) / ((crossings[crossings.length - 1] - crossings[0]) * dt);
}

/** Fractional sample positions where the signal rises through `level` after having been below `level − hysteresis`. */
function risingCrossings(values: readonly number[], level: number, hysteresis: number): number[] {
  const found: number[] = [];
  let armed = false;
  for (let i = 1; i < values.length; i++) {
    if (values[i - 1] < level - hysteresis) armed = true;
    if (armed && values[i - 1] < level && values[i] >= level) {
      found.push(i - 1 + (level - values[i - 1]) / (values[i] - values[i - 1]));
      armed = false;
    }
  }
  return found;
}

export interface StepResponse {
  initial: number;
  final: number;
  /** 10 % → 90 % of the step, in seconds. */
  riseTime: number | null;
  /** Peak beyond the final value, in % of the step (0 when it never passes it). */
  overshootPct: number;
  /** From `start` until the signal stays within ±`band` of the step around the final value, in seconds. */
  settlingTime: number | null;
}

/**
 * The response to a step at sample `start` (the trigger): the initial value is the mean before it (or the first
 * sample), the final value the mean of the last 10 % of the samples. Null when there is no step to measure.
 */
export function stepResponse(values: readonly number[], dt: number, start = 0, band = 0.02): StepResponse | null {
  if (values.length < 3 || start >= values.length - 1) return null;
  const initial = start > 0 ? average(values.slice(0, start)) : values[0];
  const final = average(values.slice(Math.floor(values.length * 0.9)));
  const step = final - initial;
  const range = Math.max(...values) - Math.min(...values);
  if (step === 0 || Math.abs(step) < range * 0.05) return null;
  const normalised = values.slice(start).map((value) => (value - initial) / step);
  const t10 = firstReaching(normalised, 0.1), t90 = firstReaching(normalised, 0.9);
  const peak = Math.max(...normalised);
  const outside = lastOutside(normalised, band);
  return {
    initial,
    final,
    riseTime: t10 !== null && t90 !== null ? (t90 - t10) * dt : null,
    overshootPct: peak > 1 ? (peak - 1) * 100 : 0,
    settlingTime: outside === normalised.length - 1 ? null : (outside + 1) * dt,
  };
}

function average(values: readonly number[]): number {
  return values.reduce((sum, value) => sum + value, 0) / values.length;
}

/** The fractional sample where `values` first reaches `level` (interpolated), or null. */
function firstReaching(values: readonly number[], level: number): number | null {
  if (values[0] >= level) return 0;
  for (let i = 1; i < values.length; i++) {
    if (values[i] >= level) return i - 1 + (level - values[i - 1]) / (values[i] - values[i - 1]);
  }
  return null;
}

/** The last sample outside 1 ± band (−1: none). */
function lastOutside(values: readonly number[], band: number): number {
  for (let i = values.length - 1; i >= 0; i--) if (Math.abs(values[i] - 1) > band) return i;
  return -1;
}

// ---- math traces ------------------------------------------------------------------------------------------------

export type MathOperation = "a-b" | "a*k" | "d/dt";

export function difference(a: readonly number[], b: readonly number[]): number[] {
  return a.map((value, i) => value - b[i]);
}

export function scaled(a: readonly number[], k: number): number[] {
  return a.map((value) => value * k);
}

/** Derivative per second: central differences inside, one-sided at both ends. */
export function derivative(a: readonly number[], dt: number): number[] {
  if (a.length < 2) return a.map(() => 0);
  return a.map((_, i) => {
    const before = Math.max(0, i - 1), after = Math.min(a.length - 1, i + 1);
    return (a[after] - a[before]) / ((after - before) * dt);
  });
}

// ---- cursors ------------------------------------------------------------------------------------------------

/** The sample nearest to time `t` of a signal whose sample 0 is at `t0` (null outside the capture). */
export function sampleAt(values: readonly number[], t0: number, dt: number, t: number): number | null {
  const index = Math.round((t - t0) / dt);
  return index >= 0 && index < values.length ? values[index] : null;
}

export interface CursorDelta {
  dt: number;
  /** 1/Δt in Hz: the frequency whose period the two cursors span (null when they coincide). */
  inverse: number | null;
}

export function cursorDelta(a: number, b: number): CursorDelta {
  const dt = b - a;
  return { dt, inverse: dt === 0 ? null : 1 / Math.abs(dt) };
}
