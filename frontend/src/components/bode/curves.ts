/**
 * Which curves and markers each view of the Bode page draws (pure):
 * - closed loop: the measured closed-loop results, the predicted closed loop with the what-if gains and with the
 *   drive's gains, their −3 dB bandwidths;
 * - open loop: the predicted open loops, the phase margin at the gain crossover and the gain margin at the phase
 *   crossover;
 * - plant: the measured plant results with their coherence, resonance and anti-resonance.
 */

import type { SavedResult } from "../../client/frequency";
import { measuredTrace, traceOf, type Prediction } from "../../lib/bode";
import { sig } from "../../lib/procedures";
import type { Curve, MarkerLine } from "./figure";
import type { BodeViewKind } from "./model";

export const MEASURED_COLORS = ["#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"];
export const WHATIF_COLOR = "#d62728";
export const CURRENT_COLOR = "#7f7f7f";

export interface FigureInputs {
  curves: Curve[];
  lines: MarkerLine[];
  magnitudeTitle: string;
}

export interface Shown {
  name: string;
  result: SavedResult;
}

const MAGNITUDE = { closed: "|ω/ω_ref| [dB]", open: "|L| [dB]", plant: "|ω/T| [dB of (rad/s)/(N·m)]" };

function measured(shown: Shown[], loop: "plant" | "closed"): { curves: Curve[]; lines: MarkerLine[] } {
  const curves: Curve[] = [], lines: MarkerLine[] = [];
  shown.forEach(({ name, result }, n) => {
    if (result.loop !== loop) return;
    const color = MEASURED_COLORS[n % MEASURED_COLORS.length];
    curves.push({ label: `${name} (measured)`, trace: measuredTrace(result.points), color });
    const markers = result.markers;
    const add = (freq: number | null | undefined, label: string) => {
      if (typeof freq === "number" && freq > 0) lines.push({ freq, label: `${label} ${sig(freq, "Hz")}`, color, at: "start" });
    };
    if (loop === "closed") add(markers?.bandwidth_hz, "bandwidth");
    else {
      add(markers?.resonance_hz, "resonance");
      add(markers?.antiresonance_hz, "anti-resonance");
    }
  });
  return { curves, lines };
}

function predictedCurves(which: "open" | "closed", predicted: Prediction | null, current: Prediction | null): Curve[] {
  const curves: Curve[] = [];
  if (current) curves.push({ label: `${which} loop, drive's gains (predicted)`, trace: traceOf(current[which]), color: CURRENT_COLOR, dash: "dot" });
  if (predicted) curves.push({ label: `${which} loop, what-if gains (predicted)`, trace: traceOf(predicted[which]), color: WHATIF_COLOR, dash: "dash" });
  return curves;
}

function marginLines(prediction: Prediction | null, color: string): MarkerLine[] {
  if (!prediction) return [];
  const { gainCrossoverHz, phaseCrossoverHz, markers } = prediction;
  const lines: MarkerLine[] = [];
  if (gainCrossoverHz !== null) lines.push({ freq: gainCrossoverHz, label: `phase margin ${sig(markers.phase_margin_deg, "°")}`, color });
  if (phaseCrossoverHz !== null) lines.push({ freq: phaseCrossoverHz, label: `gain margin ${sig(markers.gain_margin_db, "dB")}`, color });
  return lines;
}

export function figureInputs(view: BodeViewKind, shown: Shown[], predicted: Prediction | null, current: Prediction | null): FigureInputs {
  const magnitudeTitle = MAGNITUDE[view];
  if (view === "plant") return { ...measured(shown, "plant"), magnitudeTitle };
  if (view === "open") {
    return { curves: predictedCurves("open", predicted, current), lines: [...marginLines(current, CURRENT_COLOR), ...marginLines(predicted, WHATIF_COLOR)], magnitudeTitle };
  }
  const { curves, lines } = measured(shown, "closed");
  const bandwidth = predicted?.markers.bandwidth_hz;
  if (bandwidth) lines.push({ freq: bandwidth, label: `what-if bandwidth ${sig(bandwidth, "Hz")}`, color: WHATIF_COLOR });
  return { curves: [...curves, ...predictedCurves("closed", predicted, current)], lines, magnitudeTitle };
}
