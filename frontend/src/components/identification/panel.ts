/**
 * The tool's own identification on the tuning page (docs/identification.md): for a drive without auto-tuning
 * (encoTRive, any CiA 402 drive) the only way to its inertia and friction, on the others a cross-check of the
 * drive's own. The experiment turns the motor both ways within the position window: Start needs the axis armed by
 * this page; Abort cancels the job (the server quick-stops the axis and puts back what the run changed).
 */

import {
  identificationApi,
  type IdentificationClient,
  type IdentificationOptions,
  type IdentificationResult,
  type TuningAfterIdentification,
} from "../../client/identification";
import { cancelJob, runJob } from "../../client/jobs";
import { h, state, type State } from "../../lib/dom";
import { armed, type ProceduresModel } from "../procedures/model";
import { errorText, messageView, type Message } from "../ui";

interface Field {
  key: keyof IdentificationOptions;
  label: string;
  value: State<number>;
  note: string;
}

export interface IdentificationRun {
  job: State<string | null>;
  progress: State<string>;
  result: State<IdentificationResult | null>;
  message: State<Message | null>;
}

export function identificationPanel(model: ProceduresModel, client: IdentificationClient = identificationApi): HTMLElement {
  const fields: Field[] = [
    { key: "speed_rpm", label: "Speed", value: state(800), note: "rpm (the higher of the two speeds held both ways)" },
    { key: "position_window_rev", label: "Position window", value: state(6), note: "revolutions either side of the start" },
    { key: "cycles", label: "Cycles", value: state(2), note: "repetitions (more: less scatter in the friction)" },
  ];
  const bandwidth = state<number | null>(null);
  const current: IdentificationRun = { job: state<string | null>(null), progress: state(""), result: state<IdentificationResult | null>(null), message: state<Message | null>(null) };
  const block = () => (current.job.val !== null ? "running" : armed(model) ? null : "Arm the axis first (Controller panel): the motor turns.");
  const options = (): IdentificationOptions => Object.fromEntries(fields.map((field) => [field.key, field.value.rawVal]));
  return h("section", { class: "panel", "data-testid": "identification" },
    h("h2", null, "Identification by the tool (inertia, friction)"),
    h("div", { class: "panel-body grid", style: { gap: "10px" } },
      h("div", { class: "muted" }, "The axis moves back and forth (profile position, two speeds each way, targets within the window) and the tool fits inertia, viscous and ",
        "Coulomb friction and a constant load to the recorded torque, speed and position. The axis is quick-stopped when it leaves ",
        "the window or exceeds 1.25 × the speed or the current limit."),
      h("div", { class: "grid", style: { gridTemplateColumns: "auto 1fr", gap: "6px 12px", alignItems: "center" } }, fields.map(fieldRow), bandwidthRow(bandwidth)),
      h("div", { class: "toolbar" },
        h("button", { class: "primary", "data-testid": "identification-start", disabled: () => block() !== null, title: () => block() ?? "",
          onclick: () => void startIdentification(model, client, current, options(), bandwidth.rawVal) }, "Identify"),
        h("button", { class: "danger", "data-testid": "identification-abort", disabled: () => current.job.val === null,
          onclick: () => void abortIdentification(current) }, "Abort"),
        h("span", { class: "muted", "data-testid": "identification-reason" }, () => (current.job.val === null ? block() ?? "Ready." : current.progress.val))),
      messageView(current.message),
      h("div", { "data-testid": "identification-result" }, () => (current.result.val ? resultTable(current.result.val) : null))));
}

function fieldRow(field: Field): HTMLElement[] {
  return [h("label", null, field.label), h("span", null,
    h("input", { type: "number", value: () => String(field.value.val), "data-testid": `identification-${field.key}`, style: { width: "90px" },
      onchange: (event: Event) => (field.value.val = Number((event.target as HTMLInputElement).value)) }),
    h("span", { class: "muted" }, ` ${field.note}`))];
}

function bandwidthRow(bandwidth: State<number | null>): HTMLElement[] {
  return [h("label", null, "Then tune for"), h("span", null,
    h("input", { type: "number", placeholder: "no tuning", "data-testid": "identification-bandwidth", style: { width: "90px" },
      onchange: (event: Event) => {
        const text = (event.target as HTMLInputElement).value.trim();
        bandwidth.val = text === "" ? null : Number(text);
      } }),
    h("span", { class: "muted" }, " Hz closed speed-loop bandwidth (gains, or the encoTRive's inertia setting: written, then verified by a step)"))];
}

export async function startIdentification(model: ProceduresModel, client: IdentificationClient, current: IdentificationRun,
  options: IdentificationOptions, bandwidth: number | null = null): Promise<void> {
  current.message.val = null;
  current.job.val = "starting";
  try {
    const job = await runJob<IdentificationResult>(model.live, async () => {
      const started = await client.start(model.where.bus, model.where.node, options, bandwidth);
      current.job.val = started.id;
      return started;
    }, (event) => (current.progress.val = typeof event.message === "string" ? event.message : ""));
    if (job.result) current.result.val = job.result;
    if (job.state === "failed") current.message.val = { text: job.error ?? "The identification failed.", tone: "error", testid: "identification-failed" };
    if (job.state === "cancelled") current.message.val = { text: "Stopped: the axis was quick-stopped, its objects are as before.", tone: "warn", testid: "identification-stopped" };
  } catch (error) {
    current.message.val = { text: errorText(error), tone: "error", testid: "identification-refused" };
  } finally {
    current.job.val = null;
  }
}

async function abortIdentification(current: IdentificationRun): Promise<void> {
  const id = current.job.rawVal;
  if (id === null || id === "starting") return;
  try {
    await cancelJob(id);
  } catch (error) {
    current.message.val = { text: errorText(error), tone: "error", testid: "identification-abort-failed" };
  }
}

const ROWS: [keyof IdentificationResult["identified"], string, string][] = [
  ["inertia_kgm2", "Inertia (total)", "kg·m²"],
  ["viscous_friction_nms_per_rad", "Viscous friction", "N·m·s/rad"],
  ["coulomb_friction_nm", "Coulomb friction", "N·m"],
  ["load_torque_nm", "Constant load torque", "N·m"],
  ["inertia_ratio", "Inertia ratio (total / motor)", ""],
  ["residual", "Residual of the fit (0 = perfect)", ""],
];

const shown = (value: unknown) => (typeof value === "number" ? value.toPrecision(4) : "—");

export function resultTable(result: IdentificationResult): HTMLElement {
  return h("div", null,
    h("table", { class: "table", "data-testid": "identification-table" },
      h("tbody", null, ROWS.map(([key, label, unit]) => h("tr", { "data-testid": `identified-${key}` },
        h("td", null, label), h("td", { class: "num" }, shown(result.identified[key])), h("td", { class: "muted" }, unit))))),
    result.tuning ? tuningLine(result.tuning) : null);
}

function tuningLine(tuning: TuningAfterIdentification): HTMLElement {
  const step = tuning.verification?.speed_step ?? null;
  const measured = step ? `measured ${shown(step.bandwidth_hz)} Hz from the speed step (overshoot ${shown(step.overshoot_pct)} %)` : tuning.verification?.skipped ?? "not verified";
  return h("p", { "data-testid": "identification-tuning" }, `Gains written for ${tuning.bandwidth_hz} Hz: ${measured}.`);
}
