/**
 * The scope page's states and the actions that change them (arm, force, stop, open, save), shared by its
 * components. The draft is what the form shows; `request()` turns it into the server's capture definition.
 */

import type { LiveHub } from "../../client/live";
import { runJob } from "../../client/jobs";
import {
  savedCaptures,
  scopeApi,
  scopeProgress,
  type CaptureData,
  type CaptureJobResult,
  type CaptureRequest,
  type Preset,
  type SavedCapture,
  type ScopeInfo,
} from "../../client/scope";
import { state, type State } from "../../lib/dom";
import type { MathOperation } from "../../lib/measure";
import type { Dictionary } from "../../lib/od";
import { errorText, type Message } from "../ui";

export type Edge = "rising" | "falling" | "either";
export type Mode = "single" | "normal" | "auto";
export const CHANNEL_SLOTS = 4;
/** The recorder's power-on channels: position, velocity, current, status word. */
const DEFAULT_CHANNELS = ["0x6064,0", "0x606C,0", "0x6078,0", "0x6041,0"];

export interface Draft {
  channels: State<string[]>;
  period: State<string>;
  samples: State<string>;
  /** "" = immediate */
  triggerSource: State<string>;
  edge: State<Edge>;
  level: State<string>;
  pretrigger: State<string>;
  mode: State<Mode>;
  /** Auto mode: ms without a trigger after which the recorder forces one. */
  autoTimeout: State<string>;
}

export interface MathTrace {
  operation: MathOperation | "none";
  a: number;
  b: number;
  k: number;
}

export interface Cursors {
  a: number | null;
  b: number | null;
  /** The cursor the next click on the plot moves. */
  next: "a" | "b";
}

export interface ScopeModel {
  bus: string;
  node: number;
  project: string;
  axis: string;
  live: LiveHub;
  dictionary: Dictionary;
  draft: Draft;
  info: State<ScopeInfo | null>;
  /** Recorder stage as the job reports it: idle, armed, filling, waiting, recording, done, uploading. */
  stage: State<string>;
  upload: State<{ done: number; total: number } | null>;
  job: State<string | null>;
  capture: State<CaptureData | null>;
  /** The live id of the shown capture (null: a saved one, or none). */
  captureId: State<string | null>;
  cursors: State<Cursors>;
  math: State<MathTrace>;
  view: State<"time" | "fft">;
  message: State<Message | null>;
  saved: State<SavedCapture[]>;
}

export function createModel(
  live: LiveHub, dictionary: Dictionary, where: { bus: string; node: number; project: string; axis: string },
): ScopeModel {
  return {
    ...where,
    live,
    dictionary,
    draft: {
      channels: state(DEFAULT_CHANNELS),
      period: state("250"),
      samples: state("2048"),
      triggerSource: state(""),
      edge: state<Edge>("rising"),
      level: state("0"),
      pretrigger: state("0"),
      mode: state<Mode>("single"),
      autoTimeout: state("100"),
    },
    info: state<ScopeInfo | null>(null),
    stage: state("idle"),
    upload: state<{ done: number; total: number } | null>(null),
    job: state<string | null>(null),
    capture: state<CaptureData | null>(null),
    captureId: state<string | null>(null),
    cursors: state<Cursors>({ a: null, b: null, next: "a" }),
    math: state<MathTrace>({ operation: "none", a: 0, b: 1, k: 1 }),
    view: state<"time" | "fft">("time"),
    message: state<Message | null>(null),
    saved: state<SavedCapture[]>([]),
  };
}

/** The draft as a capture definition; a field that is not a number is refused here with its name. */
export function request(draft: Draft): CaptureRequest {
  const number = (text: string, what: string) => {
    const value = Number(text.trim());
    if (text.trim() === "" || !Number.isFinite(value)) throw new Error(`${what}: "${text}" is not a number (use "." as decimal point)`);
    return value;
  };
  const source = draft.triggerSource.rawVal;
  return {
    channels: draft.channels.rawVal.filter((key) => key !== ""),
    period_us: number(draft.period.rawVal, "Period"),
    samples: number(draft.samples.rawVal, "Samples"),
    trigger: source ? { source, edge: draft.edge.rawVal, level: number(draft.level.rawVal, "Trigger level") } : { source: null, edge: "rising", level: 0 },
    pre_trigger_pct: source ? number(draft.pretrigger.rawVal, "Pre-trigger") : 0,
    mode: draft.mode.rawVal,
    auto_timeout_ms: number(draft.autoTimeout.rawVal, "Auto timeout"),
    source: "auto",
  };
}

/** Put a preset's definition (or a capture's) into the form. */
export function applyDefinition(draft: Draft, definition: Preset["definition"]): void {
  const channels = [...definition.channels, "", "", "", ""].slice(0, CHANNEL_SLOTS);
  draft.channels.val = channels;
  draft.period.val = String(definition.period_us ?? 250);
  draft.samples.val = String(definition.samples ?? 2048);
  draft.triggerSource.val = definition.trigger?.source ?? "";
  draft.edge.val = (definition.trigger?.edge ?? "rising") as Edge;
  draft.level.val = String(definition.trigger?.level ?? 0);
  draft.pretrigger.val = String(definition.pre_trigger_pct ?? 0);
  draft.mode.val = (definition.mode ?? "single") as Mode;
  draft.autoTimeout.val = String(definition.auto_timeout_ms ?? 100);
}

/** Arm: the server checks the definition (a refusal is shown), then captures as a job; each capture is shown. */
export async function arm(model: ScopeModel): Promise<void> {
  if (model.job.rawVal !== null) return;
  model.message.val = null;
  let definition: CaptureRequest;
  try {
    definition = request(model.draft);
  } catch (error) {
    model.message.val = { text: errorText(error), tone: "error", testid: "scope-refused" };
    return;
  }
  model.stage.val = "arming";
  try {
    const job = await runJob<CaptureJobResult>(model.live, async () => {
      const started = await scopeApi.start(model.bus, model.node, definition);
      model.job.val = started.id;
      return started;
    }, (event) => void follow(model, event));
    if (job.state === "failed") model.message.val = { text: job.error ?? "the capture failed", tone: "error", testid: "scope-failed" };
    else if (job.result?.capture && model.captureId.rawVal !== job.result.capture) await show(model, job.result.capture);
  } catch (error) {
    model.message.val = { text: errorText(error), tone: "error", testid: "scope-refused" };
  } finally {
    model.job.val = null;
    model.upload.val = null;
    model.stage.val = (await scopeApi.status(model.bus, model.node).catch(() => null))?.status ?? "idle";
  }
}

async function follow(model: ScopeModel, event: Parameters<typeof scopeProgress>[0]): Promise<void> {
  const progress = scopeProgress(event);
  if (!progress) return;
  if (progress.stage === "uploading") model.upload.val = { done: progress.done ?? 0, total: progress.total ?? 0 };
  else if (progress.stage === "captured" && progress.capture) await show(model, progress.capture);
  else model.upload.val = null;
  model.stage.val = progress.stage;
}

/** Fetch a live capture and show it. */
export async function show(model: ScopeModel, id: string): Promise<void> {
  const made = await scopeApi.capture(model.bus, model.node, id);
  model.captureId.val = id;
  model.capture.val = made;
}

export async function force(model: ScopeModel): Promise<void> {
  await act(model, async () => (model.stage.val = (await scopeApi.force(model.bus, model.node)).status));
}

export async function stop(model: ScopeModel): Promise<void> {
  await act(model, async () => (model.stage.val = (await scopeApi.stop(model.bus, model.node)).status));
}

export async function refreshSaved(model: ScopeModel): Promise<void> {
  await act(model, async () => (model.saved.val = await savedCaptures.list(model.project, model.axis)));
}

export async function save(model: ScopeModel, name: string): Promise<void> {
  const id = model.captureId.rawVal;
  if (id === null) return;
  await act(model, async () => {
    const saved = await savedCaptures.save(model.project, model.axis, id, name.trim() || undefined);
    model.message.val = { text: `Saved as "${saved.name}" under axis ${model.axis}.`, tone: "ok", testid: "scope-save-done" };
    model.saved.val = await savedCaptures.list(model.project, model.axis);
  });
}

export async function openSaved(model: ScopeModel, name: string): Promise<void> {
  await act(model, async () => {
    const made = await savedCaptures.open(model.project, model.axis, name);
    model.captureId.val = null;
    model.capture.val = made;
    applyDefinition(model.draft, made.definition);
  });
}

async function act(model: ScopeModel, work: () => Promise<unknown>): Promise<void> {
  try {
    await work();
  } catch (error) {
    model.message.val = { text: errorText(error), tone: "error", testid: "scope-error" };
  }
}
