/**
 * The what-if panel: KPv and KIv (log sliders from 1/10 to 10 times the drive's value), the three current-command
 * filters and the speed-measurement filter. A change only changes the draft: the predictions follow at once and
 * nothing is written until "Write these gains" (Expert; confirmed with the list of changes).
 */

import { filterAt, filterPosition, gainAt, positionOf, SLIDER_STEPS, type Draft } from "../../lib/bode";
import { h, type Child } from "../../lib/dom";
import { sig } from "../../lib/procedures";
import { confirmAction } from "../ui";
import { pendingChange, resetDraft, writeGains, type BodeModel } from "./model";

export interface WhatIfActions {
  /** may this user write gains (Expert and above) */
  mayWrite(): boolean;
  /** after the gains were written, with the bandwidth the what-if predicted for them (the page re-measures) */
  written(predictedHz: number | null): void;
}

function sliderRow(label: string, testid: string, position: () => number, move: (position: number) => void, value: () => string): Child[] {
  return [
    h("label", { for: testid }, label),
    h("input", {
      id: testid, type: "range", min: "0", max: String(SLIDER_STEPS), step: "1", "data-testid": testid, value: () => String(position()),
      oninput: (event: Event) => move(Number((event.target as HTMLInputElement).value)),
    }),
    h("span", { class: "num mono", "data-testid": `${testid}-value` }, value),
  ];
}

function gainRows(model: BodeModel): Child[] {
  const edit = (change: Partial<Draft>) => (model.draft.val = { ...model.draft.rawVal!, ...change });
  const kpRef = () => model.loop.val?.kp_a_per_rad_s ?? 0, kiRef = () => model.loop.val?.ki_a_per_rad ?? 0;
  return [
    ...sliderRow("KPv", "whatif-kp", () => positionOf(model.draft.val?.kp ?? 0, kpRef()),
      (p) => edit({ kp: gainAt(p, kpRef()) }), () => sig(model.draft.val?.kp, "A/(rad/s)")),
    ...sliderRow("KIv", "whatif-ki", () => positionOf(model.draft.val?.ki ?? 0, kiRef()),
      (p) => edit({ ki: gainAt(p, kiRef()) }), () => sig(model.draft.val?.ki, "A/rad")),
  ];
}

function filterRows(model: BodeModel): Child[] {
  const count = model.loop.rawVal?.current_filters_hz.length ?? 0;
  return Array.from({ length: count }, (_, n) => sliderRow(`Current filter ${n + 1}`, `whatif-filter-${n + 1}`,
    () => filterPosition(model.draft.val?.filtersHz[n] ?? 0),
    (p) => (model.draft.val = { ...model.draft.rawVal!, filtersHz: model.draft.rawVal!.filtersHz.map((hz, i) => (i === n ? filterAt(p) : hz)) }),
    () => { const hz = model.draft.val?.filtersHz[n] ?? 0; return hz > 0 ? `${hz} Hz` : "off"; })).flat();
}

function speedFilterRow(model: BodeModel): Child[] {
  const choices = model.loop.rawVal?.speed_filter_choices_s ?? [];
  if (choices.length === 0) return [h("span", null, "Speed filter"), h("span", { class: "muted" }, () => `${sig((model.draft.val?.speedFilterS ?? 0) * 1000, "ms")} (fixed)`), h("span")];
  return [h("label", { for: "whatif-speed-filter" }, "Speed filter"),
    h("select", {
      id: "whatif-speed-filter", "data-testid": "whatif-speed-filter", value: () => String(model.draft.val?.speedFilterS ?? ""),
      onchange: (event: Event) => (model.draft.val = { ...model.draft.rawVal!, speedFilterS: Number((event.target as HTMLSelectElement).value) }),
    }, choices.map((tau) => h("option", { value: String(tau) }, `${sig(tau * 1000, "ms")}`))),
    h("span")];
}

/** The predicted figures beside the drive's, and what the update took. */
function readouts(model: BodeModel): HTMLElement {
  const row = (label: string, key: string, value: (m: NonNullable<BodeModel["predicted"]["rawVal"]>) => string) =>
    h("tr", null, h("td", null, label),
      h("td", { class: "num", "data-testid": `whatif-${key}-drive` }, () => (model.current.val ? value(model.current.val) : "—")),
      h("td", { class: "num", "data-testid": `whatif-${key}` }, () => (model.predicted.val ? value(model.predicted.val) : "—")));
  return h("table", { class: "data kv" },
    h("thead", null, h("tr", null, h("th", null, "predicted"), h("th", null, "drive's gains"), h("th", null, "what-if"))),
    h("tbody", null,
      row("bandwidth (−3 dB)", "bandwidth", (t) => sig(t.prediction.markers.bandwidth_hz, "Hz")),
      row("phase margin", "pm", (t) => sig(t.prediction.markers.phase_margin_deg, "°")),
      row("gain margin", "gm", (t) => sig(t.prediction.markers.gain_margin_db, "dB")),
      row("update took", "ms", (t) => sig(t.computeMs, "ms"))));
}

async function confirmWrite(model: BodeModel, actions: WhatIfActions): Promise<void> {
  const list = Object.entries(pendingChange(model)).map(([key, value]) => `${key} = ${sig(value)}`).join(", ");
  const text = `Write to node ${model.where.node} (axis ${model.where.axis}): ${list}. The server checks every value before anything is written.`;
  const predictedHz = model.predicted.rawVal?.prediction.markers.bandwidth_hz ?? null;
  if ((await confirmAction("Write these gains", text, "Write to drive", true)) && (await writeGains(model))) actions.written(predictedHz);
}

function buttons(model: BodeModel, actions: WhatIfActions): HTMLElement {
  const changed = () => Object.keys(pendingChange(model)).length > 0;
  return h("div", { class: "toolbar" },
    h("button", { "data-testid": "whatif-reset", disabled: () => !changed(), onclick: () => resetDraft(model) }, "Back to the drive's gains"),
    h("button", {
      class: "primary", "data-testid": "whatif-write", disabled: () => !changed() || model.busy.val || !actions.mayWrite(),
      title: () => (actions.mayWrite() ? "Write the what-if gains to the drive" : "Writing gains needs the Expert level"),
      onclick: () => void confirmWrite(model, actions),
    }, "Write these gains"));
}

/** Built again only when the speed loop is read (not on a slider move: the slider keeps its drag). */
function body(model: BodeModel, actions: WhatIfActions): Child {
  if (model.loopError.val) return h("div", { class: "message warn", "data-testid": "whatif-unavailable" }, model.loopError.rawVal);
  if (!model.loop.val) return h("div", { class: "muted" }, "Reading the speed loop…");
  return [
    h("div", { class: "grid", style: { gridTemplateColumns: "auto minmax(0, 1fr) 120px", gap: "4px 8px", alignItems: "center" } },
      ...gainRows(model), ...filterRows(model), ...speedFilterRow(model)),
    h("div", { class: "muted", hidden: () => model.plantName.val !== null }, "No plant measurement to predict on: measure the plant or pick a saved one."),
    readouts(model),
    buttons(model, actions),
  ];
}

export function whatIfPanel(model: BodeModel, actions: WhatIfActions): HTMLElement {
  return h("section", { class: "panel", "data-testid": "whatif-panel" }, h("h2", null, "What-if: speed-loop gains"),
    h("div", { class: "panel-body grid", style: { gap: "8px" } }, () => body(model, actions)));
}
