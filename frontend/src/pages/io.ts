/**
 * The I/O page of one axis (tab "I/O", docs/io.md): every logic input with its function and polarity, the outputs,
 * the analog scaling, encoder emulation and CANopen I/O extension the device has, what the drive acts on now, the
 * fail-safe check of the limit switches, and on a simulated drive its test bench inputs. Edits are written together
 * (checked whole by the server, then through the motion guard: an enabled axis needs this page's armed controller).
 */

import { benchView, actsOnView, findingsView } from "../components/io/checks";
import { linesTable } from "../components/io/lines";
import { IoPageModel } from "../components/io/model";
import { settingsView } from "../components/io/settings";
import { errorText, messageView } from "../components/ui";
import { h, Scope } from "../lib/dom";
import type { AxisContext, AxisViewPage } from "./axis";

export async function ioView(context: AxisContext): Promise<AxisViewPage> {
  const model = new IoPageModel(context.axis.bus, context.axis.node_id);
  const scope = new Scope();
  const element = scope.run(() => h("div", { class: "page grid", style: { gap: "10px", alignContent: "start" }, "data-testid": "io-page" },
    toolbar(model),
    messageView(model.message),
    h("div", { class: "muted", "data-testid": "io-note" }, () => model.config.val?.note ?? ""),
    h("div", { style: { display: "grid", gridTemplateColumns: "minmax(360px, 1fr) minmax(320px, 1fr)", gap: "10px", alignItems: "start" } },
      h("div", { class: "grid", style: { gap: "10px" } },
        panel("Logic inputs", linesTable(model, "inputs")),
        panel("Outputs", linesTable(model, "outputs"))),
      h("div", { class: "grid", style: { gap: "10px" } },
        panel("The drive acts on", actsOnView(model)),
        panel("Limit switch wiring check", findingsView(model)),
        benchView(model))),
    settingsView(model)));
  try {
    await model.load();
    model.startPolling();
  } catch (error) {
    model.message.val = { text: `I/O of node ${context.axis.node_id}: ${errorText(error)}`, tone: "error", testid: "io-error" };
  }
  return { element, dispose: () => { model.stop(); scope.dispose(); } };
}

function panel(title: string, body: HTMLElement): HTMLElement {
  return h("section", { class: "panel" }, h("h2", null, title), h("div", { class: "panel-body" }, body));
}

function toolbar(model: IoPageModel): HTMLElement {
  return h("div", { class: "toolbar" },
    h("button", { class: "primary", "data-testid": "io-write", disabled: () => model.busy.val || !model.dirty, onclick: () => void model.write() }, "Check and write"),
    h("button", { "data-testid": "io-discard", disabled: () => !model.dirty, onclick: () => model.discard() }, "Discard edits"),
    h("span", { class: "muted", "data-testid": "io-dirty" }, () => (model.dirty ? "edits not written yet" : "as on the drive")),
    h("span", { class: "grow" }),
    h("button", { "data-testid": "io-reload", disabled: () => model.busy.val, onclick: () => void model.load().catch(() => undefined) }, "Read again"));
}
