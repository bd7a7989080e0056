/**
 * Live roll mode's states and actions (docs/scope.md §8): the bus budget of the chosen channels checked before
 * the start (the server's plan: frames/s and bus load), the roll started on the server (refused with its reason),
 * its socket's samples into a `RollBuffer`, stop, and at the end "record while rolling": the capture the server made
 * of the samples saved in the project under the axis and shown in the capture plot.
 */

import { rollSocket, savedCaptures, scopeApi, type CaptureChannel, type CapturePlan, type CaptureRequest } from "../../client/scope";
import { state, type State } from "../../lib/dom";
import { RollBuffer, type RollSamples } from "../../lib/roll";
import { errorText, type Message } from "../ui";
import { request, show, type ScopeModel } from "./model";

/** Seconds of samples the page keeps (and the plot's window). */
export const ROLL_WINDOW_S = 5;

export interface RollModel {
  period: State<string>;
  record: State<boolean>;
  running: State<boolean>;
  budget: State<CapturePlan | null>;
  message: State<Message | null>;
  channels: State<CaptureChannel[]>;
  /** The shown roll's samples (replaced at each start; not reactive: the plot polls it per frame). */
  buffer: RollBuffer | null;
  periodS: number;
  /** Unix ms of the SYNC of the newest sample received (the drives sampled it then). */
  syncedMs: number;
  socket: WebSocket | null;
}

export function createRoll(): RollModel {
  return {
    period: state("1000"), record: state(false), running: state(false), budget: state<CapturePlan | null>(null),
    message: state<Message | null>(null), channels: state<CaptureChannel[]>([]), buffer: null, periodS: 0.001,
    syncedMs: NaN, socket: null,
  };
}

/** The roll's channels and period as a TPDO capture definition: the server's check gives its bus budget. */
function definition(model: ScopeModel, roll: RollModel): CaptureRequest {
  const period = Number(roll.period.rawVal.trim());
  if (!roll.period.rawVal.trim() || !Number.isFinite(period)) throw new Error(`Roll period: "${roll.period.rawVal}" is not a number`);
  const base = request({ ...model.draft, triggerSource: state("") });
  return { ...base, period_us: period, samples: 2048, source: "tpdo", mode: "single" };
}

/** The budget before the start; a refusal (over-subscribed, too fast) is shown with the server's reason. */
export async function checkBudget(model: ScopeModel, roll: RollModel): Promise<void> {
  try {
    roll.budget.val = await scopeApi.check(model.bus, model.node, definition(model, roll));
    if (roll.message.rawVal?.testid === "scope-roll-refused") roll.message.val = null;
  } catch (error) {
    roll.budget.val = null;
    roll.message.val = { text: errorText(error), tone: "error", testid: "scope-roll-refused" };
  }
}

export async function startRoll(model: ScopeModel, roll: RollModel): Promise<void> {
  if (roll.running.rawVal) return;
  roll.message.val = null;
  try {
    const { channels, period_us } = definition(model, roll);
    const started = await scopeApi.roll(model.bus, model.node, { channels, period_us, record: roll.record.rawVal });
    roll.budget.val = started.plan;
    roll.channels.val = started.plan.channels;
    roll.periodS = started.plan.period_ns / 1e9;
    roll.buffer = new RollBuffer(started.plan.channels.length, Math.round(ROLL_WINDOW_S / roll.periodS));
    roll.running.val = true;
    follow(model, roll, rollSocket(started.socket));
  } catch (error) {
    roll.message.val = { text: errorText(error), tone: "error", testid: "scope-roll-refused" };
  }
}

/** Ask the server to end the roll; its `end` event follows on the socket. */
export function stopRoll(roll: RollModel, then?: () => void): void {
  const socket = roll.socket;
  const stop = () => {
    socket?.send(JSON.stringify({ type: "stop" }));
    then?.();
  };
  if (socket?.readyState === WebSocket.OPEN) stop();
  else if (socket?.readyState === WebSocket.CONNECTING) socket.addEventListener("open", stop);
}

/** Leaving the page ends the roll (the server's job would otherwise hold the axes and the bus's SYNC). */
export function disposeRoll(roll: RollModel): void {
  const socket = roll.socket;
  stopRoll(roll, () => socket?.close());
  roll.socket = null;
}

function follow(model: ScopeModel, roll: RollModel, socket: WebSocket): void {
  roll.socket = socket;
  let ended = false;
  socket.addEventListener("message", (message) => {
    const event = JSON.parse(String(message.data)) as { type: string } & Record<string, unknown>;
    if (event.type === "samples") received(roll, event as unknown as RollSamples);
    else if (event.type === "gap") roll.buffer?.gap(event as { from?: number; to?: number; reason?: string });
    else if (event.type === "end") {
      ended = true;
      void finished(model, roll, event);
    } else if (event.type === "error") roll.message.val = { text: String(event.detail ?? "refused"), tone: "error", testid: "scope-roll-error" };
  });
  socket.addEventListener("close", () => {
    roll.running.val = false;
    if (!ended && roll.socket === socket) roll.message.val = { text: "the roll's connection to the server was lost", tone: "error", testid: "scope-roll-error" };
  });
}

function received(roll: RollModel, event: RollSamples): void {
  roll.buffer?.add(event);
  roll.syncedMs = event.synced_at[1] * 1000;
}

/** The roll's end: a failure said; recorded, the capture saved in the project and shown. */
async function finished(model: ScopeModel, roll: RollModel, end: Record<string, unknown>): Promise<void> {
  roll.running.val = false;
  if (typeof end.error === "string") {
    roll.message.val = { text: end.error, tone: "error", testid: "scope-roll-error" };
    return;
  }
  const capture = typeof end.capture === "string" ? end.capture : null;
  if (capture === null) return;
  try {
    const saved = await savedCaptures.save(model.project, model.axis, capture);
    roll.message.val = { text: `Recorded ${saved.samples} samples, saved as "${saved.name}" under axis ${model.axis}.`, tone: "ok", testid: "scope-roll-saved" };
    model.saved.val = await savedCaptures.list(model.project, model.axis);
    await show(model, capture);
  } catch (error) {
    roll.message.val = { text: errorText(error), tone: "error", testid: "scope-roll-error" };
  }
}
