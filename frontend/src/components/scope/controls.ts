/**
 * The capture's definition and the recorder's commands: presets, 4 channels picked by name, period, samples,
 * trigger (object, edge, level in its unit, pre-trigger), mode; Arm / Force / Stop (keys a, f, s) with the
 * recorder's stage and the upload's progress.
 */

import { h, type State } from "../../lib/dom";
import type { Searchable } from "../../lib/search";
import { messageView } from "../ui";
import { CHANNEL_SLOTS, applyDefinition, arm, force, stop, type ScopeModel } from "./model";
import { entryOf, objectPicker } from "./picker";

export function controlsView(model: ScopeModel, index: Searchable[]): HTMLElement {
  return h("section", { class: "panel" },
    h("div", { class: "panel-body grid", style: { gap: "8px" } },
      h("div", { class: "toolbar" }, presetSelect(model), commandButtons(model), stageView(model)),
      channelRow(model, index),
      timingRow(model),
      triggerRow(model, index),
      h("div", { "data-testid": "scope-message" }, messageView(model.message))));
}

function presetSelect(model: ScopeModel): HTMLElement {
  const select: HTMLSelectElement = h("select", {
    "data-testid": "scope-preset", "aria-label": "Preset",
    onchange: () => {
      const preset = model.info.rawVal?.presets.find((item) => item.key === select.value);
      if (preset) applyDefinition(model.draft, preset.definition);
      select.value = "";
    },
  }, h("option", { value: "" }, "Preset…"), () => (model.info.val?.presets ?? []).map((preset) =>
    h("option", { value: preset.key, title: preset.description }, preset.title)));
  return select;
}

function commandButtons(model: ScopeModel): HTMLElement[] {
  const running = () => model.job.val !== null;
  return [
    h("button", { class: "primary", "data-testid": "scope-arm", title: "Arm (a)", disabled: running, onclick: () => void arm(model) }, "Arm"),
    h("button", { "data-testid": "scope-force", title: "Force the trigger (f)", onclick: () => void force(model) }, "Force"),
    h("button", { "data-testid": "scope-stop", title: "Stop (s)", onclick: () => void stop(model) }, "Stop"),
  ];
}

function stageView(model: ScopeModel): HTMLElement {
  return h("span", { class: "pill", "data-testid": "scope-stage" }, () => {
    const upload = model.upload.val;
    const shown = upload ? `uploading ${Math.round((100 * upload.done) / Math.max(upload.total, 1))} %` : model.stage.val;
    return [h("span", { class: `dot ${model.job.val ? "warn" : "ok"}` }), `Recorder: ${shown}`];
  });
}

function channelRow(model: ScopeModel, index: Searchable[]): HTMLElement {
  const channels = model.draft.channels;
  const slot = (n: number) => h("label", null, `Ch ${n + 1} `,
    objectPicker({ value: channelSlot(channels, n), index, placeholder: "search by name or 0x…", testid: `scope-ch${n + 1}` }));
  return h("div", { class: "toolbar", style: { flexWrap: "wrap" } }, Array.from({ length: CHANNEL_SLOTS }, (_, n) => slot(n)));
}

/** Channel `n` of the list as a state of its own: reading tracks the list, writing replaces that one entry. */
function channelSlot(channels: State<string[]>, n: number): State<string> {
  return {
    get val() {
      return channels.val[n] ?? "";
    },
    set val(key: string) {
      channels.val = channels.rawVal.map((current, i) => (i === n ? key : current));
    },
    get rawVal() {
      return channels.rawVal[n] ?? "";
    },
  };
}

function timingRow(model: ScopeModel): HTMLElement {
  const draft = model.draft;
  const base = () => (model.info.val ? model.info.val.base_period_ns / 1000 : 250);
  return h("div", { class: "toolbar" },
    h("label", null, "Period ", textField(draft.period, "scope-period", "70px"), () => ` µs (× ${base()} µs)`),
    h("label", null, "Samples ", textField(draft.samples, "scope-samples", "80px")),
    h("label", null, "Mode ", choice(draft.mode, ["single", "normal", "auto"], "scope-mode")),
    () => draft.mode.val === "auto" ? h("label", null, "forced after ", textField(draft.autoTimeout, "scope-auto-timeout", "60px"), " ms") : null,
    h("span", { class: "muted" }, () => sourceText(model.info.val)));
}

/** What takes the samples: the drive's recorder, TPDOs at the server's SYNC, or SDO polling (docs/scope.md §7). */
function sourceText(info: ScopeModel["info"]["val"]): string {
  if (!info) return "";
  if (info.source === "recorder") return `recorder: buffer ${info.capacity ?? 0} bytes, ${info.channels} channels`;
  if (info.source === "tpdo") return `no recorder: TPDOs at the server's SYNC (every ${info.base_period_ns / 1e6} ms at the fastest), ${info.channels} channels`;
  return "no recorder, no TPDO: polled by SDO (the plan states the rate)";
}

function triggerRow(model: ScopeModel, index: Searchable[]): HTMLElement {
  const draft = model.draft;
  const unit = () => entryOf(index, draft.triggerSource.val)?.variable.unit ?? "";
  const edgeParts = () => draft.triggerSource.val === "" ? h("span", { class: "muted" }, "no trigger source: the recording starts at the arm") : [
    h("label", null, "Edge ", choice(draft.edge, ["rising", "falling", "either"], "scope-edge")),
    h("label", null, "Level ", textField(draft.level, "scope-level", "90px"), () => ` ${unit()}`),
    h("label", null, "Pre-trigger ", textField(draft.pretrigger, "scope-pretrigger", "50px"), " %"),
  ];
  return h("div", { class: "toolbar", style: { flexWrap: "wrap" } },
    h("label", null, "Trigger ", objectPicker({ value: draft.triggerSource, index, placeholder: "immediate", testid: "scope-trigger" })),
    edgeParts);
}

function textField(value: State<string>, testid: string, width: string): HTMLInputElement {
  const input: HTMLInputElement = h("input", { "data-testid": testid, value, style: { width }, oninput: () => (value.val = input.value) });
  return input;
}

function choice<T extends string>(value: State<T>, options: T[], testid: string): HTMLSelectElement {
  const select: HTMLSelectElement = h("select", { "data-testid": testid, value, onchange: () => (value.val = select.value as T) },
    options.map((option) => h("option", { value: option }, option)));
  return select;
}
