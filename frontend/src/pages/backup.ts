/**
 * Backup and restore of one axis: the drive's files (DRIVEPAR.TXT, USER_PAR.TXT, SEQUENCE.TXT) to and from this
 * PC, the drive's values into the project and back, and "store to flash". Long runs show progress and can be
 * cancelled between objects.
 */

import { projectAddress, projects, request, setParametersSkipping } from "../client/api";
import { confirmAction, errorText, pickFile } from "../components/ui";
import { driveApi } from "../client/drives";
import { runJob, type JobInfo } from "../client/jobs";
import { h, replaceChildren } from "../lib/dom";
import { entries, isReadable, isWritable, type Entry } from "../lib/od";
import { unstorableReason } from "../lib/values";
import type { AxisContext, AxisViewPage } from "./axis";

const CHUNK = 40;

/** One file's restore result as the server reports it (`PUT …/files/{name}`). */
interface RestoreAnswer {
  ok: boolean;
  cancelled: boolean;
  counts: Record<string, number>;
  error: string | null;
  objects: { label: string; status: string; error: string }[];
}
/** 'save' as the U32 the drive expects at 0x1010,1 (CiA 301: little-endian ASCII). */
const SAVE_SIGNATURE = 0x65766173;

export async function backupView(context: AxisContext): Promise<AxisViewPage> {
  const { project, axis, dictionary } = context;
  const bus = axis.bus;
  const node = axis.node_id;
  const all = entries(dictionary);
  const saved = all.filter((entry) => entry.variable.save_type !== "NONE" && isReadable(entry.variable.access) && isWritable(entry.variable.access));
  const files = ["DRIVEPAR.TXT"];
  if (all.some((entry) => entry.variable.save_type === "USER_PAR")) files.push("USER_PAR.TXT");
  if (dictionary.objects.some((object) => /sequence/i.test(object.name) && object.index >= 0x3600 && object.index < 0x3700)) files.push("SEQUENCE.TXT");

  const progressArea = h("div", { "data-testid": "backup-progress" });
  const result = h("div", { "data-testid": "backup-result" });
  let running: AbortController | null = null;
  const buttons: HTMLButtonElement[] = [];
  const setBusy = (busy: boolean) => buttons.forEach((button) => (button.disabled = busy));

  /** Run `work` with a progress bar and a Cancel button; cancel stops at the next object. */
  /** What a run reports: its summary, marked as a warning when some objects were refused or unreadable. */
  type Outcome = { text: string; warning: boolean; cancelled?: boolean };
  const run = async (label: string, total: number, work: (signal: AbortSignal, step: (done: number, text?: string, newTotal?: number) => void) => Promise<Outcome>) => {
    const controller = new AbortController();
    running = controller;
    setBusy(true);
    const bar = h("progress", { max: String(Math.max(1, total)), value: "0" });
    const text = h("span", { class: "muted", style: { whiteSpace: "nowrap" } }, `${label}: 0 / ${total}`);
    replaceChildren(progressArea, h("div", { class: "progress-line" }, text, bar,
      h("button", { "data-testid": "backup-cancel", onclick: () => controller.abort() }, "Cancel")));
    replaceChildren(result);
    try {
      const outcome = await work(controller.signal, (done, extra, newTotal) => {
        if (newTotal !== undefined) {
          total = newTotal;
          bar.max = Math.max(1, total);
        }
        bar.value = done;
        text.textContent = `${label}: ${done} / ${total}${extra ? ` · ${extra}` : ""}`;
      });
      // A server job may have ended before Cancel reached it: then it says it was not cancelled.
      const cancelled = outcome.cancelled ?? controller.signal.aborted;
      replaceChildren(result, h("div", { class: `message ${cancelled || outcome.warning ? "warn" : "ok"}` }, cancelled ? `${label} cancelled. ${outcome.text}` : outcome.text));
    } catch (error) {
      replaceChildren(result, h("div", { class: "message error" }, `${label}: ${errorText(error)}`));
    } finally {
      running = null;
      setBusy(false);
      replaceChildren(progressArea);
    }
  };

  const backupToProject = () => run("Reading the drive", saved.length, async (signal, step) => {
    const values: Record<string, number | string> = {};
    const failed: string[] = [];
    const refused: string[] = [];
    for (let start = 0; start < saved.length && !signal.aborted; start += CHUNK) {
      const chunk = saved.slice(start, start + CHUNK);
      const read = await driveApi.readMany(bus, node, chunk.map((e) => [e.object.index, e.variable.subindex]), signal);
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
      text: `${stored} values of node ${node} stored in project ${project.name} (${answer.parameters.length} changed).`
        + (refused.length ? ` ${refused.length} the project cannot hold: ${refused.slice(0, 3).join("; ")}.` : "")
        + (failed.length ? ` ${failed.length} could not be read: ${failed.slice(0, 3).join("; ")}.` : ""),
      warning: refused.length > 0 || failed.length > 0,
    };
  });

  const restoreFromProject = async () => {
    const rows = (await projects.parameters(project.name, axis.name)).parameters.filter((row) => row.file !== null && row.value !== null);
    const byKey = new Map(all.map((entry) => [entry.key, entry]));
    const writes = rows.map((row) => ({ row, entry: byKey.get(`${row.index}.${row.subindex}`) })).filter((w): w is { row: typeof rows[number]; entry: Entry } => Boolean(w.entry && isWritable(w.entry.variable.access)));
    if (!(await confirmAction("Restore project to drive", `Write ${writes.length} project values into node ${node} on ${bus}? The drive's current values are overwritten.`, "Write to drive", true))) return;
    await run("Writing the drive", writes.length, async (signal, step) => {
      const failed: string[] = [];
      let written = 0;
      for (const [position, { row, entry }] of writes.entries()) {
        if (signal.aborted) break;
        try {
          await driveApi.write(bus, node, entry.object.index, entry.variable.subindex, row.value as number | string);
          written++;
        } catch (error) {
          failed.push(`${projectAddress(row.index, row.subindex)}: ${errorText(error)}`);
        }
        step(position + 1, failed.length ? `${failed.length} refused` : "");
      }
      return {
        text: `${written} values written to node ${node}.${failed.length ? ` ${failed.length} refused: ${failed.slice(0, 3).join("; ")}.` : ""} Store to flash to keep them after a power cycle.`,
        warning: failed.length > 0,
      };
    });
  };

  const storeToFlash = () => run("Storing to flash", 1, async (_signal, step) => {
    await driveApi.write(bus, node, 0x1010, 1, SAVE_SIGNATURE);
    step(1);
    return { text: `Node ${node} stored its parameters to flash (0x1010,1 = 'save').`, warning: false };
  });

  const downloadFile = (name: string) => run(`Backing up ${name}`, 1, async (signal, step) => {
    const response = await fetch(driveApi.fileUrl(bus, node, name), { signal });
    if (!response.ok) throw new Error((await response.json().catch(() => ({ detail: `HTTP ${response.status}` }))).detail);
    const text = await response.text();
    const url = URL.createObjectURL(new Blob([text], { type: "text/plain" }));
    const link = h("a", { href: url, download: `${axis.name}_${name}` });
    document.body.append(link);
    link.click();
    link.remove();
    URL.revokeObjectURL(url);
    step(1);
    return { text: `${name} of node ${node} saved as ${axis.name}_${name} (${text.split("\n").length} lines).`, warning: false };
  });

  const restoreFile = async (name: string) => {
    const file = await pickFile(".txt,.TXT");
    if (!file) return;
    if (!(await confirmAction(`Restore ${name}`, `Send ${file.name} to node ${node} as ${name}? It is validated first, then written, verified and stored to flash.`, "Restore", true))) return;
    const text = await file.text();
    // A server job: its progress comes as events and Cancel stops it on the server at the next object.
    await run(`Restoring ${name}`, 1, async (signal, step) => {
      const job = await runJob<Record<string, RestoreAnswer[]>>(context.page.app.live,
        () => request<JobInfo<Record<string, RestoreAnswer[]>>>("PUT", `${driveApi.fileUrl(bus, node, name)}?job=true`,
          new Blob([text], { type: "text/plain" })),
        (event) => step(Number(event.done) || 0, String(event.file ?? ""), Number(event.total) || 1), signal);
      const answer = job.result?.[String(node)]?.[0];
      if (!answer) throw new Error(job.error ?? `the restore job ended ${job.state}`);
      const counts = Object.entries(answer.counts).map(([status, count]) => `${count} ${status}`).join(", ");
      if (answer.cancelled) return { text: `${answer.error ?? ""} (${counts}).`, warning: true, cancelled: true };
      if (!answer.ok) throw new Error(`${answer.error ?? "not all objects verified"} (${counts}) ${answer.objects.slice(0, 3).map((o) => `${o.label}: ${o.error}`).join("; ")}`);
      return { text: `${name} restored to node ${node}: ${counts}.`, warning: false, cancelled: false };
    });
  };

  const button = (label: string, onclick: () => unknown, testid: string, primary = false) => {
    const element = h("button", { class: primary ? "primary" : "", "data-testid": testid, onclick: () => void onclick() }, label);
    buttons.push(element);
    return element;
  };

  return {
    dispose: () => running?.abort(),
    element: h("div", { class: "page" },
      progressArea, result,
      h("div", { class: "grid cols-2" },
        h("section", { class: "panel" }, h("h2", null, "Drive ⇄ project"),
          h("div", { class: "panel-body grid", style: { gap: "8px" } },
            h("div", { class: "muted" }, `${saved.length} saved objects of ${dictionary.product_name} (DRIVEPAR/USER_PAR), node ${node} on ${bus}, project ${project.name}.`),
            h("div", { class: "toolbar" },
              button("Back up drive into project", backupToProject, "backup-to-project", true),
              button("Restore project to drive…", restoreFromProject, "restore-from-project")),
            h("div", { class: "toolbar" }, button("Store parameters to flash", storeToFlash, "store-flash"),
              h("span", { class: "muted" }, "0x1010,1 = 'save': the drive keeps its values after a power cycle")))),
        h("section", { class: "panel" }, h("h2", null, "Drive files ⇄ this PC"),
          h("table", { class: "data" }, h("tbody", null, files.map((name) => h("tr", null,
            h("td", { class: "mono" }, name),
            h("td", null, h("span", { class: "toolbar" },
              button("Back up to PC", () => downloadFile(name), `download-${name}`),
              button("Restore from PC…", () => restoreFile(name), `upload-${name}`)))))))))),
  };
}
