/**
 * Backup and restore of one axis: the drive's files (DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT; a TTA-PRO's TTAPAR.TXT,
 * TTASEQ.TXT) to and from this PC, the drive's values into the project and back, and "store parameters" (the
 * device's own save). Long runs show progress and can be cancelled between objects.
 */

import { errorOf, projectAddress, projects, request, setParametersSkipping, type KeptRevision, type ProjectParameter } from "../client/api";
import { driveApi } from "../client/drives";
import { runJob, type JobInfo } from "../client/jobs";
import type { RestoreResult } from "../client/messages";
import { confirmChanges, type Change } from "../components/confirm/changes";
import { confirmAction, errorText, messageView, pickFile, type Message } from "../components/ui";
import { h, state, type State } from "../lib/dom";
import { objectFiles } from "../lib/objectfile";
import { entries, entryKey, isReadable, isWritable, type Dictionary, type Entry, type Scalar } from "../lib/od";
import { formatValue, sameValue, unstorableReason } from "../lib/values";
import type { AxisContext, AxisViewPage } from "./axis";

const CHUNK = 40;

/** What a run reports: its summary, marked as a warning when some objects were refused or unreadable. */
interface Outcome {
  text: string;
  warning: boolean;
  /** Every entry the text counts but does not name (values left out and why), listed under the message. */
  notes?: string[];
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
  notes: State<string[]>;
  /** The project's newest kept revision (what the last backup into the project replaced). */
  kept: State<KeptRevision | null>;
}

export async function backupView(context: AxisContext): Promise<AxisViewPage> {
  const { project, axis, dictionary } = context;
  const view: BackupView = {
    context, bus: axis.bus, node: axis.node_id, running: state<Run | null>(null), result: state<Message | null>(null),
    notes: state<string[]>([]), kept: state<KeptRevision | null>(null),
  };
  void loadKept(view);
  const saved = savedEntries(dictionary);
  const button = (label: string, action: () => Promise<void>, testid: string, primary = false) =>
    h("button", { class: primary ? "primary" : "", "data-testid": testid, disabled: () => view.running.val !== null, onclick: () => void action() }, label);
  return {
    dispose: () => view.running.rawVal?.controller.abort(),
    element: h("div", { class: "page" },
      h("div", { "data-testid": "backup-progress" }, () => progressLine(view.running.val)),
      h("div", { "data-testid": "backup-result" }, messageView(view.result)),
      h("div", null, () => (view.notes.val.length ? h("ul", { class: "muted", "data-testid": "backup-notes" }, view.notes.val.map((note) => h("li", null, note))) : null)),
      h("div", { class: "grid cols-2" },
        h("section", { class: "panel" }, h("h2", null, "Drive ⇄ project"),
          h("div", { class: "panel-body grid", style: { gap: "8px" } },
            h("div", { class: "muted" }, `${saved.length} saved objects of ${dictionary.product_name}, node ${view.node} on ${view.bus}, project ${project.name}.`),
            h("div", { class: "toolbar" },
              button("Back up drive into project", () => run(view, "Reading the drive", saved.length, backupToProject(view, saved)), "backup-to-project", true),
              button("Restore project to drive…", () => restoreFromProject(view), "restore-from-project")),
            h("div", null, () => keptLine(view, button)),
            storeLine(view, dictionary, button))),
        h("section", { class: "panel" }, h("h2", null, "Drive files ⇄ this PC"),
          h("table", { class: "data" }, h("tbody", null, dictionary.files.map((name) => h("tr", null,
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
  view.notes.val = [];
  try {
    const outcome = await work(controller.signal, (done, extra, newTotal) => {
      progress.val = { done, total: newTotal ?? progress.rawVal.total, extra: extra ?? "" };
    });
    // A server job may have ended before Cancel reached it: then it says it was not cancelled.
    const cancelled = outcome.cancelled ?? controller.signal.aborted;
    view.result.val = { text: cancelled ? `${label} cancelled. ${outcome.text}` : outcome.text, tone: cancelled || outcome.warning ? "warn" : "ok" };
    view.notes.val = outcome.notes ?? [];
  } catch (error) {
    view.result.val = { text: `${label}: ${errorText(error)}`, tone: "error" };
  } finally {
    view.running.val = null;
  }
}

/**
 * Read the saved entries from the drive in chunks, show what storing them changes in the project and ask, then store
 * them keeping the project's previous revision restorable; what the project cannot hold is left out and listed.
 */
function backupToProject(view: BackupView, saved: Entry[]): Work {
  const { project, axis } = view.context;
  return async (signal, step) => {
    const read = await readSaved(view, saved, signal, step);
    if (signal.aborted) return { text: "Nothing was stored in the project.", warning: true };
    const current = (await projects.parameters(project.name, axis.name)).parameters;
    const changes = projectChanges(saved, read.values, current);
    if (!(await confirmBackup(view, read, changes))) return { text: "Nothing was stored: the project is unchanged.", warning: false, cancelled: true };
    const answer = await setParametersSkipping(project.name, axis.name, read.values, true);
    const refused = [...read.refused, ...answer.skipped];
    const stored = Object.keys(read.values).length - answer.skipped.length;
    await loadKept(view);
    const left = refused.length ? ` ${refused.length} drive values the project cannot hold were left out (listed below).` : "";
    const failed = read.failed.length ? ` ${read.failed.length} could not be read (listed below).` : "";
    return {
      text: `${stored} values of node ${view.node} stored in project ${project.name}: ${changes.length} changed.${left}${failed}`
        + (view.kept.rawVal ? ` The previous project revision ${view.kept.rawVal.revision} is kept: restore it below.` : ""),
      warning: read.failed.length > 0,
      notes: [...refused.map((text) => `left out: ${text}`), ...read.failed.map((text) => `not read: ${text}`)],
    };
  };
}

interface SavedValues {
  values: Record<string, number | string>;
  failed: string[];
  refused: string[];
}

async function readSaved(view: BackupView, saved: Entry[], signal: AbortSignal, step: Step): Promise<SavedValues> {
  const result: SavedValues = { values: {}, failed: [], refused: [] };
  for (let start = 0; start < saved.length && !signal.aborted; start += CHUNK) {
    const chunk = saved.slice(start, start + CHUNK);
    const read = await driveApi.readMany(view.bus, view.node, chunk.map((e) => [e.object.index, e.variable.subindex]), signal);
    for (const [position, value] of read.entries()) {
      const label = projectAddress(value.index, value.subindex);
      const refusal = value.error ? null : unstorableReason(chunk[position].variable, value.raw);
      if (value.error || value.raw === null) result.failed.push(`${label}: ${value.error}`);
      else if (refusal) result.refused.push(`${label}: ${refusal}`);
      else result.values[label] = value.raw;
    }
    step(Math.min(saved.length, start + CHUNK));
  }
  return result;
}

/** The project values a backup replaces (project value → drive value), in dictionary order. */
export function projectChanges(saved: Entry[], values: Record<string, number | string>, current: ProjectParameter[]): Change[] {
  const rows = new Map(current.map((row) => [entryKey(row.index, row.subindex), row]));
  const text = (entry: Entry, raw: Scalar) => `${formatValue(entry.variable, raw)} ${entry.variable.unit}`.trim();
  return saved.flatMap((entry) => {
    const raw = values[projectAddress(entry.object.index, entry.variable.subindex)];
    const row = rows.get(entry.key);
    if (raw === undefined || (row && sameValue(row.value, raw))) return [];
    const old = row && row.value !== null ? text(entry, row.value) : "not set";
    return [{ address: projectAddress(entry.object.index, entry.variable.subindex), name: entry.variable.name, old, new: text(entry, raw) }];
  });
}

function confirmBackup(view: BackupView, read: SavedValues, changes: Change[]): Promise<boolean> {
  const count = Object.keys(read.values).length;
  return confirmChanges({
    title: "Back up drive into project", confirm: `Store ${count} values in the project`, changes, folded: true,
    text: `Store the ${count} values read from node ${view.node} in project ${view.context.project.name}? ${changes.length} project values change (project → drive), ${count - changes.length} are the same already.`,
    notes: [
      "The project as it is now is kept as a revision: you can restore it afterwards.",
      ...(read.refused.length ? [`${read.refused.length} drive values the project cannot hold are left out; they are listed afterwards.`] : []),
      ...(read.failed.length ? [`${read.failed.length} entries the drive did not answer are left out; they are listed afterwards.`] : []),
    ],
  });
}

async function loadKept(view: BackupView): Promise<void> {
  try {
    view.kept.val = (await projects.revisions(view.context.project.name))[0] ?? null;
  } catch {
    view.kept.val = null;
  }
}

type Button = (label: string, action: () => Promise<void>, testid: string, primary?: boolean) => HTMLElement;

function keptLine(view: BackupView, button: Button): HTMLElement | null {
  const kept = view.kept.val;
  if (!kept) return null;
  const when = new Date(kept.saved_at * 1000).toLocaleString();
  return h("div", { class: "toolbar" },
    button("Restore previous project revision…", () => restoreKept(view, kept), "restore-revision"),
    h("span", { class: "muted", "data-testid": "kept-revision" }, `revision ${kept.revision}, replaced ${when} (${kept.reason})`));
}

async function restoreKept(view: BackupView, kept: KeptRevision): Promise<void> {
  const name = view.context.project.name;
  if (!(await confirmAction("Restore previous project revision", `Make project ${name} what it was before: revision ${kept.revision} (replaced by: ${kept.reason})? The project as it is now is kept as a revision in turn.`, "Restore revision"))) return;
  await run(view, "Restoring the project", 1, async (_signal, step) => {
    const restored = await projects.restoreRevision(name, kept.revision);
    step(1);
    await loadKept(view);
    return { text: `Project ${name} restored to revision ${restored.revision}.`, warning: false };
  });
}

/**
 * Restore the values the project sets to the drive as its own files (DRIVEPAR.TXT, USER_PAR.TXT), each one server
 * job — validated, written, verified and stored, the path of `servostudio restore` (issue #14 point 5: one REST
 * write per value took 5.7 s for 370 values; the job takes about a second).
 */
async function restoreFromProject(view: BackupView): Promise<void> {
  const { project, axis } = view.context;
  const { files, left } = objectFiles((await projects.parameters(project.name, axis.name)).parameters);
  const names = [...files.keys()];
  if (names.length === 0) return void (view.result.val = { text: `Project ${project.name} sets no value of axis ${axis.name}.`, tone: "warn" });
  if (!(await confirmAction("Restore project to drive", `Write the project's ${names.join(" and ")} of axis ${axis.name} into node ${view.node} on ${view.bus} and store them to flash? They are validated first; the drive's current values are overwritten.`, "Write to drive", true))) return;
  await run(view, "Writing the drive", 1, async (signal, step) => {
    const done: string[] = [];
    for (const [name, text] of files) {
      const outcome = await restoreJob(view, name, text, signal, step);
      done.push(outcome.text);
      if (outcome.cancelled) return { ...outcome, text: done.join(" ") };
    }
    const note = left.length ? ` ${left.length} values no file can carry were left out: ${left.slice(0, 3).join("; ")}.` : "";
    return { text: done.join(" ") + note, warning: left.length > 0, cancelled: false };
  });
}

/** "Store parameters": the device's own save, as the dictionary names it (none: no button). */
function storeLine(view: BackupView, dictionary: Dictionary, button: Button): HTMLElement | null {
  if (!dictionary.store) return null;
  return h("div", { class: "toolbar" }, button("Store parameters in the drive", () => run(view, "Storing the parameters", 1, storeParameters(view)), "store-flash"),
    h("span", { class: "muted", "data-testid": "store-action" }, `${dictionary.store}: the drive keeps the values it holds now after a power cycle`));
}

function storeParameters(view: BackupView): Work {
  return async (_signal, step) => {
    const answer = await driveApi.store(view.bus, view.node);
    step(1);
    return { text: `Node ${view.node} stored its parameters (${answer.wrote}).`, warning: false };
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
  await run(view, `Restoring ${name}`, 1, (signal, step) => restoreJob(view, name, text, signal, step));
}

/** One drive file restored by a server job; its progress comes as events and Cancel stops it at the next object. */
async function restoreJob(view: BackupView, name: string, text: string, signal: AbortSignal, step: Step): Promise<Outcome> {
  const job = await runJob<RestoreResult>(view.context.page.app.live,
    () => request<JobInfo<RestoreResult>>("PUT", `${driveApi.fileUrl(view.bus, view.node, name)}?job=true`, new Blob([text], { type: "text/plain" })),
    (event) => step(Number(event.done) || 0, String(event.file ?? ""), Number(event.total) || 1), signal);
  const answer = job.result?.[String(view.node)]?.[0];
  if (!answer) throw new Error(job.error ?? `the restore job ended ${job.state}`);
  const counts = Object.entries(answer.counts).map(([status, count]) => `${count} ${status}`).join(", ");
  if (answer.cancelled) return { text: `${answer.error ?? ""} (${counts}).`, warning: true, cancelled: true };
  if (!answer.ok) throw new Error(`${answer.error ?? "not all objects verified"} (${counts}) ${answer.objects.slice(0, 3).map((o) => `${o.label}: ${o.error}`).join("; ")}`);
  return { text: `${name} restored to node ${view.node}: ${counts}.`, warning: false, cancelled: false };
}
