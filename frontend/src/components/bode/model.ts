/**
 * The Bode page's state: the axis's saved frequency responses (listed, opened on demand, some overlaid), the plant
 * the what-if runs on, the drive's speed loop and the draft gains the sliders edit, and the predictions derived
 * from them — recomputed at once when a slider moves, the time it took kept in `computeMs`.
 */

import { savedFrequency, speedLoopApi, type SavedResult, type SavedSummary, type SpeedLoop } from "../../client/frequency";
import { barePlant, changeOf, draftOf, fitOf, paramsWith, predict, type Draft, type Prediction } from "../../lib/bode";
import { derive, state, type Scope, type State } from "../../lib/dom";
import type { SpeedLoopReading } from "../../lib/whatif/loop";
import { errorText, type Message } from "../ui";

export type BodeViewKind = "closed" | "open" | "plant";

export interface Where {
  bus: string;
  node: number;
  project: string;
  axis: string;
}

export interface Timed {
  prediction: Prediction;
  computeMs: number;
}

export interface BodeModel {
  where: Where;
  saved: State<SavedSummary[] | null>;
  savedError: State<string | null>;
  /** the results opened so far, by name (replaced, never mutated) */
  results: State<Record<string, SavedResult>>;
  /** the saved results overlaid */
  shown: State<string[]>;
  /** the plant measurement the what-if runs on */
  plantName: State<string | null>;
  view: State<BodeViewKind>;
  loop: State<SpeedLoop | null>;
  loopError: State<string | null>;
  draft: State<Draft | null>;
  /** the what-if prediction (draft gains) and the prediction with the drive's gains */
  predicted: State<Timed | null>;
  current: State<Timed | null>;
  message: State<Message | null>;
  busy: State<boolean>;
}

const reading = (loop: SpeedLoop) => loop as unknown as SpeedLoopReading;

function timedPrediction(model: BodeModel, draft: () => Draft | null): Timed | null {
  const loop = model.loop.val, name = model.plantName.val, wanted = draft();
  const result = name ? model.results.val[name] : undefined;
  if (!loop || !result || !wanted) return null;
  const started = performance.now();
  const prediction = predict(barePlant(result, loop.control_period_s), fitOf(result), paramsWith(reading(loop), wanted));
  return { prediction, computeMs: performance.now() - started };
}

export function createModel(scope: Scope, where: Where): BodeModel {
  const model = {
    where, saved: state<SavedSummary[] | null>(null), savedError: state<string | null>(null),
    results: state<Record<string, SavedResult>>({}), shown: state<string[]>([]), plantName: state<string | null>(null),
    view: state<BodeViewKind>("closed"), loop: state<SpeedLoop | null>(null), loopError: state<string | null>(null),
    draft: state<Draft | null>(null), message: state<Message | null>(null), busy: state(false),
  } as Omit<BodeModel, "predicted" | "current"> as BodeModel;
  scope.run(() => {
    model.predicted = derive(() => timedPrediction(model, () => model.draft.val));
    model.current = derive(() => timedPrediction(model, () => (model.loop.val ? draftOf(reading(model.loop.val)) : null)));
  });
  return model;
}

/** Open a saved result (once) so it can be drawn. */
export async function openResult(model: BodeModel, name: string): Promise<void> {
  if (model.results.rawVal[name]) return;
  const { project, axis } = model.where;
  const result = await savedFrequency.open(project, axis, name);
  model.results.val = { ...model.results.rawVal, [name]: result };
}

/** List the saved results again; the first time, show the newest plant and run the what-if on it. */
export async function refreshSaved(model: BodeModel): Promise<void> {
  try {
    const saved = await savedFrequency.list(model.where.project, model.where.axis);
    model.saved.val = saved;
    model.savedError.val = null;
    const names = new Set(saved.map((item) => item.name));
    model.shown.val = model.shown.rawVal.filter((name) => names.has(name));
    if (model.plantName.rawVal && !names.has(model.plantName.rawVal)) model.plantName.val = null;
    const plant = saved.find((item) => item.loop === "plant" && !item.error);
    if (model.plantName.rawVal === null && plant) await usePlant(model, plant.name);
  } catch (error) {
    model.savedError.val = errorText(error);
  }
}

export async function toggleShown(model: BodeModel, name: string, on: boolean): Promise<void> {
  try {
    if (on) await openResult(model, name);
    const others = model.shown.rawVal.filter((shown) => shown !== name);
    model.shown.val = on ? [...others, name] : others;
  } catch (error) {
    model.message.val = { text: `${name}: ${errorText(error)}`, tone: "error", testid: "bode-error" };
  }
}

/** Run the what-if on this plant measurement (and overlay it). */
export async function usePlant(model: BodeModel, name: string): Promise<void> {
  await toggleShown(model, name, true);
  if (model.results.rawVal[name]) model.plantName.val = name;
}

/** Read the drive's speed loop; the sliders start from it. */
export async function loadLoop(model: BodeModel): Promise<void> {
  try {
    const loop = await speedLoopApi.get(model.where.bus, model.where.node);
    model.loop.val = loop;
    model.draft.val = draftOf(reading(loop));
    model.loopError.val = null;
  } catch (error) {
    model.loopError.val = errorText(error);
  }
}

/** Back to the drive's gains. */
export function resetDraft(model: BodeModel): void {
  const loop = model.loop.rawVal;
  if (loop) model.draft.val = draftOf(reading(loop));
}

/** The draft's changes as the PUT sends them (empty: the draft is the drive's loop). */
export function pendingChange(model: BodeModel): Record<string, number> {
  const loop = model.loop.val, draft = model.draft.val;
  return loop && draft ? changeOf({ ...reading(loop), writable: loop.writable }, draft) : {};
}

/** "Write these gains": PUT the changes (every value checked by the server before any write), then read back. */
export async function writeGains(model: BodeModel): Promise<boolean> {
  const change = pendingChange(model);
  model.busy.val = true;
  try {
    const answer = await speedLoopApi.put(model.where.bus, model.where.node, change);
    model.loop.val = answer.after;
    model.draft.val = draftOf(reading(answer.after));
    model.message.val = { text: `Written to the drive: ${answer.written.map(([name, raw]) => `${String(name)} = ${String(raw)}`).join(", ")}.`, tone: "ok", testid: "bode-written" };
    return true;
  } catch (error) {
    model.message.val = { text: `Nothing written: ${errorText(error)}`, tone: "error", testid: "bode-error" };
    return false;
  } finally {
    model.busy.val = false;
  }
}

export async function removeSaved(model: BodeModel, name: string): Promise<void> {
  try {
    await savedFrequency.remove(model.where.project, model.where.axis, name);
    const { [name]: _gone, ...rest } = model.results.rawVal;
    model.results.val = rest;
    await refreshSaved(model);
  } catch (error) {
    model.message.val = { text: `${name}: ${errorText(error)}`, tone: "error", testid: "bode-error" };
  }
}
