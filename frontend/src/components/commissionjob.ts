/**
 * Project-wide commissioning as a server job (`POST /api/projects/{p}/commission`): check every axis's drive,
 * upload the drives into the project, or download the project into the drives. Progress and the final report
 * arrive as `progress` and `job` events on `/api/ws/events`; the panel shows one progress bar per axis. Cancel asks
 * the server to stop the job at the next object (download) or file (upload); the report then says what was done.
 */

import type { App } from "../app";
import { post } from "../client/api";
import { cancelJob, runJob, type JobInfo } from "../client/jobs";
import type { CommissionResult, EventMap } from "../client/messages";
import { h, state, type Child, type State } from "../lib/dom";
import { confirmAction, errorText } from "./ui";

type CommissionJob = JobInfo<CommissionResult>;

const DIRECTIONS: [string, string, string][] = [
  ["check", "Check drives", "Identify every axis's drive (bus open, node answers, right device)."],
  ["upload", "Upload drives → project", "Read every drive's parameter files into the project's axis files."],
  ["download", "Download project → drives", "Write the project's files into the drives: validated, written, verified, stored to flash."],
];

/** One axis's progress bar. */
export interface AxisProgress {
  axis: string;
  bar: State<{ done: number; total: number; text: string }>;
}

/** What the panel shows under its buttons: a line, the progress bars of a running job, or the report. */
export type CommissionStatus =
  | { kind: "idle" }
  | { kind: "line"; text: string; tone: "muted" | "error"; testid?: string }
  | { kind: "running"; text: string; axes: State<AxisProgress[]> }
  | { kind: "report"; job: CommissionJob };

export function commissionPanel(app: App, project: string, onDone: () => void): HTMLElement {
  const status = state<CommissionStatus>({ kind: "idle" });
  const job = state<string | null>(null);
  const busy = state(false);
  const start = async (direction: string, label: string) => {
    if (direction === "download" && !(await confirmAction(label, `Write the files of project ${project} into every axis's drive and store them to flash? The drives' current values are overwritten.`, "Download", true))) return;
    busy.val = true;
    const axes = state<AxisProgress[]>([]);
    status.val = { kind: "line", text: `${label}: starting…`, tone: "muted" };
    try {
      const ended = await runJob<CommissionResult>(app.live, async () => {
        const started = await post<CommissionJob>(`/api/projects/${encodeURIComponent(project)}/commission`, { direction });
        job.val = started.id;
        status.val = { kind: "running", text: `${label}: job ${started.id} running`, axes };
        return started;
      }, (event) => followProgress(axes, event as EventMap["progress"]));
      status.val = { kind: "report", job: ended };
      if (ended.state !== "failed" && ended.result) onDone();
    } catch (error) {
      status.val = { kind: "line", text: errorText(error), tone: "error", testid: "commission-result" };
    } finally {
      job.val = null;
      busy.val = false;
    }
  };
  const cancel = h("button", {
    "data-testid": "commission-cancel", disabled: () => job.val === null, title: "Stop the job at the next object or file",
    onclick: () => {
      const id = job.rawVal;
      job.val = null;
      if (id !== null) void cancelJob(id).catch((error) => (status.val = { kind: "line", text: errorText(error), tone: "error" }));
    },
  }, "Cancel");
  const buttons = DIRECTIONS.map(([direction, label, title]) => h("button", {
    class: direction === "download" ? "danger" : "", title, "data-testid": `commission-${direction}`, disabled: busy,
    onclick: () => void start(direction, label),
  }, label));
  return h("section", { class: "panel" }, h("h2", null, "Commission all axes"),
    h("div", { class: "panel-body", "data-testid": "commission-panel" },
      h("div", { class: "toolbar" }, buttons, cancel, h("span", { class: "muted" }, "All axes in parallel; progress per axis.")),
      h("div", { class: "grid", style: { gap: "6px", marginTop: "8px" } }, () => statusView(status.val))));
}

/** Apply one progress event of the job: a step of the whole job (every axis) or the files of one axis. */
export function followProgress(axes: State<AxisProgress[]>, event: EventMap["progress"]): void {
  const barOf = (axis: string) => {
    let entry = axes.rawVal.find((candidate) => candidate.axis === axis);
    if (!entry) {
      entry = { axis, bar: state({ done: 0, total: 1, text: "waiting" }) };
      axes.val = [...axes.rawVal, entry];
    }
    return entry.bar;
  };
  if (event.operation === "commission") {
    for (const { axis } of event.axes ?? []) {
      const bar = barOf(axis);
      bar.val = { ...bar.rawVal, text: `${String(event.step)}…` };
    }
    return;
  }
  const bar = barOf(typeof event.axis === "string" ? event.axis : `node ${String(event.node)}`);
  bar.val = {
    done: Number(event.done) || 0,
    total: Math.max(1, Number(event.total) || 1),
    text: `${event.operation} ${String(event.file ?? "")} ${String(event.done)}/${String(event.total)}`,
  };
}

function statusView(status: CommissionStatus): Child {
  switch (status.kind) {
    case "idle":
      return null;
    case "line":
      return h("div", { class: status.tone === "error" ? "message error" : "muted", "data-testid": status.testid }, status.text);
    case "running":
      return [h("div", { class: "muted" }, status.text),
        h("div", { class: "grid", style: { gap: "6px" } }, () => status.axes.val.map(progressLine))];
    case "report":
      return report(status.job);
  }
}

function progressLine({ axis, bar }: AxisProgress): HTMLElement {
  return h("div", { class: "progress-line" }, h("strong", { style: { width: "90px" } }, axis),
    h("progress", { max: () => bar.val.total, value: () => bar.val.done }),
    h("span", { class: "muted", style: { whiteSpace: "nowrap" } }, () => bar.val.text));
}

/** The job's report: one row per axis with its status, files and problem. */
export function report(job: CommissionJob): Child {
  const result = job.result;
  if (job.state === "failed" || !result) {
    return h("div", { class: "message error", "data-testid": "commission-result" }, job.error ?? "The job failed.");
  }
  const cancelled = job.state === "cancelled";
  const summary = cancelled ? "cancelled; the table shows what was done" : result.ok ? "every axis OK" : "some axes need attention";
  return [
    h("div", { class: `message ${result.ok && !cancelled ? "ok" : "warn"}`, "data-testid": "commission-result" }, `${result.direction}: ${summary}`),
    h("table", { class: "data" }, h("thead", null, h("tr", null, ["Axis", "Node", "Bus", "Status", "Files", "Problem"].map((t) => h("th", null, t)))),
      h("tbody", null, result.axes.map((axis) => h("tr", { class: axis.ok ? "" : "differs" },
        h("td", null, axis.axis), h("td", { class: "num" }, String(axis.node_id)), h("td", null, axis.bus_id ?? ""),
        h("td", { class: axis.ok ? "ok-text" : "error-text" }, axis.status),
        h("td", { class: "wrap" }, axis.files.map((file) => `${file.file ?? ""}${file.ok === false ? " ✗" : " ✓"}`).join(", ")),
        h("td", { class: "wrap" }, axis.problem ?? axis.error ?? ""))))),
  ];
}
