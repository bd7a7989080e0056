/**
 * The drive side of the editor: read the sequence memory into the editor, write the editor's file to it (LOAD or
 * MERGE, checked whole by the server first; optionally stored to flash), store, arm the axis (motion needs this page
 * as its controller: docs/motion-safety.md), start a sequence, stop, set the conditional input 0x3601,3, and watch
 * the live monitor.
 */

import { controlApi, heldByMe, holderText, type AxisControl } from "../../client/control";
import { sequencesApi, type LoadMode, type MonitorSnapshot } from "../../client/sequences";
import { h, state, type Scope, type State } from "../../lib/dom";
import type { SequenceModel } from "./model";
import { monitorView } from "./timeline";

const POLL_MS = 100;

export interface Online {
  control: State<AxisControl | null>;
  monitor: State<MonitorSnapshot | null>;
  mode: State<LoadMode>;
  store: State<boolean>;
  start: State<string>;
  bits: State<string>;
}

export function onlinePanel(model: SequenceModel, scope: Scope): HTMLElement {
  const online: Online = { control: state(null), monitor: state(null), mode: state("load"), store: state(false), start: state("1"), bits: state("........") };
  const { bus, node } = model.ref;
  void controlApi.get(bus, node).then((control) => (online.control.val = control)).catch(() => undefined);
  let timer: ReturnType<typeof setInterval> | null = null;
  const poll = () => void sequencesApi.monitor(bus, node).then((snapshot) => (online.monitor.val = snapshot)).catch(() => undefined);
  const watch = async () => {
    online.monitor.val = await sequencesApi.watch(bus, node);
    if (!timer) timer = setInterval(poll, POLL_MS);
  };
  scope.add(() => {
    if (timer) clearInterval(timer);
    if (online.monitor.rawVal) void sequencesApi.unwatch(bus, node).catch(() => undefined);
  });
  return h("section", { class: "panel", "data-testid": "sequence-online" },
    h("h2", null, `Drive: node ${node} on ${bus}`),
    h("div", { class: "panel-body" },
      memoryBar(model, online),
      controlBar(model, online),
      runBar(model, online, watch),
      monitorView(online.monitor)));
}

function button(testid: string, label: string, onclick: () => void, model: SequenceModel, disabled?: () => boolean): HTMLElement {
  return h("button", { "data-testid": testid, onclick, disabled: () => model.busy.val || (disabled?.() ?? false) }, label);
}

function memoryBar(model: SequenceModel, online: Online): HTMLElement {
  const { bus, node } = model.ref;
  const read = () => void model.guard("Read the drive's sequence memory into the editor (not saved to the project yet)", async () => {
    const memory = await sequencesApi.upload(bus, node);
    model.setRows(memory.sequences ?? []);
  });
  const write = () => void model.guard("Written to the drive and verified", async () => {
    const result = await sequencesApi.download(bus, node, model.text, online.mode.rawVal, online.store.rawVal);
    if (!result.verified) throw new Error(`the drive holds other values for sequences ${result.mismatched.join(", ")}`);
  });
  const store = () => void model.guard("Stored to the drive's flash (sseq)", async () => void (await sequencesApi.store(bus, node)));
  return h("div", { class: "toolbar" },
    button("sequence-read", "Read from drive", read, model),
    h("select", { "data-testid": "sequence-mode", value: online.mode, onchange: (event: Event) => (online.mode.val = (event.target as HTMLSelectElement).value as LoadMode) },
      h("option", { value: "load" }, "LOAD (clear the others)"), h("option", { value: "merge" }, "MERGE (keep the others)")),
    h("label", null, h("input", { type: "checkbox", "data-testid": "sequence-store-too", checked: online.store, onchange: (event: Event) => (online.store.val = (event.target as HTMLInputElement).checked) }), " and store"),
    button("sequence-write", "Write to drive", write, model, () => !model.check.val?.ok),
    button("sequence-store", "Store to flash", store, model));
}

function controlBar(model: SequenceModel, online: Online): HTMLElement {
  const { bus, node } = model.ref;
  const arm = () => void model.guard("This page is the axis's controller", async () => void (online.control.val = await controlApi.arm(bus, node)));
  const release = () => void model.guard("Released (an enabled axis was quick-stopped)", async () => void (online.control.val = await controlApi.release(bus, node)));
  return h("div", { class: "toolbar" },
    h("span", { "data-testid": "sequence-holder" }, () => holderText(online.control.val)),
    () => (heldByMe(online.control.val) ? button("sequence-release", "Release", release, model) : button("sequence-arm", "Arm", arm, model)));
}

function runBar(model: SequenceModel, online: Online, watch: () => Promise<void>): HTMLElement {
  const { bus, node } = model.ref;
  const start = () => void model.guard(`Sequence ${online.start.rawVal} started`, async () => {
    await watch();
    await sequencesApi.start(bus, node, Number(online.start.rawVal));
  });
  const stop = () => void model.guard("Stopped", async () => void (await sequencesApi.stop(bus, node)));
  const bits = () => void model.guard("Conditional input set", async () => void (await sequencesApi.inputs(bus, node, online.bits.rawVal)));
  const armed = () => !heldByMe(online.control.val);
  return h("div", { class: "toolbar" },
    h("input", { "data-testid": "sequence-start-number", size: 4, value: online.start, oninput: (event: Event) => (online.start.val = (event.target as HTMLInputElement).value) }),
    button("sequence-start", "Start", start, model, armed),
    button("sequence-stop", "Stop", stop, model, armed),
    h("input", { "data-testid": "sequence-bits", size: 18, title: "0x3601,3: 1/0/. MSB first (bit 7 = input 8), or a number", value: online.bits, oninput: (event: Event) => (online.bits.val = (event.target as HTMLInputElement).value) }),
    button("sequence-set-bits", "Set inputs", bits, model, armed),
    button("sequence-watch", "Monitor", () => void model.guard("Monitoring (TPDO 4)", watch), model));
}
