/**
 * Project-wide commissioning as a server job (`POST /api/projects/{p}/commission`): check every axis's drive,
 * upload the drives into the project, or download the project into the drives. Progress and the final report
 * arrive as `progress` and `job` events on `/api/ws/events`; the page shows one progress bar per axis. Cancel asks
 * the server to stop the job at the next object (download) or file (upload); the report then says what was done.
 */

import type { App } from "../app";
import { post } from "../client/api";
import { cancelJob } from "../client/jobs";
import { h, replaceChildren } from "../lib/dom";
import type { LiveEvent } from "../client/live";
import { confirmAction, errorText } from "./ui";

interface JobInfo {
  id: string;
  state: string;
  result: CommissionResult | null;
  error: string | null;
}

interface AxisResult {
  axis: string;
  node_id: number;
  bus_id: string | null;
  status: string;
  problem: string | null;
  ok: boolean;
  error: string | null;
  files: { file?: string; ok?: boolean; objects?: number; error?: string | null; counts?: Record<string, number> }[];
}

interface CommissionResult {
  ok: boolean;
  direction: string;
  axes: AxisResult[];
}

const DIRECTIONS: [string, string, string][] = [
  ["check", "Check drives", "Identify every axis's drive (bus open, node answers, right device)."],
  ["upload", "Upload drives → project", "Read every drive's parameter files into the project's axis files."],
  ["download", "Download project → drives", "Write the project's files into the drives: validated, written, verified, stored to flash."],
];

export function commissionPanel(app: App, project: string, onDone: () => void): HTMLElement {
  const body = h("div", { class: "panel-body", "data-testid": "commission-panel" });
  const status = h("div", { class: "grid", style: { gap: "6px", marginTop: "8px" } });
  const bars = new Map<string, { bar: HTMLProgressElement; text: HTMLElement }>();
  let job: string | null = null;
  let offProgress: (() => void) | null = null;
  let offJob: (() => void) | null = null;
  const cancel = h("button", {
    "data-testid": "commission-cancel", disabled: true, title: "Stop the job at the next object or file",
    onclick: () => {
      if (job === null) return;
      cancel.disabled = true;
      void cancelJob(job).catch((error) => replaceChildren(status, h("div", { class: "message error" }, errorText(error))));
    },
  }, "Cancel");
  const buttons = DIRECTIONS.map(([direction, label, title]) => h("button", {
    class: direction === "download" ? "danger" : "", title, "data-testid": `commission-${direction}`,
    onclick: () => void start(direction, label),
  }, label));

  const barFor = (axis: string) => {
    let entry = bars.get(axis);
    if (!entry) {
      entry = { bar: h("progress", { max: "1", value: "0" }), text: h("span", { class: "muted", style: { whiteSpace: "nowrap" } }, "waiting") };
      bars.set(axis, entry);
      status.append(h("div", { class: "progress-line" }, h("strong", { style: { width: "90px" } }, axis), entry.bar, entry.text));
    }
    return entry;
  };

  const onProgress = (event: LiveEvent) => {
    if (event.job !== job) return;
    if (event.operation === "commission") {
      const text = `${String(event.step)}…`;
      for (const axis of (event.axes as { axis: string }[] | undefined) ?? []) barFor(axis.axis).text.textContent = text;
      return;
    }
    const axis = typeof event.axis === "string" ? event.axis : `node ${String(event.node)}`;
    const entry = barFor(axis);
    entry.bar.max = Math.max(1, Number(event.total) || 1);
    entry.bar.value = Number(event.done) || 0;
    entry.text.textContent = `${String(event.operation)} ${String(event.file ?? "")} ${String(event.done)}/${String(event.total)}`;
  };

  const finish = (info: JobInfo) => {
    offProgress?.();
    offJob?.();
    job = null;
    buttons.forEach((button) => (button.disabled = false));
    cancel.disabled = true;
    if (info.state === "failed" || !info.result) {
      replaceChildren(status, h("div", { class: "message error", "data-testid": "commission-result" }, info.error ?? "The job failed."));
      return;
    }
    const result = info.result;
    const summary = info.state === "cancelled" ? "cancelled; the table shows what was done"
      : result.ok ? "every axis OK" : "some axes need attention";
    replaceChildren(status, h("div", { class: `message ${result.ok && info.state !== "cancelled" ? "ok" : "warn"}`, "data-testid": "commission-result" },
      `${result.direction}: ${summary}`),
    h("table", { class: "data" }, h("thead", null, h("tr", null, ["Axis", "Node", "Bus", "Status", "Files", "Problem"].map((t) => h("th", null, t)))),
      h("tbody", null, result.axes.map((axis) => h("tr", { class: axis.ok ? "" : "differs" },
        h("td", null, axis.axis), h("td", { class: "num" }, String(axis.node_id)), h("td", null, axis.bus_id ?? ""),
        h("td", { class: axis.ok ? "ok-text" : "error-text" }, axis.status),
        h("td", { class: "wrap" }, axis.files.map((file) => `${file.file ?? ""}${file.ok === false ? " ✗" : " ✓"}`).join(", ")),
        h("td", { class: "wrap" }, axis.problem ?? axis.error ?? ""))))));
    onDone();
  };

  const start = async (direction: string, label: string) => {
    if (direction === "download" && !(await confirmAction(label, `Write the files of project ${project} into every axis's drive and store them to flash? The drives' current values are overwritten.`, "Download", true))) return;
    buttons.forEach((button) => (button.disabled = true));
    bars.clear();
    replaceChildren(status, h("div", { class: "muted" }, `${label}: starting…`));
    offProgress = app.live.on("progress", onProgress);
    // A short job can end before its id comes back from the POST: remember every ending meanwhile.
    const ended = new Map<string, JobInfo>();
    offJob = app.live.on("job", (event) => {
      if (event.id === job) finish(event as unknown as JobInfo);
      else ended.set(String(event.id), event as unknown as JobInfo);
    });
    try {
      const started = await post<JobInfo>(`/api/projects/${encodeURIComponent(project)}/commission`, { direction });
      job = started.id;
      cancel.disabled = false;
      replaceChildren(status, h("div", { class: "muted" }, `${label}: job ${started.id} running`));
      const early = ended.get(started.id);
      if (early) finish(early);
      else if (started.state !== "running") finish(started);
    } catch (error) {
      finish({ id: "", state: "failed", result: null, error: errorText(error) });
    }
  };

  replaceChildren(body, h("div", { class: "toolbar" }, buttons, cancel, h("span", { class: "muted" }, "All axes in parallel; progress per axis.")), status);
  return h("section", { class: "panel" }, h("h2", null, "Commission all axes"), body);
}
