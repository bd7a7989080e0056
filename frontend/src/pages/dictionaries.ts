/** Object dictionaries: the library (built-in and imported EDS files) and a browser for one dictionary. */

import type { Page, PageContext } from "../app";
import { getDictionary, importDictionary, listDictionaries } from "../client/api";
import { errorText, openDialog, toast } from "../components/ui";
import { h, replaceChildren } from "../lib/dom";
import { formatHex } from "../lib/numbers";
import { buildPath } from "../lib/router";
import { ParameterEditor } from "./parameters";

export async function dictionariesPage(_context: PageContext): Promise<Page> {
  const body = h("tbody");
  const load = async () => {
    const list = await listDictionaries();
    replaceChildren(body, list.map((item) => h("tr", { "data-testid": `dictionary-${item.device}` },
      h("td", null, h("a", { href: buildPath({ page: "dictionary", device: item.device }) }, item.device)),
      h("td", null, item.product_name),
      h("td", { class: "mono" }, formatHex(item.vendor_id, 8)),
      h("td", { class: "mono" }, formatHex(item.product_code, 8)),
      h("td", { class: "mono" }, formatHex(item.revision, 8)),
      h("td", { class: "num" }, String(item.object_count)),
      h("td", null, item.builtin ? "built-in" : "imported"))));
  };
  await load();
  const importDialog = () => {
    const dialog = openDialog("Import an EDS");
    const eds = h("input", { type: "file", accept: ".eds,.EDS", "data-testid": "import-eds-file" });
    const props = h("input", { type: "file", accept: ".props", "data-testid": "import-props-file" });
    const message = h("div");
    dialog.body.append(
      h("label", { class: "field" }, "EDS file (CiA 306)", eds),
      h("label", { class: "field" }, "Companion .props file (optional: units, groups, enumerations, bit fields)", props),
      message);
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"), h("button", {
      class: "primary", "data-testid": "import-confirm", onclick: async () => {
        const edsFile = eds.files?.[0];
        if (!edsFile) {
          replaceChildren(message, h("div", { class: "message error" }, "Choose the EDS file."));
          return;
        }
        try {
          const added = await importDictionary(edsFile, props.files?.[0] ?? null);
          dialog.close();
          toast(`Imported ${added.product_name} as "${added.device}"`, "ok");
          await load();
        } catch (error) {
          replaceChildren(message, h("div", { class: "message error", "data-testid": "dialog-error" }, errorText(error)));
        }
      },
    }, "Import"));
  };
  const importButton = h("button", { "data-testid": "import-eds", onclick: importDialog }, "Import EDS…");
  return {
    title: "Object dictionaries",
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Object dictionaries"), h("span", { class: "grow" }), importButton),
      h("p", { class: "muted", style: { margin: "0" } },
        "Each supported device is described by a CiA 306 EDS and its companion .props file (units, groups, enumerations, bit fields)."),
      h("div", { class: "panel" }, h("table", { class: "data" },
        h("thead", null, h("tr", null, ["Device", "Product", "Vendor ID", "Product code", "Revision", "Objects", "Source"].map((title) => h("th", null, title)))),
        body))),
  };
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
