/**
 * Backup and restore of one axis: the drive's files (DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT) to and from this
 * PC, the drive's values into the project and back, and "store to flash". Long runs show progress and can be
 * cancelled between objects.
 */

import { errorOf, projectAddress, projects, request, setParametersSkipping } from "../client/api";
import { driveApi } from "../client/drives";
import { runJob, type JobInfo } from "../client/jobs";
import type { RestoreResult } from "../client/messages";
import { confirmAction, errorText, messageView, pickFile, type Message } from "../components/ui";
import { h, state, type State } from "../lib/dom";
import { entries, isReadable, isWritable, type Dictionary, type Entry } from "../lib/od";
import { unstorableReason } from "../lib/values";
import type { AxisContext, AxisViewPage } from "./axis";

const CHUNK = 40;
/** 'save' as the U32 the drive expects at 0x1010,1 (CiA 301: little-endian ASCII). */
const SAVE_SIGNATURE = 0x65766173;

/** What a run reports: its summary, marked as a warning when some objects were refused or unreadable. */
interface Outcome {
  text: string;
  warning: boolean;
  /** Set by a server job, which knows whether Cancel reached it before it ended. */
  cancelled?: boolean;
}

/** Report progress: objects done, an extra text, and a new total when the work learns it on the way. */
type Step = (done: number, extra?: string, total?: number) => void;
type Work = (signal: AbortSignal, step: Step) => Promise<Outcome>;

interface Run {
  label: string;
  controller: AbortController;
  progress: State<{ done: number; total: number; extra: string }>;
}

interface BackupView {
  context: AxisContext;
  bus: string;
  node: number;
  running: State<Run | null>;
  result: State<Message | null>;
}

export async function backupView(context: AxisContext): Promise<AxisViewPage> {
  const { project, axis, dictionary } = context;
  const view: BackupView = { context, bus: axis.bus, node: axis.node_id, running: state<Run | null>(null), result: state<Message | null>(null) };
  const saved = savedEntries(dictionary);
  const button = (label: string, action: () => Promise<void>, testid: string, primary = false) =>
    h("button", { class: primary ? "primary" : "", "data-testid": testid, disabled: () => view.running.val !== null, onclick: () => void action() }, label);
  return {
    dispose: () => view.running.rawVal?.controller.abort(),
    element: h("div", { class: "page" },
      h("div", { "data-testid": "backup-progress" }, () => progressLine(view.running.val)),
      h("div", { "data-testid": "backup-result" }, messageView(view.result)),
      h("div", { class: "grid cols-2" },
        h("section", { class: "panel" }, h("h2", null, "Drive ⇄ project"),
          h("div", { class: "panel-body grid", style: { gap: "8px" } },
            h("div", { class: "muted" }, `${saved.length} saved objects of ${dictionary.product_name} (DRIVEPAR/USER_PAR), node ${view.node} on ${view.bus}, project ${project.name}.`),
            h("div", { class: "toolbar" },
              button("Back up drive into project", () => run(view, "Reading the drive", saved.length, backupToProject(view, saved)), "backup-to-project", true),
              button("Restore project to drive…", () => restoreFromProject(view), "restore-from-project")),
            h("div", { class: "toolbar" }, button("Store parameters to flash", () => run(view, "Storing to flash", 1, storeToFlash(view)), "store-flash"),
              h("span", { class: "muted" }, "0x1010,1 = 'save': the drive keeps its values after a power cycle")))),
        h("section", { class: "panel" }, h("h2", null, "Drive files ⇄ this PC"),
          h("table", { class: "data" }, h("tbody", null, driveFiles(dictionary).map((name) => h("tr", null,
            h("td", { class: "mono" }, name),
            h("td", null, h("span", { class: "toolbar" },
              button("Back up to PC", () => run(view, `Backing up ${name}`, 1, downloadFile(view, name)), `download-${name}`),
              button("Restore from PC…", () => restoreFile(view, name), `upload-${name}`)))))))))),
  };
}

/** The entries a backup reads: saved (DRIVEPAR/USER_PAR), readable and writable. */
function savedEntries(dictionary: Dictionary): Entry[] {
  return entries(dictionary).filter((entry) => entry.variable.save_type !== "NONE" && isReadable(entry.variable.access) && isWritable(entry.variable.access));
}

/** The drive's own files the device has. */
export function driveFiles(dictionary: Dictionary): string[] {
  const files = ["DRIVEPAR.TXT"];
  if (entries(dictionary).some((entry) => entry.variable.save_type === "USER_PAR")) files.push("USER_PAR.TXT");
  if (dictionary.objects.some((object) => /sequence/i.test(object.name) && object.index >= 0x3600 && object.index < 0x3700)) files.push("SEQUENCE.TXT");
  return files;
}

function progressLine(current: Run | null): HTMLElement | null {
  if (!current) return null;
  const { label, progress, controller } = current;
  return h("div", { class: "progress-line" },
    h("span", { class: "muted", style: { whiteSpace: "nowrap" } }, () => {
      const { done, total, extra } = progress.val;
      return `${label}: ${done} / ${total}${extra ? ` · ${extra}` : ""}`;
    }),
    h("progress", { max: () => Math.max(1, progress.val.total), value: () => progress.val.done }),
    h("button", { "data-testid": "backup-cancel", onclick: () => controller.abort() }, "Cancel"));
}

/** Run `work` with a progress bar and a Cancel button; cancel stops at the next object. */
async function run(view: BackupView, label: string, total: number, work: Work): Promise<void> {
  const progress = state({ done: 0, total, extra: "" });
  const controller = new AbortController();
  view.running.val = { label, controller, progress };
  view.result.val = null;
  try {
    const outcome = await work(controller.signal, (done, extra, newTotal) => {
      progress.val = { done, total: newTotal ?? progress.rawVal.total, extra: extra ?? "" };
    });
    // A server job may have ended before Cancel reached it: then it says it was not cancelled.
    const cancelled = outcome.cancelled ?? controller.signal.aborted;
    view.result.val = { text: cancelled ? `${label} cancelled. ${outcome.text}` : outcome.text, tone: cancelled || outcome.warning ? "warn" : "ok" };
  } catch (error) {
    view.result.val = { text: `${label}: ${errorText(error)}`, tone: "error" };
  } finally {
    view.running.val = null;
  }
}

/** Read the saved entries from the drive in chunks, then store them in the project (what it cannot hold is listed). */
function backupToProject(view: BackupView, saved: Entry[]): Work {
  const { project, axis } = view.context;
  return async (signal, step) => {
    const values: Record<string, number | string> = {};
    const failed: string[] = [];
    const refused: string[] = [];
    for (let start = 0; start < saved.length && !signal.aborted; start += CHUNK) {
      const chunk = saved.slice(start, start + CHUNK);
      const read = await driveApi.readMany(view.bus, view.node, chunk.map((e) => [e.object.index, e.variable.subindex]), signal);
      for (const [position, value] of read.entries()) {
        const label = projectAddress(value.index, value.subindex);
        const refusal = value.error ? null : unstorableReason(chunk[position].variable, value.raw);
        if (value.error || value.raw === null) failed.push(`${label}: ${value.error}`);
        else if (refusal) refused.push(`${label}: ${refusal}`);
        else values[label] = value.raw;
      }
      step(Math.min(saved.length, start + CHUNK));
    }
    if (signal.aborted) return { text: "Nothing was stored in the project.", warning: true };
    const answer = await setParametersSkipping(project.name, axis.name, values);
    refused.push(...answer.skipped);
    const stored = Object.keys(values).length - answer.skipped.length;
    return {
      text: `${stored} values of node ${view.node} stored in project ${project.name} (${answer.parameters.length} changed).`
        + (refused.length ? ` ${refused.length} the project cannot hold: ${refused.slice(0, 3).join("; ")}.` : "")
        + (failed.length ? ` ${failed.length} could not be read: ${failed.slice(0, 3).join("; ")}.` : ""),
      warning: refused.length > 0 || failed.length > 0,
    };
  };
}

/** Write every value the project files set into the drive, one by one (refusals are counted and listed). */
async function restoreFromProject(view: BackupView): Promise<void> {
  const { project, axis, dictionary } = view.context;
  const rows = (await projects.parameters(project.name, axis.name)).parameters.filter((row) => row.file !== null && row.value !== null);
  const byKey = new Map(entries(dictionary).map((entry) => [entry.key, entry]));
  const writes = rows.flatMap((row) => {
    const entry = byKey.get(`${row.index}.${row.subindex}`);
    return entry && isWritable(entry.variable.access) ? [{ row, entry }] : [];
  });
  if (!(await confirmAction("Restore project to drive", `Write ${writes.length} project values into node ${view.node} on ${view.bus}? The drive's current values are overwritten.`, "Write to drive", true))) return;
  await run(view, "Writing the drive", writes.length, async (signal, step) => {
    const failed: string[] = [];
    let written = 0;
    for (const [position, { row, entry }] of writes.entries()) {
      if (signal.aborted) break;
      try {
        await driveApi.write(view.bus, view.node, entry.object.index, entry.variable.subindex, row.value as number | string);
        written++;
      } catch (error) {
        failed.push(`${projectAddress(row.index, row.subindex)}: ${errorText(error)}`);
      }
      step(position + 1, failed.length ? `${failed.length} refused` : "");
    }
    return {
      text: `${written} values written to node ${view.node}.${failed.length ? ` ${failed.length} refused: ${failed.slice(0, 3).join("; ")}.` : ""} Store to flash to keep them after a power cycle.`,
      warning: failed.length > 0,
    };
  });
}

function storeToFlash(view: BackupView): Work {
  return async (_signal, step) => {
    await driveApi.write(view.bus, view.node, 0x1010, 1, SAVE_SIGNATURE);
    step(1);
    return { text: `Node ${view.node} stored its parameters to flash (0x1010,1 = 'save').`, warning: false };
  };
}

/** Save one of the drive's files on this PC as `<axis>_<file>`. */
function downloadFile(view: BackupView, name: string): Work {
  const axis = view.context.axis;
  return async (signal, step) => {
    const url = driveApi.fileUrl(view.bus, view.node, name);
    const response = await fetch(url, { signal });
    if (!response.ok) throw await errorOf(url, response);
    const text = await response.text();
    const saved = URL.createObjectURL(new Blob([text], { type: "text/plain" }));
    const link = h("a", { href: saved, download: `${axis.name}_${name}` });
    document.body.append(link);
    link.click();
    link.remove();
    URL.revokeObjectURL(saved);
    step(1);
    return { text: `${name} of node ${view.node} saved as ${axis.name}_${name} (${text.split("\n").length} lines).`, warning: false };
  };
}

/** Restore one of the drive's files from this PC: a server job (validated, written, verified, stored). */
async function restoreFile(view: BackupView, name: string): Promise<void> {
  const file = await pickFile(".txt,.TXT");
  if (!file) return;
  if (!(await confirmAction(`Restore ${name}`, `Send ${file.name} to node ${view.node} as ${name}? It is validated first, then written, verified and stored to flash.`, "Restore", true))) return;
  const text = await file.text();
  // Its progress comes as events and Cancel stops it on the server at the next object.
  await run(view, `Restoring ${name}`, 1, async (signal, step) => {
    const job = await runJob<RestoreResult>(view.context.page.app.live,
      () => request<JobInfo<RestoreResult>>("PUT", `${driveApi.fileUrl(view.bus, view.node, name)}?job=true`, new Blob([text], { type: "text/plain" })),
      (event) => step(Number(event.done) || 0, String(event.file ?? ""), Number(event.total) || 1), signal);
    const answer = job.result?.[String(view.node)]?.[0];
    if (!answer) throw new Error(job.error ?? `the restore job ended ${job.state}`);
    const counts = Object.entries(answer.counts).map(([status, count]) => `${count} ${status}`).join(", ");
    if (answer.cancelled) return { text: `${answer.error ?? ""} (${counts}).`, warning: true, cancelled: true };
    if (!answer.ok) throw new Error(`${answer.error ?? "not all objects verified"} (${counts}) ${answer.objects.slice(0, 3).map((o) => `${o.label}: ${o.error}`).join("; ")}`);
    return { text: `${name} restored to node ${view.node}: ${counts}.`, warning: false, cancelled: false };
  });
}
