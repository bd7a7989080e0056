/**
 * The results of a procedure kept in the project under the axis (`procedures/<name>-<UTC time>.json`), newest
 * first, listed again after every run; Show puts one into the result view of its procedure.
 */

import { isTuningCheck, savedTime, type ProcedureResult } from "../../client/procedures";
import { effect, h, state, type Child } from "../../lib/dom";
import { sig } from "../../lib/procedures";
import { errorText } from "../ui";
import { run, type ProceduresModel } from "./model";

/** One line saying what a saved result found. */
export function summaryOf(result: ProcedureResult): string {
  if (result.error) return result.error;
  if (result.identified) {
    const bandwidth = isTuningCheck(result.verification) ? result.verification.speed_step?.bandwidth_hz : null;
    const plant = result.identified.per_ampere;
    const found = plant
      ? `J/Kt ${sig(plant.inertia_as2_per_rad, "A·s²/rad")}, B/Kt ${sig(plant.viscous_friction_as_per_rad, "A·s/rad")}`
      : `J ${sig(result.identified.inertia_kgm2, "kg·m²")}, B ${sig(result.identified.viscous_friction_nms_per_rad, "N·m·s/rad")}`;
    return found + (bandwidth ? `, ${sig(bandwidth, "Hz")}` : "");
  }
  if (result.pole_pairs !== undefined) return `pole pairs ${result.pole_pairs}, offset ${result.sensor_offset ?? "—"}`;
  if (result.sensor_offset !== undefined) return `offset ${result.sensor_offset}`;
  if (result.gains) return `${Object.keys(result.gains.after).length} gains`;
  return "";
}

export function savedPanel(model: ProceduresModel, names: string[], title: string): HTMLElement {
  const saved = state<ProcedureResult[] | string | null>(null);
  const load = async () => {
    try {
      const all = await model.client.saved(model.where.project, model.where.axis);
      saved.val = all.filter((result) => names.includes(result.procedure ?? ""));
    } catch (error) {
      saved.val = errorText(error);
    }
  };
  // Listed when the panel is built and again when a run of one of its procedures ends.
  effect(() => {
    for (const name of names) void run(model, name).ended.val;
    void load();
  });
  return h("section", { class: "panel" }, h("h2", null, title),
    h("div", { class: "panel-body", "data-testid": "saved-results" }, () => savedList(model, saved.val)));
}

function savedList(model: ProceduresModel, saved: ProcedureResult[] | string | null): Child {
  if (saved === null) return h("div", { class: "muted" }, "Reading…");
  if (typeof saved === "string") return h("div", { class: "error-text" }, saved);
  if (saved.length === 0) return h("div", { class: "muted", "data-testid": "saved-none" }, `No result kept for axis ${model.where.axis} yet.`);
  return h("table", { class: "data" },
    h("thead", null, h("tr", null, ["Time (UTC)", "Procedure", "Status", "Result", ""].map((title) => h("th", null, title)))),
    h("tbody", null, saved.map((result) => h("tr", { "data-testid": "saved-row" },
      h("td", { class: "mono" }, savedTime(result)), h("td", null, result.procedure ?? ""), h("td", null, result.status),
      h("td", { class: "wrap" }, summaryOf(result)),
      h("td", null, h("button", { class: "small", onclick: () => (run(model, result.procedure ?? "").result.val = result) }, "Show"))))));
}
