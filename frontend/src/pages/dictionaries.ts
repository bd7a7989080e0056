/** Object dictionaries: the library (built-in and imported EDS files) and a browser for one dictionary. */

import type { Page, PageContext } from "../app";
import { getDictionary, importDictionary, listDictionaries } from "../client/api";
import { formDialog, toast } from "../components/ui";
import { h, state } from "../lib/dom";
import type { DictionarySummary } from "../lib/od";
import { formatHex } from "../lib/numbers";
import { buildPath } from "../lib/router";
import { ParameterEditor } from "./parameters";

export async function dictionariesPage(_context: PageContext): Promise<Page> {
  const list = state(await listDictionaries());
  const reload = async () => void (list.val = await listDictionaries());
  return {
    title: "Object dictionaries",
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Object dictionaries"), h("span", { class: "grow" }),
        h("button", { "data-testid": "import-eds", onclick: () => importDialog(reload) }, "Import EDS…")),
      h("p", { class: "muted", style: { margin: "0" } },
        "Each supported device is described by a CiA 306 EDS and its companion .props file (units, groups, enumerations, bit fields)."),
      h("div", { class: "panel" }, h("table", { class: "data" },
        h("thead", null, h("tr", null, ["Device", "Product", "Vendor ID", "Product code", "Revision", "Objects", "Source"].map((title) => h("th", null, title)))),
        h("tbody", null, () => list.val.map(dictionaryRow))))),
  };
}

function dictionaryRow(item: DictionarySummary): HTMLElement {
  return h("tr", { "data-testid": `dictionary-${item.device}` },
    h("td", null, h("a", { href: buildPath({ page: "dictionary", device: item.device }) }, item.device)),
    h("td", null, item.product_name),
    h("td", { class: "mono" }, formatHex(item.vendor_id, 8)),
    h("td", { class: "mono" }, formatHex(item.product_code, 8)),
    h("td", { class: "mono" }, formatHex(item.revision, 8)),
    h("td", { class: "num" }, String(item.object_count)),
    h("td", null, item.builtin ? "built-in" : "imported"));
}

/** Import an EDS (and optionally its .props); the loader's `file:line` refusal is shown in the dialog. */
function importDialog(imported: () => Promise<void>): void {
  const eds = h("input", { type: "file", accept: ".eds,.EDS", "data-testid": "import-eds-file" });
  const props = h("input", { type: "file", accept: ".props", "data-testid": "import-props-file" });
  formDialog({
    title: "Import an EDS",
    body: [
      h("label", { class: "field" }, "EDS file (CiA 306)", eds),
      h("label", { class: "field" }, "Companion .props file (optional: units, groups, enumerations, bit fields)", props),
    ],
    confirm: "Import",
    confirmTestid: "import-confirm",
    errorTestid: "dialog-error",
    submit: async () => {
      const edsFile = eds.files?.[0];
      if (!edsFile) throw new Error("Choose the EDS file.");
      const added = await importDictionary(edsFile, props.files?.[0] ?? null);
      toast(`Imported ${added.product_name} as "${added.device}"`, "ok");
      await imported();
    },
  });
}

export async function dictionaryPage(context: PageContext, device: string): Promise<Page> {
  const dictionary = await getDictionary(device);
  const editor = new ParameterEditor(dictionary, {
    drive: null,
    project: null,
    onQuery: (query) => context.app.replaceQuery(query),
  }, context.location);
  await editor.start();
  return {
    title: `${dictionary.product_name} dictionary`,
    crumbs: [h("a", { href: "/dictionaries" }, "Dictionaries"), ` / ${dictionary.product_name}`],
    element: editor.element,
    update: (location) => editor.update(location),
    dispose: () => editor.dispose(),
    focusSearch: () => editor.focusSearch(),
  };
}
