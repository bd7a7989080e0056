/**
 * Ask before a bulk change, showing what it changes: one line per object (address, name, old → new), and notes on
 * what it leaves out (rows hidden by a filter, values the target cannot hold). A long list can start folded: the
 * count is in the text, the list on demand.
 */

import { h } from "../../lib/dom";
import { openDialog } from "../ui";

export interface Change {
  address: string;
  name: string;
  old: string;
  new: string;
}

export interface ChangeConfirmation {
  title: string;
  /** What the action does, with the count. */
  text: string;
  changes: Change[];
  /** Extra facts (what is not written, what stays restorable), one paragraph each. */
  notes?: string[];
  confirm: string;
  /** The list folded behind "Show the N changes" (for hundreds of lines). */
  folded?: boolean;
  danger?: boolean;
}

/** Resolves true when the user confirms. */
export function confirmChanges(ask: ChangeConfirmation): Promise<boolean> {
  return new Promise((resolve) => {
    let answered = false;
    const dialog = openDialog(ask.title, () => {
      if (!answered) resolve(false);
    });
    dialog.body.append(h("p", { style: { margin: "0 0 8px" }, "data-testid": "confirm-text" }, ask.text),
      ...(ask.notes ?? []).map((note) => h("p", { class: "muted", style: { margin: "0 0 8px" }, "data-testid": "confirm-note" }, note)),
      ...(ask.changes.length ? [changeList(ask)] : []));
    const ok = h("button", { class: ask.danger ? "danger solid" : "primary", "data-testid": "confirm" }, ask.confirm);
    ok.addEventListener("click", () => {
      answered = true;
      dialog.close();
      resolve(true);
    });
    dialog.actions.append(h("button", { "data-testid": "confirm-cancel", onclick: () => dialog.close() }, "Cancel"), ok);
    ok.focus();
  });
}

function changeList(ask: ChangeConfirmation): HTMLElement {
  const table = h("div", { style: { maxHeight: "300px", overflow: "auto" } }, h("table", { class: "data", "data-testid": "confirm-changes" },
    h("thead", null, h("tr", null, h("th", null, "Object"), h("th", null, "Name"), h("th", { class: "num" }, "Now"), h("th", null, ""), h("th", { class: "num" }, "New"))),
    h("tbody", null, ask.changes.map((change) => h("tr", { "data-testid": "confirm-change", "data-address": change.address },
      h("td", { class: "mono" }, change.address), h("td", { class: "wrap" }, change.name),
      h("td", { class: "num mono" }, change.old), h("td", { class: "muted" }, "→"), h("td", { class: "num mono" }, change.new))))));
  if (!ask.folded) return table;
  return h("details", { "data-testid": "confirm-details" }, h("summary", null, `Show the ${ask.changes.length} changes`), table);
}
