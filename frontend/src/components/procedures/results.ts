/**
 * The results of phasing and of the current-loop calculation: values before → after (pole pairs, phase order,
 * sensor offset; gains and limits with their meaning) and the phasing's verification (torque per ampere).
 */

import { isPhasingCheck, type Change, type PhasingCheck, type ProcedureResult, type ResultBase } from "../../client/procedures";
import { h, type Child } from "../../lib/dom";
import { changeRows, gainMeaning, offsetText, phaseOrderText } from "../../lib/procedures";

/** A before → after table of semantic names; changed rows are marked. */
export function changeTable(change: Change, testid: string): HTMLElement {
  const rows = changeRows(change.before, change.after);
  return h("table", { class: "data", "data-testid": testid },
    h("thead", null, h("tr", null, ["Value", "Before", "After", "Meaning"].map((title) => h("th", null, title)))),
    h("tbody", null, rows.map((row) => {
      const [short, meaning] = gainMeaning(row.name);
      return h("tr", { class: row.changed ? "differs" : "", "data-testid": `${testid}-${row.name}` },
        h("td", { title: row.name }, short),
        h("td", { class: "num" }, row.before === undefined ? "—" : String(row.before)),
        h("td", { class: "num" }, row.after === undefined ? "—" : String(row.after)),
        h("td", { class: "wrap muted" }, meaning));
    })));
}

function commutationRow(label: string, testid: string, before: string, after: string): HTMLElement {
  return h("tr", { class: before !== after ? "differs" : "", "data-testid": testid },
    h("td", null, label), h("td", { class: "num" }, before), h("td", { class: "num" }, "→"), h("td", { class: "num" }, after));
}

/** Auto-phasing / motor phasing: the commutation before → after, and the verification when there was one. */
export function phasingResult(result: ProcedureResult): Child {
  const before = result.before ?? {};
  const rows = [
    result.pole_pairs !== undefined ? commutationRow("Pole pairs", "result-pole-pairs", String(before.pole_pairs ?? "—"), String(result.pole_pairs)) : null,
    result.phase_order !== undefined ? commutationRow("Phase order", "result-phase-order", phaseOrderText(before.phase_order), phaseOrderText(result.phase_order)) : null,
    result.sensor_offset !== undefined ? commutationRow("Sensor offset", "result-sensor-offset",
      offsetText(before.sensor_offset, before.pole_pairs ?? result.pole_pairs), offsetText(result.sensor_offset, result.pole_pairs ?? before.pole_pairs)) : null,
  ];
  return [
    doneLine(result),
    h("table", { class: "data kv", "data-testid": "phasing-values" }, h("tbody", null, rows)),
    isPhasingCheck(result.verification) ? verification(result.verification) : null,
  ];
}

function verification(check: PhasingCheck): HTMLElement {
  if (check.skipped) return h("div", { class: "message warn", "data-testid": "phasing-verification", "data-passed": "skipped" }, `No verification move: ${check.skipped}.`);
  const percent = check.torque_per_ampere_ratio === null ? "—" : `${(check.torque_per_ampere_ratio * 100).toFixed(1)} %`;
  const verdict = check.passed ? "commutation correct (≥ 98 %)" : `commutation wrong (< 98 %): phase again${check.reason ? ` (${check.reason})` : ""}`;
  const error = typeof check.error_deg === "number" ? `, angle error ${check.error_deg.toFixed(1)}° el.` : "";
  return h("div", { class: `message ${check.passed ? "ok" : "error"}`, "data-testid": "phasing-verification", "data-passed": String(Boolean(check.passed)) },
    `Verification move: torque per ampere ${percent} of the expected value${error} — ${verdict}.`);
}

/** The current-loop calculation: gains and current limits before → after. */
export function currentLoopResult(result: ProcedureResult): Child {
  return [
    doneLine(result),
    result.gains ? [h("strong", null, "Current loop gains (0x60F6)"), changeTable(result.gains, "current-gains")] : null,
    result.limits ? [h("strong", null, "Current limits"), changeTable(result.limits, "current-limits")] : null,
  ];
}

/** "Done", and where it was saved. */
export function doneLine(result: ResultBase): HTMLElement {
  return h("div", { class: `message ${result.status === "done" ? "ok" : "warn"}`, "data-testid": "result-status" },
    result.status === "done" ? "Done." : `Status: ${result.status}.`,
    result.saved ? ` Saved in the project: ${result.saved}` : "");
}
