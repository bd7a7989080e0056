/**
 * What one frame of the live roll shows (docs/scope.md §8), as pure numbers: the window of the last seconds, each
 * channel decimated to the plot's pixel columns (min/max per column, `decimate`), each channel's own y-scale with
 * "nice" ticks (1, 2, 5 × 10ⁿ), the time axis's ticks and the gaps as bands. The canvas painter
 * (`components/scope/rollcanvas.ts`) only maps these to pixels, so everything it draws is unit-tested here.
 */

import { decimate, type RollBuffer, type Series } from "./roll";

/** An axis: its ends and its tick values, `step` apart. */
export interface Scale {
  low: number;
  high: number;
  step: number;
  ticks: number[];
}

/** The sequence numbers a frame shows: [`from`, `to`) of samples, the axis to `end` (the window fills up first). */
export interface RollWindow {
  from: number;
  to: number;
  end: number;
}

export interface RollFrame {
  /** Seconds at the left and the right end of the plot. */
  time: Scale;
  series: Series[];
  scales: Scale[];
  /** The gaps in the window, in seconds (a shaded band each; the lines break there). */
  gaps: { from: number; to: number }[];
}

/** The newest `keep` sequence numbers; the axis spans a whole window from the start on. */
export function rollWindow(buffer: RollBuffer): RollWindow {
  const to = buffer.last + 1;
  return { from: Math.max(0, to - buffer.keep), to, end: Math.max(to, buffer.keep) };
}

/** The frame of the buffer's window, `columns` pixel columns wide, with about `timeTicks` ticks on the time axis. */
export function rollFrame(buffer: RollBuffer, period: number, columns: number, timeTicks: number): RollFrame {
  const window = rollWindow(buffer);
  const series = buffer.values.map((values) => decimate(buffer.seqs, values, period, window.from, window.to, columns));
  const t0 = window.from * period, t1 = window.end * period;
  const step = niceStep((t1 - t0) / Math.max(timeTicks, 1));
  const gaps = buffer.gaps.filter((gap) => gap.to > window.from).map((gap) => ({ from: Math.max(gap.from, window.from) * period, to: gap.to * period }));
  return { time: { low: t0, high: t1, step, ticks: ticksWithin(t0, t1, step) }, series, scales: series.map((one) => valueScale(one.y)), gaps };
}

/** The smallest 1, 2 or 5 × 10ⁿ at least `rough` (a tick step); 1 for a zero or non-finite span. */
export function niceStep(rough: number): number {
  if (!(rough > 0) || !Number.isFinite(rough)) return 1;
  const power = 10 ** Math.floor(Math.log10(rough));
  const step = [1, 2, 5, 10].map((k) => k * power).find((candidate) => candidate >= rough * (1 - 1e-9));
  return step ?? 10 * power;
}

/** The y-scale of a channel: its finite values' range widened to whole ticks (about `count`); a constant signal
 * is centred in a small range of its own, no finite value at all is 0..1. */
export function valueScale(values: number[], count = 5): Scale {
  let low = Infinity, high = -Infinity;
  for (const value of values) {
    if (value < low) low = value;
    if (value > high) high = value;
  }
  if (!Number.isFinite(low) || !Number.isFinite(high)) [low, high] = [0, 1];
  const size = Math.max(Math.abs(low), Math.abs(high));
  if (high - low <= Math.max(size * 1e-12, 1e-300)) { // constant (to the last digits)
    const pad = size > 1e-300 ? size * 0.01 : 1;
    [low, high] = [low - pad, high + pad];
  }
  const step = niceStep((high - low) / count);
  let bottom = Math.floor(low / step + 1e-9) * step, top = Math.ceil(high / step - 1e-9) * step;
  if (bottom > low) bottom -= step; // the tolerance above rounded past a value
  if (top < high) top += step;
  return { low: bottom, high: top, step, ticks: ticksWithin(bottom, top, step) };
}

/** The multiples of `step` in [`low`, `high`], rounded to the step's decimals (no 0.30000000000000004). */
export function ticksWithin(low: number, high: number, step: number): number[] {
  const decimals = stepDecimals(step), ticks: number[] = [];
  for (let k = Math.ceil(low / step - 1e-9); k * step <= high + step * 1e-9 && ticks.length < 1000; k++) ticks.push(Number((k * step).toFixed(decimals)));
  return ticks;
}

/** A tick's label: as many decimals as its step needs. */
export function tickLabel(value: number, step: number): string {
  return value.toFixed(stepDecimals(step));
}

function stepDecimals(step: number): number {
  return Math.min(12, Math.max(0, -Math.floor(Math.log10(step) + 1e-9)));
}

/** `value` of [`low`, `high`] as a pixel of [`from`, `to`] (y pixels grow downwards: pass from > to). */
export function toPixel(value: number, low: number, high: number, from: number, to: number): number {
  return from + ((value - low) / (high - low)) * (to - from);
}
