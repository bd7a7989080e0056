/** The 128 sequence slots: number, type (an empty slot has none), what it does, and whether the reader objects. */

import type { SequenceRow } from "../../client/sequences";
import { h } from "../../lib/dom";
import { issuesOf, type SequenceModel } from "./model";
import { summary } from "./text";

export const SLOTS = 128;

export function sequenceTable(model: SequenceModel): HTMLElement {
  const body = h("tbody", null, () => {
    const byNumber = new Map(model.rows.val.map((row) => [row.sequence, row]));
    return Array.from({ length: SLOTS }, (_, number) => slotRow(model, number, byNumber.get(number)));
  });
  return h("div", { style: { maxHeight: "420px", overflow: "auto" } },
    h("table", { class: "data", "data-testid": "sequence-table" },
      h("thead", null, h("tr", null, h("th", null, "Nb"), h("th", null, "Type"), h("th", null, "Does"), h("th", null, ""))),
      body));
}

function slotRow(model: SequenceModel, number: number, row: SequenceRow | undefined): HTMLElement {
  const types = ["", ...model.catalog.types];
  const select = h("select", {
    "data-testid": `sequence-type-${number}`,
    value: row?.type ?? "",
    onchange: (event: Event) => {
      model.setType(number, (event.target as HTMLSelectElement).value);
      model.selected.val = number;
    },
  }, types.map((type) => h("option", { value: type }, type || "—")));
  return h("tr", {
    "data-testid": `sequence-row-${number}`,
    class: () => (model.selected.val === number ? "differs" : ""), // the data table's highlighted row
    onclick: () => (model.selected.val = number),
  },
  h("td", null, String(number)),
  h("td", null, select),
  h("td", { class: "muted" }, row ? summary(row) : ""),
  h("td", null, () => (issuesOf(model, number).length ? h("span", { class: "dot bad", title: "the file reader objects" }) : null)));
}
