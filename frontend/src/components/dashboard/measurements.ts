/** Measurements: the CiA 402 signals and temperatures as live readouts in their units. */

import { derive, h } from "../../lib/dom";
import type { Entry } from "../../lib/od";
import { formatValue, LIVE_DIGITS } from "../../lib/values";
import type { LiveCell } from "./model";

export interface MeasurementsProps {
  entries: Entry[];
  /** The live value of an entry; read inside bindings. */
  cell(entry: Entry): LiveCell;
  address(entry: Entry): string;
}

export function measurementsPanel(props: MeasurementsProps): HTMLElement {
  return h("section", { class: "panel" }, h("h2", null, "Measurements"),
    h("div", { class: "readouts", "data-testid": "dashboard-readouts" }, props.entries.map((entry) => readout(entry, props))));
}

function readout(entry: Entry, props: MeasurementsProps): HTMLElement {
  const { variable } = entry;
  const address = props.address(entry);
  // Derived texts: the readout changes only when what it shows does, not at every sample.
  const text = derive(() => {
    const cell = props.cell(entry);
    return cell.error ? "error" : cell.value ? formatValue(variable, cell.value.raw, LIVE_DIGITS) : "";
  });
  const error = derive(() => props.cell(entry).error ?? "");
  return h("div", { class: "readout", title: `${address} ${variable.description}`, "data-testid": `readout-${address}` },
    h("div", { class: "label" }, variable.name === "Highest sub-index supported" ? entry.object.name : variable.name),
    h("div", null, h("span", { class: "value", title: error }, text), h("span", { class: "unit" }, variable.unit)));
}
