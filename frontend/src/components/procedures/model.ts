/**
 * The states of a procedure page and the actions that change them, shared by its components: the drive's
 * procedures with their preconditions (read again after every run), the axis's controller (a moving procedure needs
 * this page to have armed the axis, docs/motion-safety.md), and one `Run` per procedure — its job, live progress,
 * result and message. A start is a server job; Abort cancels it (the server writes 0 to the trigger and leaves the
 * drive disabled and the gains as before).
 */

import { controlApi, heldByMe, type AxisControl } from "../../client/control";
import { serverBus } from "../../client/drives";
import { cancelJob, runJob, type JobState } from "../../client/jobs";
import type { LiveHub } from "../../client/live";
import {
  procedureProgress,
  proceduresApi,
  type ProcedureInfo,
  type ProcedureProgress,
  type ProcedureResult,
  type ProceduresClient,
  type StartRequest,
} from "../../client/procedures";
import { state, type Scope, type State } from "../../lib/dom";
import { errorText, type Message } from "../ui";

export interface Where {
  bus: string;
  node: number;
  project: string;
  axis: string;
}

/** One procedure's run on this page. */
export interface Run {
  name: string;
  job: State<string | null>;
  progress: State<ProcedureProgress | null>;
  /** The last result (of this page's run, or a saved one opened from the list). */
  result: State<ProcedureResult | null>;
  /** How the last job ended. */
  ended: State<JobState | null>;
  message: State<Message | null>;
}

export type ControlClient = Pick<typeof controlApi, "get" | "arm" | "release" | "request" | "takeOver">;

export interface ProceduresModel {
  where: Where;
  live: LiveHub;
  client: ProceduresClient;
  control: ControlClient;
  /** null until the first answer. */
  procedures: State<ProcedureInfo[] | null>;
  listError: State<string | null>;
  /** Who holds the axis; null until the server answered. */
  holder: State<AxisControl | null>;
  askedBy: State<string | null>;
  busy: State<boolean>;
  runs: Map<string, Run>;
}

export function createModel(scope: Scope, live: LiveHub, where: Where,
  client: ProceduresClient = proceduresApi, control: ControlClient = controlApi): ProceduresModel {
  const model: ProceduresModel = {
    where, live, client, control,
    procedures: state<ProcedureInfo[] | null>(null),
    listError: state<string | null>(null),
    holder: state<AxisControl | null>(null),
    askedBy: state<string | null>(null),
    busy: state(false),
    runs: new Map(),
  };
  const ours = (event: { bus: unknown; node: unknown }) => event.bus === serverBus(where.bus) && event.node === where.node;
  scope.add(live.on("control", (event) => {
    if (!ours(event)) return;
    model.holder.val = { bus: event.bus, node: event.node, holder: event.holder, requests: event.requests };
    if (!heldByMe(model.holder.rawVal)) model.askedBy.val = null;
  }));
  scope.add(live.on("control_request", (event) => {
    if (ours(event)) model.askedBy.val = event.from.user;
  }));
  scope.add(live.on("ws_open", () => void refreshControl(model)));
  return model;
}

export function run(model: ProceduresModel, name: string): Run {
  let existing = model.runs.get(name);
  if (!existing) {
    existing = {
      name, job: state<string | null>(null), progress: state<ProcedureProgress | null>(null),
      result: state<ProcedureResult | null>(null), ended: state<JobState | null>(null), message: state<Message | null>(null),
    };
    model.runs.set(name, existing);
  }
  return existing;
}

/** The procedure as the drive lists it (tracked when read in a binding). */
export function infoOf(model: ProceduresModel, name: string): ProcedureInfo | undefined {
  return model.procedures.val?.find((procedure) => procedure.name === name);
}

export function armed(model: ProceduresModel): boolean {
  return heldByMe(model.holder.val);
}

/** The drive's procedures and their preconditions, read now. */
export async function refresh(model: ProceduresModel): Promise<void> {
  try {
    model.procedures.val = await model.client.list(model.where.bus, model.where.node);
    model.listError.val = null;
  } catch (error) {
    model.listError.val = errorText(error);
  }
}

export async function refreshControl(model: ProceduresModel): Promise<void> {
  try {
    model.holder.val = await model.control.get(model.where.bus, model.where.node);
  } catch {
    model.holder.val = null; // the bus is not open: the procedure list says so
  }
}

/** Start `name` as a server job, follow its progress and keep its result; a refusal shows in the run's message. */
export async function start(model: ProceduresModel, name: string, options: StartRequest["options"], verify = true): Promise<void> {
  const current = run(model, name);
  if (current.job.rawVal !== null) return;
  const { bus, node, project, axis } = model.where;
  current.message.val = null;
  current.progress.val = null;
  current.ended.val = null;
  current.job.val = "starting";
  try {
    const job = await runJob<ProcedureResult>(model.live, async () => {
      const started = await model.client.start(bus, node, name, { options, verify, project, axis });
      current.job.val = started.id;
      return started;
    }, (event) => {
      const progress = procedureProgress(event);
      if (progress) current.progress.val = progress;
    });
    current.ended.val = job.state;
    if (job.result) current.result.val = job.result;
    current.message.val = endMessage(job.state, job.error ?? null, job.result ?? null);
  } catch (error) {
    current.message.val = { text: errorText(error), tone: "error", testid: `${name}-refused` };
  } finally {
    current.job.val = null;
    await refresh(model);
  }
}

function endMessage(ended: JobState, error: string | null, result: ProcedureResult | null): Message | null {
  if (ended === "failed") return { text: error ?? "The procedure failed.", tone: "error", testid: "procedure-failed" };
  if (ended === "cancelled") {
    return { text: "Aborted: the drive is left disabled and the gains as they were before.", tone: "warn", testid: "procedure-aborted" };
  }
  if (result && result.status !== "done") return { text: `The drive reports: ${result.status}`, tone: "warn", testid: "procedure-status" };
  return null;
}

/** Abort the running job: the server writes 0 to the trigger and restores what the procedure changed. */
export async function abort(model: ProceduresModel, name: string): Promise<void> {
  const id = run(model, name).job.rawVal;
  if (id === null || id === "starting") return;
  try {
    await cancelJob(id);
  } catch (error) {
    run(model, name).message.val = { text: errorText(error), tone: "error", testid: "procedure-abort-failed" };
  }
}

/** Run a controller action (arm, release, …); its refusal shows in the procedure list's error line. */
export async function controlAction(model: ProceduresModel, action: keyof ControlClient): Promise<void> {
  model.busy.val = true;
  try {
    model.holder.val = await model.control[action](model.where.bus, model.where.node);
    if (action === "release") model.askedBy.val = null;
  } catch (error) {
    model.listError.val = `${action}: ${errorText(error)}`;
  } finally {
    model.busy.val = false;
  }
}
