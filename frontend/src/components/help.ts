/** The `?` overlay listing every keyboard shortcut (from the same table the key handler uses). */

import { h } from "../lib/dom";
import { BINDINGS } from "../lib/keys";
import { openDialog, type DialogHandle } from "./ui";

let open: DialogHandle | null = null;

export function showHelp(): void {
  if (open) return;
  open = openDialog("Keyboard shortcuts", () => (open = null));
  open.body.dataset.testid = "help-overlay";
  open.body.append(
    h("table", { class: "keys-table" },
      h("tbody", null, BINDINGS.map((binding) =>
        h("tr", null,
          h("td", null, binding.keys.split(" ").map((key, i) => [i > 0 ? " then " : "", h("kbd", null, key)])),
          h("td", null, binding.description))))),
    h("p", { class: "muted", style: { margin: "0" } },
      "In the parameter table ↑ and ↓ move the selection and Enter edits the selected entry. Numbers use \".\" as decimal separator whatever the browser language; hexadecimal input starts with 0x."),
  );
  open.actions.append(h("button", { onclick: () => open?.close() }, "Close"));
}

export function toggleHelp(): void {
  if (open) open.close();
  else showHelp();
}
