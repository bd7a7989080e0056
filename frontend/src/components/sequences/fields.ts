/**
 * The selected sequence's parameters: the fields of its type in the drive's user units (0x6093 factor group, as the
 * drive converts them when the sequence begins), each with its unit and the range a file may write; constants as
 * choices, Output / StartCond / EndCond as bit-pattern editors naming the bits. What the file reader objects to
 * (after every change) is shown at the field.
 */

import type { Keyword } from "../../client/sequences";
import { h } from "../../lib/dom";
import { issuesOf, type SequenceModel } from "./model";
import { patternEditor } from "./pattern";
import { allowedText, type Value } from "./text";

export function sequenceFields(model: SequenceModel): HTMLElement {
  return h("div", { "data-testid": "sequence-fields" }, () => {
    const number = model.selected.val;
    const row = model.rows.val.find((candidate) => candidate.sequence === number);
    if (!row) return h("p", { class: "muted" }, `Sequence ${number} is empty: choose its type in the table.`);
    const keywords = model.catalog.keywords[row.type] ?? [];
    return [
      h("h3", null, `Sequence ${number}: ${row.type}`),
      h("table", { class: "kv" }, h("tbody", null, keywords.map((keyword) => fieldRow(model, number, keyword, row.values[keyword.name] ?? null)))),
      h("div", null, () => issuesOf(model, number).map((issue) =>
        h("div", { class: "message error", "data-testid": "sequence-issue" }, `${issue.keyword ?? ""}: ${issue.reason}`))),
    ];
  });
}

function fieldRow(model: SequenceModel, number: number, keyword: Keyword, value: Value): HTMLElement {
  const unit = keyword.unit ? ` (${keyword.unit})` : "";
  return h("tr", null,
    h("td", { title: `0x3611,${keyword.subs.join("/")}` }, `${keyword.name}${unit}`),
    h("td", null, editor(model, number, keyword, value)),
    h("td", { class: "muted", style: { fontSize: "11px", whiteSpace: "normal", wordBreak: "break-all" } },
      keyword.pattern || keyword.constants ? "" : allowedText(keyword)));
}

function editor(model: SequenceModel, number: number, keyword: Keyword, value: Value): HTMLElement {
  const set = (next: Value) => model.setValue(number, keyword.name, next);
  const testid = `field-${keyword.name}`;
  if (keyword.pattern) return patternEditor(keyword.name, String(value ?? ""), set, model.ioNames.val);
  if (keyword.constants) {
    const choices = ["", ...keyword.constants];
    return h("select", { "data-testid": testid, value: value ?? "", onchange: (event: Event) => set((event.target as HTMLSelectElement).value || null) },
      choices.map((choice) => h("option", { value: choice }, choice || "—")));
  }
  return h("input", {
    "data-testid": testid,
    type: "text",
    inputmode: "numeric",
    size: 12,
    value: value ?? "",
    onchange: (event: Event) => set(numberOrText((event.target as HTMLInputElement).value)),
  });
}

/** A number as typed (decimal or 0x hex, as the file allows); anything else goes to the reader as it is, which says why. */
function numberOrText(text: string): Value {
  const trimmed = text.trim();
  if (!trimmed) return null;
  return /^-?\d+$/.test(trimmed) ? Number(trimmed) : trimmed;
}
