/**
 * The Bode page's logic without the DOM (docs/what-if.md): a saved plant measurement and a set of speed-loop gains
 * → the predicted open and closed loop, their markers and the predicted step; the gains the sliders edit.
 *
 * A plant measurement (docs/frequency-response.md §2) is the speed's line jω·X of the recorded position over the
 * torque's line of the recorded current, advanced by one control period; on the simulated drive it leads the
 * continuous 1/(J·s + B) by one control period (its §5). The model's plant P (loop.ts) is the current demand held
 * over a period to the position difference over the period, used in the next one: 1/(J·s + B) one period late. So
 * a measured plant is taken two periods later, e^{−j·2ωT}, before the model runs on it (docs/what-if.md, "The plant
 * the prediction uses": measured against the re-measured closed loop).
 *
 * The current-command filters act before the measured current, so the model applies the what-if ones on the plant
 * as it is. A result that says its plant includes the filters of the loop it was measured with
 * (`plant_includes_filters`) has those (`gains.current_filters_hz`) divided out first.
 */

import { db, mul, unit, unwrapDeg } from "./whatif/complex";
import { loopResponses, paramsOf, responseOf, withoutFilters, type BodePoint, type LoopParams, type Response, type SpeedLoopReading } from "./whatif/loop";
import { coherentPart, crossingDown, markersOf, type Markers } from "./whatif/markers";
import { stepResponse, type PlantFit, type StepResponse } from "./whatif/step";

/** What the sliders change; the rest of the loop stays as the drive has it. */
export interface Draft {
  kp: number;
  ki: number;
  filtersHz: number[];
  speedFilterS: number;
}

/** A measured point as the server sends it (a value that was not finite in the file is null). */
export interface MeasuredPoint {
  freq_hz: number | null;
  magnitude_db: number | null;
  phase_deg: number | null;
  coherence: number | null;
}

/** The parts of a saved result the prediction reads. */
export interface PlantMeasurement {
  points: MeasuredPoint[];
  plant_fit?: Partial<PlantFit> | null;
  gains?: { current_filters_hz?: number[] } | null;
  plant_includes_filters?: boolean | null;
}

export interface Prediction {
  open: Response;
  closed: Response;
  markers: Markers;
  /** where |L| = 1 and where ∠L = −180° (the margins are read there); null when it does not cross */
  gainCrossoverHz: number | null;
  phaseCrossoverHz: number | null;
  step: StepResponse | null;
}

export function draftOf(loop: SpeedLoopReading): Draft {
  return { kp: loop.kp_a_per_rad_s, ki: loop.ki_a_per_rad, filtersHz: [...loop.current_filters_hz], speedFilterS: loop.speed_filter_s };
}

export function paramsWith(loop: SpeedLoopReading, draft: Draft): LoopParams {
  return { ...paramsOf(loop), kp: draft.kp, ki: draft.ki, currentFiltersHz: [...draft.filtersHz], speedFilterS: draft.speedFilterS };
}

/** The usable points (every value finite), as the loop model's Bode points. */
export function usablePoints(points: MeasuredPoint[]): BodePoint[] {
  return points.filter((p): p is BodePoint & { coherence: number | null } =>
    [p.freq_hz, p.magnitude_db, p.phase_deg].every((v) => typeof v === "number" && Number.isFinite(v)) && (p.freq_hz ?? 0) > 0)
    .map((p) => ({ freq_hz: p.freq_hz, magnitude_db: p.magnitude_db, phase_deg: p.phase_deg, coherence: p.coherence }));
}

/** Control periods between a measured plant and the model's P: the measurement's lead, the model's hold and difference. */
export const MEASURED_PLANT_SHIFT_PERIODS = 2;

/** The model's plant P of a measurement: shifted to the model's instants, without any current-command filter. */
export function barePlant(measurement: PlantMeasurement, periodS: number): Response {
  const measured = responseOf(usablePoints(measurement.points));
  const shift = (f: number) => unit(-2 * Math.PI * f * periodS * MEASURED_PLANT_SHIFT_PERIODS);
  const plant = { ...measured, value: measured.value.map((value, n) => mul(value, shift(measured.freq[n]))) };
  return measurement.plant_includes_filters ? withoutFilters(plant, measurement.gains?.current_filters_hz ?? [], periodS) : plant;
}

export function fitOf(measurement: PlantMeasurement): PlantFit | null {
  const fit = measurement.plant_fit;
  const inertia = fit?.inertia_kgm2, friction = fit?.viscous_friction_nms_per_rad;
  if (typeof inertia !== "number" || !(inertia > 0) || typeof friction !== "number" || !(friction >= 0)) return null;
  return { inertia_kgm2: inertia, viscous_friction_nms_per_rad: friction };
}

/** How long the predicted step runs: 20 time constants 1/(2π·bandwidth), within 20–300 ms. */
export function stepDuration(bandwidthHz: number | null): number {
  if (bandwidthHz === null || !(bandwidthHz > 0)) return 0.1;
  return Math.min(0.3, Math.max(0.02, 20 / (2 * Math.PI * bandwidthHz)));
}

/** Everything the page shows for one set of gains. */
export function predict(plant: Response, fit: PlantFit | null, params: LoopParams): Prediction {
  const { openLoop: open, closedLoop: closed } = loopResponses(plant, params);
  const markers = markersOf(closed, open, plant);
  const marked = coherentPart(open);
  return {
    open, closed, markers,
    gainCrossoverHz: crossingDown(marked.freq, marked.value.map(db), 0),
    phaseCrossoverHz: crossingDown(marked.freq, unwrapDeg(marked.value), -180),
    step: fit ? stepResponse(params, fit, stepDuration(markers.bandwidth_hz)) : null,
  };
}

/** A response as the figure draws it. */
export interface Trace {
  freq: number[];
  magnitudeDb: number[];
  phaseDeg: number[];
  coherence: (number | null)[] | null;
}

export function traceOf(response: Response): Trace {
  return { freq: response.freq, magnitudeDb: response.value.map(db), phaseDeg: unwrapDeg(response.value), coherence: null };
}

export function measuredTrace(points: MeasuredPoint[]): Trace {
  const usable = points.filter((p) => usablePoints([p]).length === 1);
  return {
    freq: usable.map((p) => p.freq_hz!), magnitudeDb: usable.map((p) => p.magnitude_db!),
    phaseDeg: usable.map((p) => p.phase_deg!), coherence: usable.map((p) => p.coherence),
  };
}

/** Slider positions: a gain is moved on a log scale from 1/10 to 10 times the drive's value (0 for a zero gain). */
export const SLIDER_STEPS = 400;

export function gainAt(position: number, reference: number): number {
  const base = reference > 0 ? reference : 1;
  return base * 10 ** ((2 * position) / SLIDER_STEPS - 1);
}

export function positionOf(value: number, reference: number): number {
  const base = reference > 0 ? reference : 1;
  if (!(value > 0)) return 0;
  return Math.round(((Math.log10(value / base) + 1) * SLIDER_STEPS) / 2);
}

/** A current-command filter slider: 0 is off, then 20 Hz to 2 kHz on a log scale (whole hertz, as the drive takes). */
const FILTER_LOW_HZ = 20, FILTER_HIGH_HZ = 2000;

export function filterAt(position: number): number {
  if (position <= 0) return 0;
  return Math.round(FILTER_LOW_HZ * (FILTER_HIGH_HZ / FILTER_LOW_HZ) ** ((position - 1) / (SLIDER_STEPS - 1)));
}

export function filterPosition(hz: number): number {
  if (!(hz > 0)) return 0;
  const share = Math.log(Math.min(Math.max(hz, FILTER_LOW_HZ), FILTER_HIGH_HZ) / FILTER_LOW_HZ) / Math.log(FILTER_HIGH_HZ / FILTER_LOW_HZ);
  return 1 + Math.round(share * (SLIDER_STEPS - 1));
}

/** The PUT body for a draft: only what differs from the drive and what the drive takes. */
export function changeOf(loop: SpeedLoopReading & { writable: string[] }, draft: Draft): Record<string, number> {
  const change: Record<string, number> = {};
  const put = (key: string, value: number, old: number) => {
    if (loop.writable.includes(key) && Math.abs(value - old) > 1e-12 * Math.max(1, Math.abs(old))) change[key] = value;
  };
  put("kp_a_per_rad_s", draft.kp, loop.kp_a_per_rad_s);
  put("ki_a_per_rad", draft.ki, loop.ki_a_per_rad);
  draft.filtersHz.forEach((hz, n) => put(`current_filter_${n + 1}_hz`, Math.round(hz), loop.current_filters_hz[n] ?? 0));
  put("speed_filter_s", draft.speedFilterS, loop.speed_filter_s);
  return change;
}
