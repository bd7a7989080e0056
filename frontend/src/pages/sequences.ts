/**
 * The sequence editor of one axis (tab "Sequences", docs/sequences.md): the project's SEQUENCE.TXT is the source of
 * truth, edited here offline as well as online — a table of the 128 sequences, the selected one's fields in user
 * units with bit-pattern editors, the chaining graph with its findings (checked by the server's file reader after
 * every change), import and export of SEQUENCE.TXT (LOAD or MERGE), and the drive panel: read, write, store, start,
 * stop, inputs and the live monitor with its timeline.
 */

import { sequenceFields } from "../components/sequences/fields";
import { graphView } from "../components/sequences/graph";
import { createModel, type SequenceModel } from "../components/sequences/model";
import { onlinePanel } from "../components/sequences/online";
import { sequenceTable } from "../components/sequences/table";
import { download, errorText, messageView, pickFile } from "../components/ui";
import { ioApi } from "../client/io";
import { h, Scope } from "../lib/dom";
import { ioNames } from "../lib/io-names";
import type { AxisContext, AxisViewPage } from "./axis";

export async function sequencesView(context: AxisContext): Promise<AxisViewPage> {
  const { axis, project } = context;
  const model = await createModel({ bus: axis.bus, node: axis.node_id, project: project.name, axis: axis.name });
  const scope = new Scope();
  const element = scope.run(() => h("div", { class: "page grid", style: { gap: "10px", alignContent: "start" } },
    fileBar(model),
    messageView(model.message),
    h("div", { style: { display: "grid", gridTemplateColumns: "minmax(320px, 1fr) minmax(320px, 1fr)", gap: "10px" } },
      h("section", { class: "panel" }, h("h2", null, "Sequences"), h("div", { class: "panel-body" }, sequenceTable(model), sequenceFields(model))),
      h("div", { class: "grid", style: { gap: "10px", alignContent: "start" } },
        h("section", { class: "panel" }, h("h2", null, "Chaining graph"), h("div", { class: "panel-body" }, graphView(model))),
        onlinePanel(model, scope)))));
  void ioApi.read(axis.bus, axis.node_id).then((config) => (model.ioNames.val = ioNames(config))).catch(() => undefined);
  try {
    await model.load();
  } catch (error) {
    model.message.val = { text: `SEQUENCE.TXT of ${axis.name}: ${errorText(error)}`, tone: "error", testid: "sequence-error" };
  }
  return { element, dispose: () => scope.dispose() };
}

function fileBar(model: SequenceModel): HTMLElement {
  const importFile = (mode: "load" | "merge") => async () => {
    const file = await pickFile(".txt,.TXT");
    if (file) await model.import(new TextDecoder("latin1").decode(await file.arrayBuffer()), mode);
  };
  const exportFile = () => {
    const url = URL.createObjectURL(new Blob([model.text], { type: "text/plain" }));
    download(url);
    setTimeout(() => URL.revokeObjectURL(url), 1000);
  };
  return h("div", { class: "toolbar" },
    h("button", { class: "primary", "data-testid": "sequence-save", disabled: () => model.busy.val || !model.check.val?.ok, onclick: () => void model.save() }, "Save to project"),
    h("span", { class: "muted", "data-testid": "sequence-dirty" }, () => (model.rows.val && model.text !== model.saved.val ? "unsaved changes" : "saved")),
    h("span", { class: "grow" }),
    h("button", { "data-testid": "sequence-import-load", onclick: () => void importFile("load")() }, "Import (LOAD)"),
    h("button", { "data-testid": "sequence-import-merge", onclick: () => void importFile("merge")() }, "Import (MERGE)"),
    h("button", { "data-testid": "sequence-export", onclick: exportFile }, "Export SEQUENCE.TXT"));
}
