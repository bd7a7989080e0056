/** Faults and warnings: the drive's report with the manual's name, CiA 402 code and remedy, and Fault reset. */

import type { FaultReport } from "../../client/drives";
import type { Schemas } from "../../client/schema-types";
import { h, type State } from "../../lib/dom";

type FaultCause = Schemas["FaultCauseModel"];

export interface FaultsProps {
  /** The last report; a text when it could not be read; null before the first answer. */
  report: State<FaultReport | string | null>;
  onReset(): void;
}

export function faultsPanel(props: FaultsProps): HTMLElement {
  return h("section", { class: "panel" },
    h("h2", null, "Faults and warnings",
      h("span", { class: "right" }, h("button", { class: "small", "data-testid": "fault-reset", onclick: () => props.onReset() }, "Fault reset"))),
    h("div", { class: "panel-body", style: { maxHeight: "160px", overflowY: "auto" } },
      h("div", { "data-testid": "dashboard-faults" }, () => faultList(props.report.val))));
}

function faultList(report: FaultReport | string | null): HTMLElement | HTMLElement[] | null {
  if (report === null) return null;
  if (typeof report === "string") return h("div", { class: "error-text" }, report);
  const items: HTMLElement[] = [];
  for (const fault of report.faults) items.push(faultItem("fault", fault.code, fault.cia402_code, fault.name, fault.remedy));
  if (report.fault && report.faults.length === 0) items.push(faultItem("fault", null, report.error_code, report.error_text || "Fault", ""));
  for (const cause of report.causes ?? []) items.push(causeItem(cause));
  for (const warning of report.warnings) items.push(faultItem("warning", warning.code, warning.cia402_code, warning.name, warning.remedy));
  return items.length ? items : h("div", { class: "muted", "data-testid": "no-faults" }, "No fault, no warning.");
}

function faultItem(kind: "fault" | "warning", code: number | null, cia402: number, name: string, remedy: string): HTMLElement {
  return h("div", { class: `fault-item ${kind}`, "data-testid": `${kind}-item` },
    h("div", { class: "title" }, `${kind === "fault" ? "Fault" : "Warning"}${code !== null ? ` ${code}` : ""}: ${name}`,
      h("span", { class: "mono muted" }, `  0x${cia402.toString(16).toUpperCase().padStart(4, "0")}`)),
    remedy ? h("div", null, remedy) : null);
}

/** What the tool sees behind a procedure fault that the drive does not say: a needed value at 0 or out of range. */
function causeItem(cause: FaultCause): HTMLElement {
  return h("div", { class: "fault-item fault", "data-testid": "fault-cause" },
    h("div", { class: "title" }, `Likely cause: ${cause.object} ${cause.problem}`),
    h("div", null, `${cause.needed_by} needs it: set it, then start again.`));
}
